/* SPDX-License-Identifier: MIT */
/* `bumpgrad`: global options (--isa, --version, --help), then one subcommand
 * from the table below. Every subcommand lives in its own cmd_<name>.c. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "args.h"
#include "cli.h"
#include "kernels/kernels.h" /* bg_isa_list: the levels dispatch knows */

/* The subcommand table, in the order `bumpgrad --help` lists them.
 * To add a command: declare its cli_spec_<name> in cli.h, add cmd_<name>.c to
 * src/cli/meson.build (cli_tool_sources if it needs the I/O shim), and add one
 * line in the matching block here. */
static const char *const bench_own[] = {"--isa", NULL};
static const cli_command commands[] = {
    {"eval", &cli_spec_eval, NULL},
    {"perturb", &cli_spec_perturb, NULL},
    /* Core commands without the I/O shim (bench, accuracy, stability) go here. */
    {"bench", &cli_spec_bench, bench_own},
    {"accuracy", &cli_spec_accuracy, NULL},
    {"stability", &cli_spec_stability, NULL},
#if BG_HAVE_TOOLS
    /* Commands that need OpenImageIO / OpenVDB / assimp (render, mesh, volume, ...)
     * go here. */
    {"volume", &cli_spec_volume, NULL},
    {"heightmap", &cli_spec_heightmap, NULL},
    {"render", &cli_spec_render, NULL},
    {"mesh", &cli_spec_mesh, NULL},
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
    fputs("Usage: bumpgrad [global options] COMMAND [options]\n"
          "       bumpgrad help COMMAND | --help | --version\n"
          "\n"
          "Procedural bump mapping on the CPU: Perlin noise gradients and the surface\n"
          "gradient of Mikkelsen (2010).\n"
          "\n"
          "Commands:\n",
          fp);
    for (size_t i = 0; i < n_commands; i++)
        fprintf(fp, "  %-12s %s\n", commands[i].name,
                commands[i].spec->summary);
    fputs("\n"
          "Global options (anywhere on the command line, before a `--`):\n"
          "  --isa NAME    run the SIMD kernels at ISA level NAME (scalar, sse2, avx2,\n"
          "                avx512, neon) or lower-than-best; every level gives the same\n"
          "                bits. Overrides the BUMPGRAD_ISA environment variable.\n"
          "                (After `bench`, --isa is bench's own option.)\n"
          "  -q, --quiet   only errors (and warnings) on stderr; no progress, no summary\n"
          "  --progress    progress on stderr even when it is not a terminal (one line a\n"
          "                second, then a final line with the rate)\n"
          "  -v, --verbose more detail on stderr (final rate and time of long steps)\n"
          "  --version     print the version and the active and best ISA levels\n"
          "  -h, --help    this help; `bumpgrad COMMAND --help` for a command\n"
          "Options take their value as `--opt value` or `--opt=value`; `--` ends them.\n"
          "`bumpgrad completion bash|zsh` prints a completion script, `bumpgrad man\n"
          "[COMMAND]` a man page.\n"
          "\n"
          "Environment:\n"
          "  BUMPGRAD_ISA  same as --isa; an unknown or unsupported level is an error\n"
          "  BUMPGRAD_NO_PROGRESS  if set (to anything), no progress line on a terminal\n"
          "                either; --progress still forces it\n"
          "  BUMPGRAD_MAX_MB  cap in MiB on every allocation an input decides (default\n"
          "                4096, 0 = no cap)\n"
          "  BUMPGRAD_CHILD_TIMEOUT  seconds a mesh import or VDB probe child may run\n"
          "                (default 60)\n"
          "  BUMPGRAD_MESH_MAX_MB, BUMPGRAD_VDB_MAX_MB  memory allowance in MiB of the\n"
          "                mesh import and VDB probe children (0 = no cap)\n"
          "  BUMPGRAD_IO_MODULE  path of the I/O module (default: found next to the\n"
          "                library)\n"
          "  BUMPGRAD_FONT  font of the render panels' labels (a name or a .ttf path);\n"
          "                BUMPGRAD_BITMAP_FONT (set to anything) uses the built-in 5x7 font\n"
          "\n"
          "Exit status: 0 success, 1 runtime failure (I/O, memory), 2 bad input or usage,\n"
          "3 `render --compare --fail-above DEG` found a mean error above DEG.\n",
          fp);
}

