#!/bin/sh
# SPDX-License-Identifier: MIT
# Instruction counts per sample with callgrind (valgrind), which do not depend on
# the load of a shared machine. Valgrind runs SSE2 and AVX2 but not AVX-512 (see
# scripts/kernel_loop_size.py for those).
#
#   scripts/kernel_icount.sh [CHECKKERNELS] ["c sse2 avx2"]
#       each benchmark case of checkkernels: (Ir(n=4096) - Ir(n=0)) / 4096.
#   scripts/kernel_icount.sh --bench BUMPGRAD ["c sse2 avx2"] [KERNELS] [SAMPLES]
#       each row of `bumpgrad bench` (one thread): (Ir(--runs 3) - Ir(--runs 1)) /
#       (2 SAMPLES), so data set-up and warm-up cancel. Prints "<kernel> <isa>
#       <instructions>" lines, the format of `bumpgrad bench --icount FILE`.
#       KERNELS defaults to every row of ours and stb_perlin's peers; per-point and
#       grid rows are measured once, at the active ISA (ISAS do not apply to them).
#   e.g. scripts/kernel_icount.sh --bench build/src/cli/bumpgrad > icount.txt
#        build/src/cli/bumpgrad bench --json --icount icount.txt
ir() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$@" 2>&1 |
        sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
if [ "$1" = "--bench" ]; then
    exe=$2
    isas=${3:-"scalar sse2 avx2"}
    kernels=${4:-"noise3 noise3_grad fbm3 fbm3_grad turbulence3_grad noise3_point noise3_grad_point fbm3_point fbm3_grad_point noise3_batch1_point noise3_n1 noise3_n4 noise3_n8 noise3_n16 noise3_n64 noise3_n256 noise3_grid fbm3_grid fbm3_grad_grid pnoise3 pnoise3_grad pfbm3 pfbm3_grad fbm3_seed_grad pfbm3_grad_xy pfbm3_grad_p10 fbm3_grad_l3 pfbm3_grad_l3"}
    n=${5:-16384}
    # The per-point and grid rows call the public entry points, which run at the
    # active ISA: measured once, without --isa, at the level the row reports
    # under valgrind (BUMPGRAD_ISA caps it; valgrind has no AVX-512).
    tmp=$(mktemp -d) || exit 1
    trap 'rm -rf "$tmp"' EXIT
    for k in $kernels; do
        case $k in
        *_point | *_grid)
            a=$(ir "$exe" bench --threads 1 --kernels "$k" --samples "$n" --runs 1)
            b=$(valgrind --tool=callgrind --callgrind-out-file=/dev/null --log-file="$tmp/log" \
                "$exe" bench --threads 1 --kernels "$k" --samples "$n" --runs 3 --json \
                >"$tmp/json" && sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$tmp/log")
            isa=$(sed -n 's/.*"isa": "\([a-z0-9]*\)".*/\1/p' "$tmp/json" | head -n 1)
            echo "$k $isa $(( (b - a) / (2 * n) ))"
            continue ;;
        esac
        for isa in $isas; do
            a=$(ir "$exe" bench --threads 1 --isa "$isa" --kernels "$k" --samples "$n" --runs 1)
            b=$(ir "$exe" bench --threads 1 --isa "$isa" --kernels "$k" --samples "$n" --runs 3)
            echo "$k $isa $(( (b - a) / (2 * n) ))"
        done
    done
    for op in value fbm grad_central; do
        k=peer:stb_perlin:$op
        a=$(ir "$exe" bench --threads 1 --isa scalar --kernels "$k" --samples "$n" --runs 1)
        b=$(ir "$exe" bench --threads 1 --isa scalar --kernels "$k" --samples "$n" --runs 3)
        echo "$k baseline $(( (b - a) / (2 * n) ))"
    done
    exit 0
fi
exe=${1:-build-simd/tests/kernels/checkkernels}
isas=${2:-"c sse2 avx2"}
for c in 0 1 2 3 5 6; do
    for isa in $isas; do
        a=$(ir "$exe" --run="$isa:$c:0")
        b=$(ir "$exe" --run="$isa:$c:4096")
        echo "case $c $isa $(( (b - a) / 4096 )) instructions/sample"
    done
done
