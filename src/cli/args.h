/* SPDX-License-Identifier: MIT */
/* The one option parser of the `bumpgrad` command (args.c): every command
 * declares a static const table of its options (cli_opt) and a spec
 * (cli_spec) with its usage line, texts and a function that sets the
 * defaults of its args struct. From these the parser fills the struct, and
 * the same tables generate --help (with the defaults read from the struct the
 * defaults function filled, so help and behaviour cannot disagree), the bash
 * and zsh completions (`bumpgrad completion bash|zsh`) and the man pages
 * (`bumpgrad man CMD`).
 *
 * Syntax accepted: --opt value, --opt=value, -o value, -ovalue, flags without
 * a value, `--` ends the options (everything after it is positional), a lone
 * `-` is positional (standard input/output). Errors (exit 2):
 *   unknown option "X" (see bumpgrad CMD --help)
 *   --opt needs a value
 *   --flag takes no value
 *   --opt: expected ..., got "TEXT"
 *
 * Converting a command (bench is the last one still parsed by hand):
 *   1. Put every option in a `CMD_args` struct; write `static void
 *      CMD_defaults(void *a)` that sets every default (bgt_height_init for a
 *      height, then overrides).
 *   2. Write `static const cli_opt CMD_opts[]`, one CLI_OPT_* entry per option
 *      (offsetof(CMD_args, field)), ending with CLI_OPT_END; include the
 *      shared height block with CLI_OPT_INCLUDE(offsetof(CMD_args, height),
 *      cli_height_opts, cli_height_heading).
 *   3. Write `static int CMD_run(void *args, const char *const *pos, int npos)`
 *      (the args are parsed: check what the table cannot, call one tools
 *      function, print) and `const cli_spec cli_spec_CMD = {..., .run =
 *      CMD_run}` (declared in cli.h).
 *   4. Give the command's line in main.c's table the spec (main.c then runs
 *      it through cli_run_command, and its --help, the completions and the
 *      man page come from it) and drop its cmd_CMD and `own` options (the
 *      --opt=value rewriting is only for commands without a spec).
 */
#ifndef BUMPGRAD_CLI_ARGS_H
#define BUMPGRAD_CLI_ARGS_H

#include <stddef.h>
#include <stdio.h>
#include "points/points.h" /* bgt_row_range, the --rows of cli_table_io */

typedef enum cli_opt_kind {
    CLI_KIND_END = 0,
    CLI_KIND_FLAG,    /* int field set to 1, no value */
    CLI_KIND_STRING,  /* const char * field (points into argv) */
    CLI_KIND_INT,     /* int field, integer in [lo, hi] */
    CLI_KIND_FLOAT,   /* float field, finite, range per flags */
    CLI_KIND_DOUBLE,  /* double field, finite, range per flags */
    CLI_KIND_CHOICE,  /* int field: choice_values[k] (or k) for the k-th of choices */
    CLI_KIND_CUSTOM,  /* parse(cmd, "--name", text, field) does it */
    CLI_KIND_INCLUDE  /* the options of `sub`, their offsets relative to `offset` */
} cli_opt_kind;

/* Flags of an option. */
enum {
    CLI_GT_LO = 1u << 0,     /* float/double: value > lo */
    CLI_GE_LO = 1u << 1,     /* float/double: value >= lo */
    CLI_REQUIRED = 1u << 2,  /* string: must be given */
    CLI_NO_DEFAULT = 1u << 3, /* do not print "(default ...)" */
    CLI_FILE = 1u << 4,      /* completion: a file name */
    CLI_DIR = 1u << 5,       /* completion: a directory */
    CLI_ZERO_NONE = 1u << 6, /* no "(default 0)": 0 means what the help says */
    CLI_FIRST = 1u << 7      /* set before every other option wherever it stands
                              * (render --preset: the other options override it) */
};

typedef struct cli_opt {
    const char *name;     /* long name without "--"; NULL for END and INCLUDE */
    char short_name;      /* 'o' for -o, 0 for none */
    cli_opt_kind kind;
    size_t offset;        /* offsetof(args struct, field) */
    const char *metavar;  /* "FILE", "N", ... (NULL for flags) */
    const char *help;     /* one paragraph, wrapped by the help printer */
    unsigned flags;
    double lo, hi;        /* INT: inclusive range; FLOAT/DOUBLE: see CLI_GT_LO/CLI_GE_LO */
    const char *const *choices; /* CHOICE: NULL-terminated names */
    const int *choice_values;   /* CHOICE: value stored for each name (NULL: its index) */
    /* CUSTOM: parse `text` (writable: it is argv's) into `field`; 0 or CLI_USAGE. */
    int (*parse)(const char *cmd, const char *opt, char *text, void *field);
    /* CUSTOM: the default in `field` as text; 0 if there is none to show. */
    int (*format)(const void *field, char *buf, size_t len);
    const struct cli_opt *sub; /* INCLUDE: the fragment */
    const char *heading;       /* INCLUDE: heading of its block in --help (NULL: inline) */
    const char *complete_ext;  /* CLI_FILE: extensions for completion, "csv|npy" */
} cli_opt;

