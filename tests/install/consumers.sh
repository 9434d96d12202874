#!/bin/sh
# SPDX-License-Identifier: MIT
# Installs the build into a fresh prefix under WORK_DIR, MOVES that prefix to
# another folder (so nothing may depend on the path it was installed for), and
# checks one way of using it:
#   cmake     a C++ consumer through find_package(bumpgrad CONFIG) (shared and
#             static targets, plus bumpgrad::bumpgrad-io with the tools) and
#             through pkg_check_modules(IMPORTED_TARGET)
#   io        a C program on bumpgrad/image.h linked with pkg-config bumpgrad-io
#             (with the tools), or that those headers are not installed (without)
#   relocate  bumpgrad render and bumpgrad mesh from the moved prefix
#   python    import bumpgrad from the moved prefix's site-packages
#
# usage: consumers.sh MODE BUILD_DIR SOURCE_DIR WORK_DIR TOOLS(true|false)
# CC, CXX, PKG_CONFIG, CMAKE, PYTHON and BG_SANITIZE may be set.
set -eu
# Only what the moved prefix provides: meson test points LD_LIBRARY_PATH at the build tree.
unset LD_LIBRARY_PATH || true

mode=$1 build_dir=$2 src=$3 work=$4 tools=$5
pkgconfig=${PKG_CONFIG:-pkg-config}
python=${PYTHON:-/usr/bin/python3}
san=
if [ -n "${BG_SANITIZE:-}" ] && [ "$BG_SANITIZE" != none ]; then
    san="-fsanitize=$BG_SANITIZE"
fi

rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
dest=$work/destdir
# --no-rebuild: meson test built everything already; a nested ninja would fight
# the running one over the build directory lock.
meson install -C "$build_dir" --destdir "$dest" --no-rebuild --quiet
prefix_pc=$(find "$dest" -name bumpgrad.pc | head -n 1)
[ -n "$prefix_pc" ] || { echo "FAIL: no bumpgrad.pc installed"; exit 1; }
# The prefix is the folder holding bin/ (or include/): find it inside DESTDIR,
# then move it somewhere else entirely.
inc=$(dirname "$(find "$dest" -path '*/include/bumpgrad.h' | head -n 1)")
installed_prefix=${inc%/include}
prefix=$work/moved-prefix
mv "$installed_prefix" "$prefix"
rm -rf "$dest"
echo "installed for ${installed_prefix#"$dest"}, moved to $prefix"
pcdir=$(dirname "$(find "$prefix" -name bumpgrad.pc | head -n 1)")
libdir=$(dirname "$pcdir")

# pkg-config on a moved prefix needs relocatable .pc files (prefix=${pcfiledir}/...,
# meson's pkgconfig.relocatable, on by default in meson.build). A build directory
# configured before that default has absolute ones: point pkg-config at the moved
# tree with PKG_CONFIG_SYSROOT_DIR-free --define-variable instead.
pc_args=
if ! grep -q 'pcfiledir' "$pcdir/bumpgrad.pc"; then
    pc_args="--define-variable=prefix=$prefix"
    echo "note: non-relocatable .pc files (build dir predates pkgconfig.relocatable): $pc_args"
fi
pc() { # pkg-config against the moved prefix only
    # shellcheck disable=SC2086
    PKG_CONFIG_PATH=$pcdir PKG_CONFIG_LIBDIR=$pcdir "$pkgconfig" $pc_args "$@"
}

