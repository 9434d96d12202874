#!/bin/sh
# SPDX-License-Identifier: MIT
# Instructions per sample of each benchmark case of checkkernels on the ISAs that
# valgrind can run (no AVX-512: see scripts/kernel_loop_size.py for those):
# (Ir(n=4096) - Ir(n=0)) / 4096 with callgrind.
#   scripts/kernel_icount.sh build-simd/tests/kernels/checkkernels "c sse2 avx2"
exe=${1:-build-simd/tests/kernels/checkkernels}
isas=${2:-"c sse2 avx2"}
ir() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$exe" --run="$1" 2>&1 |
        sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
for c in 0 1 2 3 5 6; do
    for isa in $isas; do
        a=$(ir "$isa:$c:0")
        b=$(ir "$isa:$c:4096")
        echo "case $c $isa $(( (b - a) / 4096 )) instructions/sample"
    done
done