/* Apply an ISA request from `source` ("--isa" or "BUMPGRAD_ISA"); CLI_USAGE on
 * an unknown name or a level this CPU (or this build) lacks. */
static int apply_isa(const char *source, const char *name)
{
    char have[96];
    bg_isa isa;
    bg_isa_list(have, sizeof have, 1);
    if (bg_isa_parse(name, &isa) != BG_OK)
        return cli_usage_error(NULL, "%s: unknown ISA level \"%s\" (this CPU has: %s)", source,
                               name, have);
    if (!bg_isa_supported(isa) || bg_isa_force(isa) != BG_OK)
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

/* 1 if argv[*i] is a global option (consumed with its value; *isa set for
 * --isa), 0 if not, CLI_USAGE if --isa lacks its value. */
static int global_option(int argc, char **argv, int *i, const char **isa)
{
    const char *o = argv[*i];
    if (strcmp(o, "--isa") == 0) {
        if (*i + 1 >= argc) {
            char all[96];
            bg_isa_list(all, sizeof all, 0);
            return cli_usage_error(NULL, "--isa needs a value (%s)", all);
        }
        *isa = argv[++*i];
    } else if (strncmp(o, "--isa=", 6) == 0) {
        *isa = o + 6;
    } else if (strcmp(o, "-q") == 0 || strcmp(o, "--quiet") == 0) {
        cli_global.quiet = 1;
    } else if (strcmp(o, "--progress") == 0) {
        cli_global.progress = 1;
    } else if (strcmp(o, "-v") == 0 || strcmp(o, "--verbose") == 0) {
        cli_global.verbose = 1;
    } else {
        return 0;
    }
    return 1;
}

static int owns(const cli_command *c, const char *arg)
{
    if (!c->own)
        return 0;
    for (size_t k = 0; c->own[k]; k++) {
        size_t n = strlen(c->own[k]);
        if (strncmp(arg, c->own[k], n) == 0 && (arg[n] == '\0' || arg[n] == '='))
            return 1;
    }
    return 0;
}

/* The command's argv without the global options, up to `--`, after which
 * every argument is left as it is. Returns the new argc; out has room for
 * 2 * argc + 2. */
static int command_argv(const cli_command *c, int argc, char **argv, char **out,
                        const char **isa, int *rc)
{
    int n = 0, done = 0;
    out[n++] = argv[0];
    for (int i = 1; i < argc; i++) {
        char *a = argv[i];
        if (done || a[0] != '-') {
            out[n++] = a;
            continue;
        }
        if (strcmp(a, "--") == 0) {
            done = 1;
            out[n++] = a;
            continue;
        }
        if (!owns(c, a)) {
            int g = global_option(argc, argv, &i, isa);
            if (g == CLI_USAGE) {
                *rc = g;
                return 0;
            }
            if (g)
                continue;
        }
        out[n++] = a;
    }
    out[n] = NULL;
    return n;
}

static const char *const global_opt_words[] = {"--isa", "-q", "--quiet", "--progress", "-v",
                                               "--verbose", NULL};

static int completion(const char *shell)
{
    const cli_spec *specs[sizeof commands / sizeof commands[0]];
    const char *names[sizeof commands / sizeof commands[0]];
    size_t ns = 0;
    for (size_t k = 0; k < n_commands; k++) {
        names[k] = commands[k].name;
        specs[ns++] = commands[k].spec;
    }
    if (shell && strcmp(shell, "bash") == 0)
        cli_args_completion_bash(stdout, specs, ns, names, n_commands, global_opt_words);
    else if (shell && strcmp(shell, "zsh") == 0)
        cli_args_completion_zsh(stdout, specs, ns, names, n_commands, global_opt_words);
    else
        return cli_usage_error(NULL, "completion: expected bash or zsh, got \"%s\"",
                               shell ? shell : "");
    return CLI_OK;
}

static void main_man(FILE *fp)
{
    fprintf(fp, ".TH BUMPGRAD 1 \"\" \"bumpgrad %s\" \"User Commands\"\n"
                ".SH NAME\nbumpgrad \\- procedural bump mapping on the CPU\n"
                ".SH SYNOPSIS\n.B bumpgrad\n[global options] COMMAND [options]\n"
                ".SH DESCRIPTION\n.nf\n",
            bg_version_string());
    main_help(fp);
    fputs(".fi\n.SH SEE ALSO\n", fp);
    int first = 1;
    for (size_t k = 0; k < n_commands; k++) {
        fprintf(fp, "%s.BR bumpgrad\\-%s (1)", first ? "" : ",\n", commands[k].name);
        first = 0;
    }
    fputc('\n', fp);
}

static int man(const char *name)
{
    if (!name) {
        main_man(stdout);
        return CLI_OK;
    }
    const cli_command *c = find_command(name);
    if (!c)
        return unknown_command(name);
    cli_args_man(c->spec, stdout, bg_version_string());
    return CLI_OK;
}

static int dispatch(int argc, char **argv)
{
    const char *isa_arg = NULL;
    int want_version = 0, want_help = 0, i = 1, rc;
    for (; i < argc && argv[i][0] == '-'; i++) {
        const char *o = argv[i];
        int g = global_option(argc, argv, &i, &isa_arg);
        if (g == CLI_USAGE)
            return g;
        if (g)
            continue;
        if (strcmp(o, "--version") == 0 || strcmp(o, "-V") == 0) {
            want_version = 1;
        } else if (strcmp(o, "--help") == 0 || strcmp(o, "-h") == 0) {
            want_help = 1;
        } else {
            return cli_usage_error(
                NULL, "unknown option \"%s\" before the command (see bumpgrad --help)", o);
        }
    }

    const cli_command *c = NULL;
    char **cargv = NULL;
    int cargc = 0;
    if (!want_help && !want_version && i < argc && strcmp(argv[i], "help") != 0) {
        if (strcmp(argv[i], "completion") == 0)
            return completion(i + 1 < argc ? argv[i + 1] : NULL);
        if (strcmp(argv[i], "man") == 0)
            return man(i + 1 < argc ? argv[i + 1] : NULL);
        c = find_command(argv[i]);
        if (!c)
            return unknown_command(argv[i]);
        cargv = malloc(sizeof *cargv * (2 * (size_t)(argc - i) + 2));
        if (!cargv)
            return cli_fail(NULL, "out of memory");
        rc = 0;
        cargc = command_argv(c, argc - i, argv + i, cargv, &isa_arg, &rc);
        if (rc) {
            free(cargv);
            return rc;
        }
    }

    /* The library would silently ignore a bad BUMPGRAD_ISA; the command refuses it
     * so a benchmark or test never runs at a level other than the one asked for. */
    if (isa_arg) {
        rc = apply_isa("--isa", isa_arg);
    } else {
        /* The library reads BUMPGRAD_ISA itself; it says what is wrong with it,
         * and the command refuses to run at a level other than the one asked. */
        char msg[256];
        rc = bg_isa_env_status(msg, sizeof msg) == BG_OK ? 0 : cli_usage_error(NULL, "%s", msg);
    }
    if (rc) {
        free(cargv);
        return rc;
    }
    if (c) {
        rc = cli_run_command(c->spec, cargc, cargv);
        free(cargv);
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
    /* `help [COMMAND]` */
    if (i + 1 >= argc) {
        main_help(stdout);
        return CLI_OK;
    }
    c = find_command(argv[i + 1]);
    if (!c)
        return unknown_command(argv[i + 1]);
    cli_args_help(c->spec, stdout);
    return CLI_OK;
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
