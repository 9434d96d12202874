/* SPDX-License-Identifier: MIT */
/* `bumpgrad`: global options (--isa, --version, --help), then one subcommand
 * from the table below. Every subcommand lives in its own cmd_<name>.c. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"

/* The subcommand table, in the order `bumpgrad --help` lists them.
 * To add a command: declare cmd_<name> in cli.h, add cmd_<name>.c to
 * src/cli/meson.build (cli_tool_sources if it needs the I/O shim), and add one
 * line in the matching block here. */
static const cli_command commands[] = {
    {"eval", "noise / fBm / turbulence value and gradient at points from a CSV table", cmd_eval},
    {"perturb", "bump surface normals from a CSV table (surface gradient or additive)",
     cmd_perturb},
    /* Core commands without the I/O shim (bench, accuracy, stability) go here. */
    {"bench", "throughput of every kernel and ISA, 1 and N threads, against peer libraries", cmd_bench},
    {"accuracy", "speed against accuracy of every gradient method: CSV and a log-log chart",
     cmd_accuracy},
    {"stability", "sweeps where bump methods fail: markdown report, CSVs, charts", cmd_stability},
#if BG_HAVE_TOOLS
    /* Commands that need OpenImageIO / OpenVDB / assimp (render, mesh, volume, ...)
     * go here. */
    {"volume", "bake a height function and its gradient into an OpenVDB file", cmd_volume},
    {"heightmap", "image -> tangent-space normal map (seed method); normal map -> derivative map",
     cmd_heightmap},
    {"render", "ray-cast the paper's scenes with a bump method; --compare, --preset fig1..3",
     cmd_render},
    {"mesh", "bump the vertex normals of a mesh file (OBJ, PLY, STL, glTF, ...) or bake a normal map",
     cmd_mesh},
#endif
};
static const size_t n_commands = sizeof commands / sizeof commands[0];

static const cli_command *find_command(const char *name)
{
    for (size_t i = 0; i < n_commands; i++)
        if (strcmp(commands[i].name, name) == 0)
            return &commands[i];
    return NULL;
}

static void main_help(FILE *fp)
{
    fputs("Usage: bumpgrad [--isa NAME] COMMAND [options]\n"
          "       bumpgrad help COMMAND | --help | --version\n"
          "\n"
          "Procedural bump mapping on the CPU: Perlin noise gradients and the surface\n"
          "gradient of Mikkelsen (2010).\n"
          "\n"
          "Commands:\n",
          fp);
    for (size_t i = 0; i < n_commands; i++)
        fprintf(fp, "  %-12s %s\n", commands[i].name, commands[i].summary);
    fputs("\n"
          "Global options (before COMMAND):\n"
          "  --isa NAME    run the SIMD kernels at ISA level NAME (scalar, sse2, avx2,\n"
          "                avx512, neon) or lower-than-best; every level gives the same\n"
          "                bits. Overrides the BUMPGRAD_ISA environment variable.\n"
          "  --version     print the version and the active and best ISA levels\n"
          "  -h, --help    this help; `bumpgrad COMMAND --help` for a command\n"
          "\n"
          "Environment:\n"
          "  BUMPGRAD_ISA  same as --isa; an unknown or unsupported level is an error\n"
          "\n"
          "Exit status: 0 success, 1 runtime failure (I/O, memory), 2 bad input or usage.\n",
          fp);
}

/* A level is usable if it is scalar, the best one, or below the best on the same
 * x86 chain (NEON is its own chain); the same rule as the library's dispatch. */
static int isa_usable(bg_isa isa, bg_isa best)
{
    if (isa == BG_ISA_SCALAR || isa == best)
        return 1;
    if (isa == BG_ISA_NEON || best == BG_ISA_NEON)
        return 0;
    return isa <= best;
}

static void list_usable(char *buf, size_t len)
{
    bg_isa best = bg_isa_best();
    buf[0] = '\0';
    for (int i = 0; i < BG_ISA_COUNT; i++)
        if (isa_usable((bg_isa)i, best)) {
            if (buf[0])
                strncat(buf, ", ", len - strlen(buf) - 1);
            strncat(buf, bg_isa_name((bg_isa)i), len - strlen(buf) - 1);
        }
}

/* Apply an ISA request from `source` ("--isa" or "BUMPGRAD_ISA"); CLI_USAGE on
 * an unknown name or a level this CPU (or this build) lacks. */