case $mode in
cmake)
    cmake=${CMAKE:-cmake}
    cxx=${CXX:-c++}
    for variant in cmake_config cmake_pkgconfig; do
        b=$work/$variant
        echo "== $variant"
        # shellcheck disable=SC2086
        PKG_CONFIG_PATH=$pcdir PKG_CONFIG_LIBDIR=$pcdir "$cmake" -S "$src/tests/install/$variant" \
            -B "$b" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_CXX_COMPILER="$cxx" \
            -DCMAKE_C_COMPILER="${CC:-cc}" -DCMAKE_BUILD_TYPE=Release \
            -DCMAKE_CXX_FLAGS="$san" -DCMAKE_C_FLAGS="$san" \
            -DPKG_CONFIG_EXECUTABLE="$pkgconfig" -DPKG_CONFIG_ARGN="$pc_args" >"$b.log" 2>&1 ||
            { cat "$b.log"; echo "FAIL: cmake configure ($variant)"; exit 1; }
        "$cmake" --build "$b" >>"$b.log" 2>&1 || { cat "$b.log"; echo "FAIL: build ($variant)"; exit 1; }
        for exe in "$b"/consumer_*; do
            "$exe"
            echo "ran $(basename "$exe") ($(ldd "$exe" | grep -o 'libbumpgrad[^ ]* => [^ ]*' || echo static))"
        done
        if [ -x "$b/io_consumer" ]; then
            "$b/io_consumer" "$work"
        fi
    done
    # The example users copy (examples/cmake), built exactly as its comment says.
    b=$work/example_cmake
    echo "== examples/cmake"
    "$cmake" -S "$src/examples/cmake" -B "$b" -DCMAKE_PREFIX_PATH="$prefix" \
        -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="$san" \
        >"$b.log" 2>&1 || { cat "$b.log"; echo "FAIL: cmake configure (examples/cmake)"; exit 1; }
    "$cmake" --build "$b" >>"$b.log" 2>&1 || { cat "$b.log"; echo "FAIL: build (examples/cmake)"; exit 1; }
    "$b/bump_normals" 20000
    if [ "$tools" = true ] && [ ! -x "$work/cmake_config/io_consumer" ]; then
        echo "FAIL: bumpgrad_HAVE_IO false in a build with the tools"; exit 1
    fi
    ;;
