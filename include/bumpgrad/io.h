/* SPDX-License-Identifier: MIT */
/**
 * @file io.h
 * @brief The I/O library (libbumpgrad-io: image.h, volume.h, mesh.h): can it be
 *        used here? A check for programs to call before starting long work.
 *
 * The functions of image.h, volume.h and mesh.h live in a module
 * (libbumpgrad_io_module.so, C++ over OpenImageIO, OpenVDB and assimp) that
 * libbumpgrad-io loads with dlopen on first use, so programs that never touch a
 * file pay nothing for those libraries at start-up (docs/INSTALL.md). The module
 * is looked up relative to the object that holds the loader, never by an absolute
 * path fixed at build time, so an installed prefix can be moved:
 *  1. $BUMPGRAD_IO_MODULE, if set (and then only that file);
 *  2. the loader in a shared library (libbumpgrad-io.so in LIBDIR):
 *     LIBDIR/bumpgrad/libbumpgrad_io_module.so, then the library's own folder
 *     (the build tree);
 *  3. the loader linked into a program (BINDIR/prog): the program's
 *     BINDIR/<BINDIR to LIBDIR>/bumpgrad/ folder; then, for programs in the build
 *     tree, src/io/ below the program's folder or any of its parents.
 * Link with `pkg-config --cflags --libs bumpgrad-io` or the CMake target
 * bumpgrad::bumpgrad-io. The library never prints: every failure comes back as a
 * status and, where the call has one, a message in the caller's buffer.
 */
#ifndef BUMPGRAD_IO_H
#define BUMPGRAD_IO_H

#include "common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Load the I/O module now (if not yet loaded) and report whether it works.
 *  BG_OK if the module is loaded. Otherwise BG_ERR_IO and, in `err` (`errlen`
 *  bytes including the terminating NUL; `err` may be NULL or `errlen` 0), why:
 *  the folders searched, or dlopen's message for a module that was found but
 *  could not be loaded (e.g. a missing OpenImageIO). The answer is computed once
 *  per process; thread-safe. Call it before a long command starts its work, so
 *  that it fails at once rather than at write time. */
BG_API bg_status bg_io_available(char *err, size_t errlen);

#ifdef __cplusplus
}
#endif

#endif /* BUMPGRAD_IO_H */
