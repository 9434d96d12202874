/* SPDX-License-Identifier: MIT */
/* Start-up cost of linking the installed I/O library (docs/INSTALL.md): linked
 * against the shared libbumpgrad-io, it exits at once ("idle": the module is
 * not loaded, as in `bumpgrad eval`) or after bg_io_available ("load": the
 * module with OpenImageIO, OpenVDB and assimp is loaded, as a command that
 * writes an image pays). Run by startup_bench.sh, a benchmark. */
#include <bumpgrad/io.h>

#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    char err[1024];
    if (argc > 1 && strcmp(argv[1], "load") == 0 && bg_io_available(err, sizeof err) != BG_OK) {
        printf("%s\n", err);
        return 1;
    }
    return 0;
}
