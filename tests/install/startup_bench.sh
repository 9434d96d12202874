#!/bin/sh
# SPDX-License-Identifier: MIT
# Start-up time and peak RSS, best of N runs each (a benchmark: it prints, it
# does not judge): `bumpgrad --version`, `bumpgrad eval` on one point, and a
# program linked with the shared libbumpgrad-io, without and with loading the
# I/O module (the cost the lazy module keeps out of every command).
# Times are best of N; under load (the machine is shared) read the CPU column.
# usage: startup_bench.sh BUMPGRAD_EXE STARTUP_PROBE [N]
set -eu
exe=$1 probe=$2 n=${3:-20}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf 'x,y,z\n3.14,42,7\n' >"$tmp/p.csv"
measure() { # label, command...  (GNU time: 10 ms resolution; CPU = user + sys)
    label=$1; shift
    best_t=999 best_c=999 best_m=0 i=0
    while [ "$i" -lt "$n" ]; do
        /usr/bin/time -f '%e %U %S %M' -o "$tmp/t" "$@" >/dev/null 2>&1
        read -r t u s m <"$tmp/t"
        best_t=$(echo "$t $best_t" | awk '{print ($1 < $2) ? $1 : $2}')
        best_c=$(echo "$u $s $best_c" | awk '{c = $1 + $2; print (c < $3) ? c : $3}')
        best_m=$m
        i=$((i + 1))
    done
    echo "$label $best_t $best_c $best_m" | awk '{m = $NF; c = $(NF-1); t = $(NF-2); $NF = $(NF-1) = $(NF-2) = "";
        printf "%-44s wall %5.0f ms  cpu %5.0f ms  peak RSS %6.1f MB\n", $0, t * 1000, c * 1000, m / 1024}'
}
measure "bumpgrad --version" "$exe" --version
measure "bumpgrad eval (1 point, float)" "$exe" eval --threads 1 -i "$tmp/p.csv" -o "$tmp/o.csv"
measure "libbumpgrad-io linked, module not loaded" "$probe" idle
measure "libbumpgrad-io linked, bg_io_available()" "$probe" load