io)
    if [ "$tools" != true ]; then
        for h in image.h volume.h mesh.h io.h; do
            if [ -e "$prefix/include/bumpgrad/$h" ]; then
                echo "FAIL: bumpgrad/$h installed without the tools: nothing could link it"
                exit 1
            fi
        done
        if [ -e "$pcdir/bumpgrad-io.pc" ]; then echo "FAIL: bumpgrad-io.pc without the tools"; exit 1; fi
        echo "io: without the tools neither the I/O headers nor bumpgrad-io.pc are installed"
        exit 0
    fi
    flags=$(pc --cflags --libs bumpgrad-io)
    echo "pkg-config --cflags --libs bumpgrad-io: $flags"
    # shellcheck disable=SC2086
    "${CC:-cc}" -std=c11 -Wall -Wextra -Werror $san "$src/tests/install/io_consumer.c" $flags \
        -Wl,-rpath,"$libdir" -o "$work/io_consumer"
    echo "linked: $(ldd "$work/io_consumer" | grep -o 'libbumpgrad-io[^ ]* => [^ ]*')"
    ( unset BUMPGRAD_IO_MODULE; "$work/io_consumer" "$work" )
    # examples/volume_io.c, built with the command its own comment gives.
    ex=$src/examples/volume_io.c
    ex_libs=$(sed -n 's/^ \*   cc volume_io\.c \$(pkg-config --cflags --libs bumpgrad-io)\(.*\) -o volume_io$/libs:\1/p' "$ex")
    [ -n "$ex_libs" ] || { echo "FAIL: no build comment in $ex"; exit 1; }
    # shellcheck disable=SC2086
    "${CC:-cc}" -std=c11 -Wall -Wextra -Werror $san "$ex" $flags ${ex_libs#libs:} \
        -Wl,-rpath,"$libdir" -o "$work/volume_io"
    ( unset BUMPGRAD_IO_MODULE; "$work/volume_io" "$work" 16 )
    # Fail fast and silently (status + message, no stderr) when the module is missing.
    BUMPGRAD_IO_MODULE=$work/no-such-module.so "$work/io_consumer" "$work" missing 2>"$work/stderr"
    if [ -s "$work/stderr" ]; then
        echo "FAIL: the library printed on stderr:"; cat "$work/stderr"; exit 1
    fi
    # Found relative to libbumpgrad-io.so: moving the module away must make it fail.
    mv "$libdir/bumpgrad" "$libdir/bumpgrad.away"
    if ( unset BUMPGRAD_IO_MODULE; "$work/io_consumer" "$work" >"$work/out" ); then
        echo "FAIL: loaded a module from outside the moved prefix"; cat "$work/out"; exit 1
    fi
    echo "without the module: $(cat "$work/out")"
    mv "$libdir/bumpgrad.away" "$libdir/bumpgrad"
    ;;
relocate)
    # No installed file may name the build tree or the prefix it was installed
    # for (docs excepted: INSTALL.md quotes /usr/local). Debug builds are not
    # checked: their DWARF records the build folder, which is harmless.
    if [ "${BG_DEBUG:-false}" != true ]; then
        build_abs=$(cd "$build_dir" && pwd)
        hits=$(grep -rlF "$build_abs" "$prefix" 2>/dev/null || true)
        hits2=$(grep -rlF "${installed_prefix#"$dest"}/" "$prefix" --exclude-dir=doc 2>/dev/null || true)
        if [ -n "$hits$hits2" ]; then
            echo "FAIL: absolute build or install paths in: $hits $hits2"; exit 1
        fi
        echo "no installed file names $build_abs or ${installed_prefix#"$dest"}/"
    fi
    # Man pages (docs/INSTALL.md): man-db finds them through PREFIX/bin on PATH,
    # or through MANPATH (the trailing colon keeps the system's pages).
    if command -v man >/dev/null 2>&1 && command -v manpath >/dev/null 2>&1; then
        page=$(unset MANPATH; PATH=$prefix/bin:$PATH man -w bumpgrad 2>&1) || true
        [ "$page" = "$prefix/share/man/man1/bumpgrad.1" ] ||
            { echo "FAIL: man -w bumpgrad with PREFIX/bin on PATH gave '$page'"; exit 1; }
        page=$(MANPATH=$prefix/share/man: man -w bumpgrad-eval 2>&1) || true
        [ "$page" = "$prefix/share/man/man1/bumpgrad-eval.1" ] ||
            { echo "FAIL: man -w bumpgrad-eval with MANPATH gave '$page'"; exit 1; }
        echo "man finds the moved prefix's pages through PATH and through MANPATH"
    fi
    [ "$tools" = true ] || { echo "relocate: no tools in this build"; exit 77; }
    cd "$work"
    unset BUMPGRAD_IO_MODULE || true
    "$prefix/bin/bumpgrad" render --size 32x32 -o x.png
    magic=$(od -An -tx1 -N8 x.png | tr -d ' \n')
    [ "$magic" = 89504e470d0a1a0a ] || { echo "FAIL: x.png is not a PNG ($magic)"; exit 1; }
    "$python" "$src/tests/mesh/make_sphere.py" sphere.ply 24 12 --normals
    "$prefix/bin/bumpgrad" mesh sphere.ply bumped.ply
    head -c 3 bumped.ply | grep -q ply || { echo "FAIL: bumped.ply is not a PLY"; exit 1; }
    echo "render and mesh ran from the moved prefix ($(wc -c <x.png) + $(wc -c <bumped.ply) bytes)"
    # The moved module really is the one used: without it the commands fail.
    mv "$libdir/bumpgrad" "$libdir/bumpgrad.away"
    if "$prefix/bin/bumpgrad" mesh sphere.ply bumped2.ply 2>"$work/err"; then
        echo "FAIL: mesh worked without the module of the moved prefix"; exit 1
    fi
    echo "without the module: $(head -c 300 "$work/err")"
    ;;
python)
    init=$(find "$prefix" -path '*/bumpgrad/__init__.py' | head -n 1)
    [ -n "$init" ] || { echo "FAIL: the Python package is not installed"; exit 1; }
    site=$(dirname "$(dirname "$init")")
    out=$(cd "$work" && PYTHONPATH=$site "$python" -c \
        'import bumpgrad, numpy; print(repr(float(bumpgrad.noise3(numpy.array([[3.14, 42, 7]]), dtype=numpy.float64)[0])), bumpgrad._c.__file__)')
    echo "PYTHONPATH=$site: $out"
    case $out in
    "0.13691995878400012 $prefix"/*) ;;
    *) echo "FAIL: expected Perlin's value from the moved prefix's package"; exit 1 ;;
    esac
    ;;
*)
    echo "unknown mode $mode"; exit 2 ;;
esac
echo "consumers $mode: all checks passed"
