#!/bin/sh
# SPDX-License-Identifier: MIT
# Installs the build into a temporary DESTDIR, then builds examples/shade_sphere.c
# the way a user would, with nothing but `pkg-config --cflags --libs bumpgrad`
# against the installed tree, runs it and checks the PPM it writes.
#
# usage: install_test.sh BUILD_DIR EXAMPLE_SOURCE WORK_DIR
# CC (default cc), PKG_CONFIG (default pkg-config) and BG_SANITIZE (meson's
# b_sanitize value, e.g. address,undefined) may be set.
set -eu

build_dir=$1
example=$2
work=$3
cc=${CC:-cc}
pkgconfig=${PKG_CONFIG:-pkg-config}

rm -rf "$work"
mkdir -p "$work"
dest=$(cd "$work" && pwd)/destdir

echo "install: meson install -C $build_dir --destdir $dest"
# --no-rebuild: meson test already built everything; a nested ninja would
# fight the running one over the build directory lock.
meson install -C "$build_dir" --destdir "$dest" --no-rebuild --quiet

pc=$(find "$dest" -name bumpgrad.pc | head -n 1)
if [ -z "$pc" ]; then
    echo "FAIL: no bumpgrad.pc under $dest"
    exit 1
fi
echo "found ${pc#"$dest"}"
for h in bumpgrad.h bumpgrad/common.h bumpgrad/noise.h bumpgrad/surfgrad.h; do
    if [ -z "$(find "$dest" -path "*/include/$h" | head -n 1)" ]; then
        echo "FAIL: header $h not installed"
        exit 1
    fi
done

# The .pc file names the final prefix (/usr/local/...); inside DESTDIR the tree
# lives under $dest. PKG_CONFIG_SYSROOT_DIR makes pkg-config prepend $dest to
# every -I and -L path, as it does for a cross sysroot.
flags=$(PKG_CONFIG_PATH=$(dirname "$pc") PKG_CONFIG_LIBDIR=$(dirname "$pc") \
    PKG_CONFIG_SYSROOT_DIR=$dest "$pkgconfig" --cflags --libs bumpgrad)
echo "pkg-config --cflags --libs bumpgrad: $flags"
case "$flags" in
*-lbumpgrad*) ;;
*) echo "FAIL: pkg-config did not give -lbumpgrad"; exit 1 ;;
esac

san=
if [ -n "${BG_SANITIZE:-}" ] && [ "$BG_SANITIZE" != none ]; then
    san="-fsanitize=$BG_SANITIZE"
fi
# The command the example's own comment gives ("cc FILE $(pkg-config ...) LIBS -o
# NAME"): its LIBS (-lm: the example calls sqrtf/powf itself) must be enough.
build_line=$(sed -n 's/^ \*   cc [^ ]*\.c \$(pkg-config --cflags --libs bumpgrad)\(.*\) -o [^ ]*$/libs:\1/p' "$example")
[ -n "$build_line" ] || { echo "FAIL: no 'cc FILE.c \$(pkg-config --cflags --libs bumpgrad) ... -o NAME' comment in $example"; exit 1; }
build_line=${build_line#libs:}
echo "the example's build comment adds:${build_line:- nothing}"
# shellcheck disable=SC2086
"$cc" -std=c11 -Wall -Wextra -Werror $san "$example" $flags $build_line -o "$work/shade_sphere"
echo "compiled $example against the installed tree"

# Run against the installed shared library, not the build tree's.
libdir=$(dirname "$(dirname "$pc")")
LD_LIBRARY_PATH=$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH} "$work/shade_sphere" "$work/sphere.ppm" 64

if command -v ldd >/dev/null 2>&1; then
    lib=$(LD_LIBRARY_PATH=$libdir ldd "$work/shade_sphere" | grep libbumpgrad || true)
    echo "linked: ${lib:-static libbumpgrad}"
    case "$lib" in
    *"$dest"*|"") ;;
    *) echo "FAIL: shade_sphere loaded a libbumpgrad outside the install tree"; exit 1 ;;
    esac
fi

hlen=$(printf 'P6\n64 64\n255\n' | wc -c | tr -d ' ')
header=$(head -c "$hlen" "$work/sphere.ppm" | od -An -c | tr -s ' ')
expected=$(printf 'P6\n64 64\n255\n' | od -An -c | tr -s ' ')
size=$(wc -c <"$work/sphere.ppm" | tr -d ' ')
want=$((hlen + 64 * 64 * 3))
echo "sphere.ppm: $size bytes (expected $want)"
if [ "$header" != "$expected" ] || [ "$size" -ne "$want" ]; then
    echo "FAIL: wrong PPM header or size"
    exit 1
fi
echo "install_test: all checks passed"