static int apply_isa(const char *source, const char *name)
{
    char have[96];
    bg_isa isa;
    list_usable(have, sizeof have);
    if (bg_isa_parse(name, &isa) != BG_OK)
        return cli_usage_error(NULL, "%s: unknown ISA level \"%s\" (this CPU has: %s)", source,
                               name, have);
    if (!isa_usable(isa, bg_isa_best()) || bg_isa_force(isa) != BG_OK)
        return cli_usage_error(NULL,
                               "%s: ISA level \"%s\" is not available here (this CPU has: %s)",
                               source, name, have);
    return 0;
}

static size_t edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 32 || lb > 32)
        return (size_t)-1;
    size_t row[33];
    for (size_t j = 0; j <= lb; j++)
        row[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t up = row[j];
            size_t best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best)
                best = up + 1;
            if (row[j - 1] + 1 < best)
                best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb];
}

static int unknown_command(const char *name)
{
    const cli_command *near = NULL;
    size_t best = (size_t)-1;
    for (size_t i = 0; i < n_commands; i++) {
        size_t d = edit_distance(name, commands[i].name);
        /* A prefix ("pert") is as good a hint as a typo. */
        if (strncmp(commands[i].name, name, strlen(name)) == 0 && *name)
            d = 1;
        if (d < best)
            best = d, near = &commands[i];
    }
    if (near && best <= 2)
        return cli_usage_error(NULL,
                               "unknown command \"%s\"; did you mean \"%s\"? (see bumpgrad --help)",
                               name, near->name);
    return cli_usage_error(NULL, "unknown command \"%s\" (see bumpgrad --help)", name);
}

static int dispatch(int argc, char **argv)
{
    const char *isa_arg = NULL;
    int want_version = 0, want_help = 0, i = 1;
    for (; i < argc && argv[i][0] == '-'; i++) {
        const char *o = argv[i];
        if (strcmp(o, "--isa") == 0) {
            if (i + 1 >= argc)
                return cli_usage_error(NULL,
                                       "--isa needs a value (scalar, sse2, avx2, avx512, neon)");
            isa_arg = argv[++i];
        } else if (strncmp(o, "--isa=", 6) == 0) {
            isa_arg = o + 6;
        } else if (strcmp(o, "--version") == 0 || strcmp(o, "-V") == 0) {
            want_version = 1;
        } else if (strcmp(o, "--help") == 0 || strcmp(o, "-h") == 0) {
            want_help = 1;
        } else {
            return cli_usage_error(
                NULL, "unknown option \"%s\" before the command (see bumpgrad --help)", o);
        }
    }

    /* The library would silently ignore a bad BUMPGRAD_ISA; the command refuses it
     * so a benchmark or test never runs at a level other than the one asked for. */
    int rc;
    if (isa_arg) {
        if ((rc = apply_isa("--isa", isa_arg)))
            return rc;
    } else {
        const char *env = getenv("BUMPGRAD_ISA");
        if (env && *env && (rc = apply_isa("BUMPGRAD_ISA", env)))
            return rc;
    }

    if (want_help) {
        main_help(stdout);
        return CLI_OK;
    }
    if (want_version) {
        printf("bumpgrad %s (isa: %s, best: %s)\n", bg_version_string(),
               bg_isa_name(bg_isa_active()), bg_isa_name(bg_isa_best()));
        return CLI_OK;
    }
    if (i >= argc) {
        main_help(stderr);
        return CLI_USAGE;
    }

    const char *name = argv[i];
    if (strcmp(name, "help") == 0) {
        if (i + 1 >= argc) {
            main_help(stdout);
            return CLI_OK;
        }
        const cli_command *c = find_command(argv[i + 1]);
        if (!c)
            return unknown_command(argv[i + 1]);
        char *help_argv[] = {(char *)c->name, (char *)"--help", NULL};
        return c->run(2, help_argv);
    }
    const cli_command *c = find_command(name);
    if (!c)
        return unknown_command(name);
    return c->run(argc - i, argv + i);
}

int main(int argc, char **argv)
{
    int rc = dispatch(argc, argv);
    /* Summaries, help, --version and stats lines lost to a full disk or a
     * closed stdout must not pass as success: stdio reports the error only when
     * it flushes. */
    if (rc == CLI_OK && (fflush(stdout) != 0 || ferror(stdout)))
        rc = cli_fail(NULL, "writing to standard output failed: %s", strerror(errno));
    return rc;
}