#define CLI_OPT_END {0}
#define CLI_OPT_INCLUDE(off, table, head)                                                         \
    {.kind = CLI_KIND_INCLUDE, .offset = (off), .sub = (table), .heading = (head)}

typedef struct cli_spec {
    const char *name;    /* "eval" */
    const char *summary; /* one line, for `bumpgrad --help` and the man page's NAME */
    const char *usage;   /* what follows "Usage: bumpgrad NAME "; '\n' starts another form */
    const char *about;   /* text between the usage and the options (may be NULL) */
    const cli_opt *opts;
    const char *more;    /* text after the options: rules, exit status, examples */
    size_t args_size;
    void (*defaults)(void *args); /* sets every default; called first by cli_args_parse */
    int max_positional;  /* positional arguments accepted */
    const char *positional_ext; /* completion of positionals: extensions, or NULL for files */
    /* The command once parsed: `args` filled, pos[0..npos-1] its positionals.
     * Calls one tools function, prints, returns the exit code. */
    int (*run)(void *args, const char *const *pos, int npos);
} cli_spec;

/* A command's spec, `const cli_spec cli_spec_NAME`, with the fields every
 * command sets the same way: .name "NAME", the args struct NAME_args, its
 * defaults NAME_defaults and run_NAME (declared here, defined after the spec);
 * the rest (.summary, .usage, .opts, ...) as designated initializers:
 *   CLI_SPEC(eval, .summary = "...", .usage = "...", .opts = eval_opts);
 *   static int run_eval(void *args, const char *const *pos, int npos) { ... } */
#define CLI_SPEC(NAME, ...)                                                                        \
    static int run_##NAME(void *args, const char *const *pos, int npos);                           \
    const cli_spec cli_spec_##NAME = {.name = #NAME,                                               \
                                      .args_size = sizeof(NAME##_args),                            \
                                      .defaults = NAME##_defaults,                                 \
                                      .run = run_##NAME,                                           \
                                      __VA_ARGS__}

enum { CLI_MAX_POSITIONAL = 4096 }; /* volume --merge takes the bricks */

/* Returned by cli_args_parse after printing --help on stdout. */
enum { CLI_HELP = -1 };

/* Set *args to the defaults, then parse argv[1..argc-1] into it. Positional
 * arguments go to pos[0..*npos-1] (pos has room for spec->max_positional;
 * either may be NULL when max_positional is 0). Returns 0, CLI_HELP, or
 * CLI_USAGE after printing the error. */
int cli_args_parse(const cli_spec *spec, int argc, char **argv, void *args, const char **pos,
                   int *npos);

/* The whole command: parse argv into a zeroed args struct of the spec (the
 * help, usage errors), then spec->run. The `run` of main.c's table for
 * every command with a spec. Returns the exit code. */
int cli_run_command(const cli_spec *spec, int argc, char **argv);

/* The generated --help of a command. */
void cli_args_help(const cli_spec *spec, FILE *fp);
/* The option lines of table `t` (defaults read from `defs`, may be NULL). */
void cli_args_help_opts(FILE *fp, const cli_opt *t, const void *defs);
/* A man page (roff, section 1) of a command; `commands` NULL-terminated for
 * bumpgrad.1 itself when spec is NULL. */
void cli_args_man(const cli_spec *spec, FILE *fp, const char *version);
/* Completion scripts covering the whole command: `specs` are the converted
 * commands, `names` every command name (the unconverted ones complete files). */
void cli_args_completion_bash(FILE *fp, const cli_spec *const *specs, size_t nspecs,
                              const char *const *names, size_t nnames,
                              const char *const *global_opts);
void cli_args_completion_zsh(FILE *fp, const cli_spec *const *specs, size_t nspecs,
                             const char *const *names, size_t nnames,
                             const char *const *global_opts);

/* ---- shared fragments (heightopt.c) ---- */
/* --function --octaves --lacunarity --gain, offsets relative to a bg_fractal. */
extern const cli_opt cli_fractal_opts[];
/* The fractal options plus --amplitude --frequency --gradient --step
 * --height-grid, offsets relative to a bgt_height. */
extern const cli_opt cli_height_opts[];
/* --period and --seed into a bg_domain (noise.h), part of cli_height_opts;
 * eval includes it next to cli_fractal_opts. cli_domain_check: 0, or a usage
 * error that says what is wrong with the domain for fractal f. */
extern const cli_opt cli_domain_opts[];
struct bg_fractal;
struct bg_domain;
int cli_domain_check(const char *cmd, const struct bg_fractal *f, const struct bg_domain *d);
extern const char cli_height_heading[];
/* --input/-i and --output/-o of the table commands (eval, perturb), both
 * required, relative to a cli_table_io. */
typedef struct cli_table_io {
    const char *input, *output;
    bgt_row_range rows; /* --rows A:B (a .npy input's rows A..B-1; points.h) */
} cli_table_io;
extern const cli_opt cli_table_io_opts[];
/* --threads N (0 = all cores, up to 1024), relative to an int. */
extern const cli_opt cli_threads_opts[];
/* Choice names shared by several commands. */
extern const char *const cli_function_choices[];
extern const int cli_function_values[];
extern const char *const cli_method_choices[];
extern const int cli_method_values[];

#endif
