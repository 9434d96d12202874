/* SPDX-License-Identifier: MIT */
/* The table-driven option parser, --help, man page and completion generator
 * (see args.h). */
#define _POSIX_C_SOURCE 200809L
#include "args.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"

/* ---- walking the tables (INCLUDE nests) ---------------------------------- */

typedef struct found {
    const cli_opt *opt;
    size_t base; /* offset of the fragment the option belongs to */
} found;

static int find_long(const cli_opt *t, size_t base, const char *name, size_t len, found *f)
{
    for (; t->kind != CLI_KIND_END; t++) {
        if (t->kind == CLI_KIND_INCLUDE) {
            if (find_long(t->sub, base + t->offset, name, len, f))
                return 1;
        } else if (strlen(t->name) == len && memcmp(t->name, name, len) == 0) {
            f->opt = t, f->base = base;
            return 1;
        }
    }
    return 0;
}

static int find_short(const cli_opt *t, size_t base, char c, found *f)
{
    for (; t->kind != CLI_KIND_END; t++) {
        if (t->kind == CLI_KIND_INCLUDE) {
            if (find_short(t->sub, base + t->offset, c, f))
                return 1;
        } else if (t->short_name == c) {
            f->opt = t, f->base = base;
            return 1;
        }
    }
    return 0;
}

static void *field_at(void *args, const found *f)
{
    return (char *)args + f->base + f->opt->offset;
}

static int choice_value(const cli_opt *o, int k)
{
    return o->choice_values ? o->choice_values[k] : k;
}

static void choice_list(const cli_opt *o, char *buf, size_t len)
{
    buf[0] = '\0';
    for (int k = 0; o->choices[k]; k++) {
        if (k)
            strncat(buf, o->choices[k + 1] ? ", " : " or ", len - strlen(buf) - 1);
        strncat(buf, o->choices[k], len - strlen(buf) - 1);
    }
}

static int set_value(const char *cmd, const cli_opt *o, const char *optname, char *v, void *field)
{
    long l;
    float f;
    double d;
    switch (o->kind) {
    case CLI_KIND_STRING:
        *(const char **)field = v;
        return 0;
    case CLI_KIND_INT:
        if (cli_parse_int(cmd, optname, v, (long)o->lo, (long)o->hi, &l))
            return CLI_USAGE;
        *(int *)field = (int)l;
        return 0;
    case CLI_KIND_FLOAT:
    case CLI_KIND_DOUBLE:
        if (o->kind == CLI_KIND_FLOAT) {
            if (cli_parse_float(cmd, optname, v, &f))
                return CLI_USAGE;
            d = f;
        } else if (cli_parse_double(cmd, optname, v, &d)) {
            return CLI_USAGE;
        }
        if ((o->flags & CLI_GT_LO) && !(d > o->lo))
            return cli_usage_error(cmd, "%s: must be > %g, got \"%s\"", optname, o->lo, v);
        if ((o->flags & CLI_GE_LO) && !(d >= o->lo))
            return cli_usage_error(cmd, "%s: must be >= %g, got \"%s\"", optname, o->lo, v);
        if (o->kind == CLI_KIND_FLOAT)
            *(float *)field = f;
        else
            *(double *)field = d;
        return 0;
    case CLI_KIND_CHOICE:
        for (int k = 0; o->choices[k]; k++)
            if (strcmp(o->choices[k], v) == 0) {
                *(int *)field = choice_value(o, k);
                return 0;
            }
        {
            char list[256];
            choice_list(o, list, sizeof list);
            return cli_usage_error(cmd, "%s: expected %s, got \"%s\"", optname, list, v);
        }
    case CLI_KIND_CUSTOM:
        return o->parse(cmd, optname, v, field) ? CLI_USAGE : 0;
    default:
        return CLI_USAGE;
    }
}

static int check_required(const char *cmd, const cli_opt *t, size_t base, const void *args)
{
    for (; t->kind != CLI_KIND_END; t++) {
        if (t->kind == CLI_KIND_INCLUDE) {
            int rc = check_required(cmd, t->sub, base + t->offset, args);
            if (rc)
                return rc;
        } else if ((t->flags & CLI_REQUIRED) && t->kind == CLI_KIND_STRING &&
                   !*(const char *const *)(const void *)((const char *)args + base + t->offset)) {
            return cli_usage_error(cmd, "--%s is required (see bumpgrad %s --help)", t->name, cmd);
        }
    }
    return 0;
}

static int add_positional(const cli_spec *spec, const char **pos, int *n, const char *a)
{
    const char *cmd = spec->name;
    if (*n >= spec->max_positional) {
        if (spec->max_positional == 0)
            return cli_usage_error(cmd, "unexpected argument \"%s\" (see bumpgrad %s --help)", a,
                                   cmd);
        return cli_usage_error(cmd, "unexpected argument \"%s\": expected at most %d "
                                    "(see bumpgrad %s --help)", a, spec->max_positional, cmd);
    }
    pos[(*n)++] = a;
    return 0;
}

/* One pass over argv. The pre-pass (`first`) sets only the CLI_FIRST options
 * and skips everything else with its value; the main pass reports every
 * error and skips the CLI_FIRST options. */
static int parse_pass(const cli_spec *spec, int argc, char **argv, void *args, const char **pos,
                      int *npos, int first)
{
    const char *cmd = spec->name;
    int n = 0, rc;
    for (int i = 1; i < argc; i++) {
        char *a = argv[i];
        if (strcmp(a, "--") == 0) {
            /* Everything after it is positional. */
            while (!first && ++i < argc)
                if ((rc = add_positional(spec, pos, &n, argv[i])) != 0)
                    return rc;
            break;
        }
        if (a[0] != '-' || a[1] == '\0') {
            if (!first && (rc = add_positional(spec, pos, &n, a)) != 0)
                return rc;
            continue;
        }
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            if (first)
                continue;
            cli_args_help(spec, stdout);
            return CLI_HELP;
        }
        found f;
        char optname[80];
        char *value = NULL;
        int ok;
        if (a[1] == '-') {
            const char *name = a + 2;
            char *eq = strchr(a + 2, '=');
            size_t len = eq ? (size_t)(eq - name) : strlen(name);
            ok = find_long(spec->opts, 0, name, len, &f);
            if (ok && eq)
                value = eq + 1;
        } else {
            ok = find_short(spec->opts, 0, a[1], &f);
            if (ok && a[2])
                value = a + 2;
        }
        if (!ok) {
            if (first)
                continue;
            char shown[80];
            const char *eq = a[1] == '-' ? strchr(a, '=') : NULL;
            size_t len = eq ? (size_t)(eq - a) : strlen(a);
            if (len >= sizeof shown)
                len = sizeof shown - 1;
            memcpy(shown, a, len);
            shown[len] = '\0';
            return cli_usage_error(cmd, "unknown option \"%s\" (see bumpgrad %s --help)", shown,
                                   cmd);
        }
        /* Whether this pass sets the option (the other one only skips it). */
        int here = !(f.opt->flags & CLI_FIRST) == !first;
        snprintf(optname, sizeof optname, "--%s", f.opt->name);
        if (f.opt->kind == CLI_KIND_FLAG) {
            if (here && value)
                return cli_usage_error(cmd, "%s takes no value, got \"%s\"", optname, a);
            if (here)
                *(int *)field_at(args, &f) = 1;
            continue;
        }
        if (!value) {
            if (i + 1 >= argc)
                return first ? 0 : cli_usage_error(cmd, "%s needs a value", a);
            value = argv[++i];
        }
        if (here && (rc = set_value(cmd, f.opt, optname, value, field_at(args, &f))) != 0)
            return rc;
    }
    if (npos)
        *npos = n;
    return 0;
}

int cli_args_parse(const cli_spec *spec, int argc, char **argv, void *args, const char **pos,
                   int *npos)
{
    if (spec->defaults)
        spec->defaults(args);
    int rc = parse_pass(spec, argc, argv, args, pos, npos, 1);
    if (!rc)
        rc = parse_pass(spec, argc, argv, args, pos, npos, 0);
    return rc ? rc : check_required(spec->name, spec->opts, 0, args);
}

int cli_run_command(const cli_spec *spec, int argc, char **argv)
{
    const char *pos[CLI_MAX_POSITIONAL] = {NULL};
    int npos = 0;
    void *args = calloc(1, spec->args_size);
    if (!args)
        return cli_fail(spec->name, "out of memory");
    int rc = spec->max_positional > CLI_MAX_POSITIONAL
                 ? cli_fail(spec->name, "too many positional arguments in the table")
                 : cli_args_parse(spec, argc, argv, args, pos, &npos);
    if (rc == 0)
        rc = spec->run(args, pos, npos);
    else if (rc == CLI_HELP)
        rc = CLI_OK;
    free(args);
    return rc;
}

/* ---- --help -------------------------------------------------------------- */

enum { HELP_COL = 26, HELP_WIDTH = 79 };

/* The default of an option as text; 0 if none is shown. */
static int default_text(const cli_opt *o, const void *field, char *buf, size_t len)
{
    if (!field || (o->flags & (CLI_NO_DEFAULT | CLI_REQUIRED)))
        return 0;
    switch (o->kind) {
    case CLI_KIND_STRING: {
        const char *s = *(const char *const *)field;
        if (!s)
            return 0;
        snprintf(buf, len, "%s", s);
        return 1;
    }
    case CLI_KIND_INT:
    case CLI_KIND_FLOAT:
    case CLI_KIND_DOUBLE: {
        /* Every int and float is exact in a double. */
        double v = o->kind == CLI_KIND_INT     ? *(const int *)field
                   : o->kind == CLI_KIND_FLOAT ? (double)*(const float *)field
                                               : *(const double *)field;
        if ((o->flags & CLI_ZERO_NONE) && v == 0)
            return 0;
        snprintf(buf, len, o->kind == CLI_KIND_INT ? "%.0f" : "%g", v);
        return 1;
    }
    case CLI_KIND_CHOICE:
        for (int k = 0; o->choices[k]; k++)
            if (choice_value(o, k) == *(const int *)field) {
                snprintf(buf, len, "%s", o->choices[k]);
                return 1;
            }
        return 0;
    case CLI_KIND_CUSTOM:
        return o->format ? o->format(field, buf, len) : 0;
    default:
        return 0;
    }
}

/* "-o, --output FILE" */
static void left_text(const cli_opt *o, char *buf, size_t len)
{
    char mv[64] = "";
    if (o->kind != CLI_KIND_FLAG) {
        if (o->metavar)
            snprintf(mv, sizeof mv, " %s", o->metavar);
        else if (o->kind == CLI_KIND_CHOICE) {
            mv[0] = ' ';
            for (int k = 0; o->choices[k]; k++) {
                if (k)
                    strncat(mv, "|", sizeof mv - strlen(mv) - 1);
                strncat(mv, o->choices[k], sizeof mv - strlen(mv) - 1);
            }
        } else
            snprintf(mv, sizeof mv, " VALUE");
    }
    if (o->short_name)
        snprintf(buf, len, "-%c, --%s%s", o->short_name, o->name, mv);
    else
        snprintf(buf, len, "--%s%s", o->name, mv);
}

/* Word-wrap `text` from column `col` to HELP_WIDTH; continuation lines start at `indent`. */
static void wrap(FILE *fp, const char *text, int col, int indent)
{
    const char *p = text;
    while (*p) {
        while (*p == ' ')
            p++;
        const char *w = p;
        while (*p && *p != ' ')
            p++;
        int wl = (int)(p - w);
        if (wl == 0)
            break;
        if (col > indent && col + 1 + wl > HELP_WIDTH) {
            fprintf(fp, "\n%*s", indent, "");
            col = indent;
        } else if (col > indent) {
            fputc(' ', fp);
            col++;
        }
        for (int k = 0; k < wl; k++)
            fputc(w[k] == '\x01' ? ' ' : w[k], fp);
        col += wl;
    }
    fputc('\n', fp);
}

static void help_opts(FILE *fp, const cli_opt *t, const void *defs, int top)
{
    for (; t->kind != CLI_KIND_END; t++) {
        if (t->kind == CLI_KIND_INCLUDE) {
            if (t->heading)
                fprintf(fp, "\n%s\n", t->heading);
            help_opts(fp, t->sub, defs ? (const char *)defs + t->offset : NULL, 0);
            continue;
        }
        char left[96], def[96], text[1024];
        left_text(t, left, sizeof left);
        const void *field = defs ? (const char *)defs + t->offset : NULL;
        snprintf(text, sizeof text, "%s", t->help ? t->help : "");
        if (t->flags & CLI_REQUIRED)
            strncat(text, " (required)", sizeof text - strlen(text) - 1);
        else if (default_text(t, field, def, sizeof def)) {
            size_t l = strlen(text);
            /* \x01: a space the wrapping keeps, so "(default X)" stays on one line */
            snprintf(text + l, sizeof text - l, " (default\x01%s)", def);
        }
        int col = fprintf(fp, "  %s", left);
        if (col + 2 > HELP_COL) {
            fprintf(fp, "\n%*s", HELP_COL, "");
            col = HELP_COL;
        } else {
            fprintf(fp, "%*s", HELP_COL - col, "");
            col = HELP_COL;
        }
        wrap(fp, text, col, HELP_COL);
    }
    (void)top;
}

void cli_args_help_opts(FILE *fp, const cli_opt *t, const void *defs)
{
    help_opts(fp, t, defs, 0);
}

static void *make_defaults(const cli_spec *s)
{
    if (!s->defaults || !s->args_size)
        return NULL;
    void *d = calloc(1, s->args_size);
    if (d)
        s->defaults(d);
    return d;
}

void cli_args_help(const cli_spec *s, FILE *fp)
{
    const char *u = s->usage;
    int first = 1;
    while (u && *u) {
        const char *nl = strchr(u, '\n');
        size_t len = nl ? (size_t)(nl - u) : strlen(u);
        fprintf(fp, "%s bumpgrad %s %.*s\n", first ? "Usage:" : "      ", s->name, (int)len, u);
        first = 0;
        u += len + (nl ? 1 : 0);
    }
    if (first)
        fprintf(fp, "Usage: bumpgrad %s [options]\n", s->name);
    fputc('\n', fp);
    if (s->about)
        fprintf(fp, "%s\n", s->about);
    fputs("Options:\n", fp);
    void *d = make_defaults(s);
    help_opts(fp, s->opts, d, 1);
    free(d);
    fputs("  -h, --help              this help\n"
          "\nGlobal options (anywhere): --isa NAME, -q/--quiet, --progress, -v/--verbose\n"
          "(see bumpgrad --help).\n",
          fp);
    if (s->more)
        fprintf(fp, "\n%s", s->more);
}

/* ---- man pages ----------------------------------------------------------- */

static void roff_text(FILE *fp, const char *s)
{
    int bol = 1;
    for (; *s; s++) {
        if (bol && (*s == '.' || *s == '\''))
            fputs("\\&", fp);
        if (*s == '\\')
            fputs("\\e", fp);
        else if (*s == '-')
            fputs("\\-", fp);
        else
            fputc(*s, fp);
        bol = *s == '\n';
    }
}

static void man_opts(FILE *fp, const cli_opt *t, const void *defs)
{
    for (; t->kind != CLI_KIND_END; t++) {
        if (t->kind == CLI_KIND_INCLUDE) {
            if (t->heading) {
                fputs(".SS ", fp);
                roff_text(fp, t->heading);
                fputc('\n', fp);
            }
            man_opts(fp, t->sub, defs ? (const char *)defs + t->offset : NULL);
            continue;
        }
        char left[96], def[96];
        left_text(t, left, sizeof left);
        fputs(".TP\n.B ", fp);
        roff_text(fp, left);
        fputc('\n', fp);
        roff_text(fp, t->help ? t->help : "");
        const void *field = defs ? (const char *)defs + t->offset : NULL;
        if (t->flags & CLI_REQUIRED)
            fputs(" (required)", fp);
        else if (default_text(t, field, def, sizeof def)) {
            fputs(" (default ", fp);
            roff_text(fp, def);
            fputc(')', fp);
        }
        fputc('\n', fp);
    }
}

void cli_args_man(const cli_spec *s, FILE *fp, const char *version)
{
    fprintf(fp, ".TH BUMPGRAD-%s 1 \"\" \"bumpgrad %s\" \"User Commands\"\n", s->name, version);
    fputs(".SH NAME\nbumpgrad\\-", fp);
    roff_text(fp, s->name);
    fputs(" \\- ", fp);
    roff_text(fp, s->summary ? s->summary : "");
    fputs("\n.SH SYNOPSIS\n", fp);
    const char *u = s->usage ? s->usage : "[options]";
    while (*u) {
        const char *nl = strchr(u, '\n');
        size_t len = nl ? (size_t)(nl - u) : strlen(u);
        char line[512];
        snprintf(line, sizeof line, "%.*s", (int)len, u);
        fprintf(fp, ".B bumpgrad %s\n", s->name);
        roff_text(fp, line);
        fputs("\n.br\n", fp);
        u += len + (nl ? 1 : 0);
    }
    if (s->about) {
        fputs(".SH DESCRIPTION\n.nf\n", fp);
        roff_text(fp, s->about);
        fputs(".fi\n", fp);
    }
    fputs(".SH OPTIONS\n", fp);
    void *d = make_defaults(s);
    man_opts(fp, s->opts, d);
    free(d);
    fputs(".TP\n.B \\-h, \\-\\-help\nthis help\n"
          ".SS Global options (anywhere on the command line)\n"
          ".TP\n.B \\-\\-isa NAME\nrun the SIMD kernels at ISA level NAME\n"
          ".TP\n.B \\-q, \\-\\-quiet\nonly errors on stderr; no summary lines\n"
          ".TP\n.B \\-\\-progress\nshow progress on stderr even when it is not a terminal\n"
          ".TP\n.B \\-v, \\-\\-verbose\nmore detail (timings, rates) on stderr\n",
          fp);
    if (s->more) {
        fputs(".SH NOTES\n.nf\n", fp);
        roff_text(fp, s->more);
        fputs(".fi\n", fp);
    }
    fputs(".SH ENVIRONMENT\n.TP\n.B BUMPGRAD_ISA\nsame as \\-\\-isa\n"
          ".TP\n.B BUMPGRAD_NO_PROGRESS\nif set, no progress line on a terminal "
          "(\\-\\-progress still forces it)\n"
          ".SH SEE ALSO\n.BR bumpgrad (1)\n",
          fp);
}

/* ---- completions ----------------------------------------------------------- */

typedef void (*opt_visit)(FILE *fp, const cli_opt *o, void *ctx);

static void visit(const cli_opt *t, FILE *fp, opt_visit f, void *ctx)
{
    for (; t->kind != CLI_KIND_END; t++) {
        if (t->kind == CLI_KIND_INCLUDE)
            visit(t->sub, fp, f, ctx);
        else
            f(fp, t, ctx);
    }
}

static void bash_words(FILE *fp, const cli_opt *o, void *ctx)
{
    (void)ctx;
    fprintf(fp, " --%s", o->name);
    if (o->short_name)
        fprintf(fp, " -%c", o->short_name);
}

/* What completes an option's value, in each shell's syntax. */
typedef struct shell_values {
    const char *choices_open, *choices_close; /* around the space-separated choices */
    const char *dir, *file;
    const char *other_open, *other_close; /* around the metavar (NULL: no metavar) */
} shell_values;

static const shell_values bash_syntax = {
    " COMPREPLY=($(compgen -W \"", "\" -- \"$cur\")); return;;\n",
    " COMPREPLY=($(compgen -d -- \"$cur\")); return;;\n",
    " COMPREPLY=($(compgen -f -- \"$cur\")); return;;\n", " return;;\n", NULL};
static const shell_values zsh_syntax = {":value:(", ")", ":directory:_files -/", ":file:_files",
                                        ":", ": "};

static void put_values(FILE *fp, const cli_opt *o, const shell_values *sh)
{
    if (o->choices) {
        fputs(sh->choices_open, fp);
        for (int k = 0; o->choices[k]; k++)
            fprintf(fp, "%s%s", k ? " " : "", o->choices[k]);
        fputs(sh->choices_close, fp);
    } else if (o->flags & CLI_DIR) {
        fputs(sh->dir, fp);
    } else if (o->flags & CLI_FILE) {
        fputs(sh->file, fp);
    } else if (o->kind != CLI_KIND_FLAG) {
        fputs(sh->other_open, fp);
        if (sh->other_close)
            fprintf(fp, "%s%s", o->metavar ? o->metavar : "value", sh->other_close);
    }
}

static void bash_values(FILE *fp, const cli_opt *o, void *ctx)
{
    (void)ctx;
    if (o->kind == CLI_KIND_FLAG)
        return;
    fprintf(fp, "            --%s", o->name);
    if (o->short_name)
        fprintf(fp, "|-%c", o->short_name);
    fputs(")", fp);
    put_values(fp, o, &bash_syntax);
}

void cli_args_completion_bash(FILE *fp, const cli_spec *const *specs, size_t nspecs,
                              const char *const *names, size_t nnames,
                              const char *const *global_opts)
{
    fputs("# bash completion for bumpgrad (generated by `bumpgrad completion bash`)\n"
          "_bumpgrad() {\n"
          "    local cur prev cmd i\n"
          "    cur=\"${COMP_WORDS[COMP_CWORD]}\"\n"
          "    prev=\"${COMP_WORDS[COMP_CWORD-1]}\"\n"
          "    cmd=\"\"\n"
          "    for ((i = 1; i < COMP_CWORD; i++)); do\n"
          "        case \"${COMP_WORDS[i]}\" in\n"
          "            --isa) ((i++));;\n"
          "            -*) ;;\n"
          "            *) cmd=\"${COMP_WORDS[i]}\"; break;;\n"
          "        esac\n"
          "    done\n"
          "    if [[ \"$prev\" == --isa ]]; then\n"
          "        COMPREPLY=($(compgen -W \"scalar sse2 avx2 avx512 neon\" -- \"$cur\")); return\n"
          "    fi\n"
          "    local globals=\"",
          fp);
    for (size_t k = 0; global_opts[k]; k++)
        fprintf(fp, "%s%s", k ? " " : "", global_opts[k]);
    fputs("\"\n    if [[ -z \"$cmd\" ]]; then\n        COMPREPLY=($(compgen -W \"$globals --help --version help",
          fp);
    for (size_t k = 0; k < nnames; k++)
        fprintf(fp, " %s", names[k]);
    fputs("\" -- \"$cur\")); return\n    fi\n    case \"$cmd\" in\n", fp);
    for (size_t k = 0; k < nspecs; k++) {
        const cli_spec *s = specs[k];
        fprintf(fp, "    %s)\n        case \"$prev\" in\n", s->name);
        visit(s->opts, fp, bash_values, NULL);
        fputs("        esac\n        if [[ \"$cur\" == -* ]]; then\n"
              "            COMPREPLY=($(compgen -W \"$globals --help",
              fp);
        visit(s->opts, fp, bash_words, NULL);
        fputs("\" -- \"$cur\"))\n        else\n"
              "            COMPREPLY=($(compgen -f -- \"$cur\"))\n        fi;;\n",
              fp);
    }
    fputs("    *) COMPREPLY=($(compgen -f -- \"$cur\"));;\n    esac\n}\n"
          "complete -o filenames -F _bumpgrad bumpgrad\n",
          fp);
}

static void zsh_escape(FILE *fp, const char *s)
{
    for (; *s; s++) {
        if (*s == '\'')
            fputs("'\\''", fp);
        else if (*s == '[' || *s == ']' || *s == ':')
            fprintf(fp, "\\%c", *s);
        else
            fputc(*s, fp);
    }
}

static void zsh_spec(FILE *fp, const cli_opt *o, void *ctx)
{
    (void)ctx;
    char first[80];
    const char *h = o->help ? o->help : "";
    size_t n = strcspn(h, ";(,");
    if (n > 60)
        n = 60;
    snprintf(first, sizeof first, "%.*s", (int)n, h);
    while (n > 0 && first[n - 1] == ' ')
        first[--n] = '\0';
    fputs("        '", fp);
    if (o->short_name)
        fprintf(fp, "(-%c --%s)'{-%c,--%s}'", o->short_name, o->name, o->short_name, o->name);
    else
        fprintf(fp, "--%s", o->name);
    if (o->kind != CLI_KIND_FLAG)
        fputs("=", fp);
    fputs("[", fp);
    zsh_escape(fp, first);
    fputs("]", fp);
    put_values(fp, o, &zsh_syntax);
    fputs("' \\\n", fp);
}

void cli_args_completion_zsh(FILE *fp, const cli_spec *const *specs, size_t nspecs,
                             const char *const *names, size_t nnames,
                             const char *const *global_opts)
{
    (void)global_opts;
    fputs("#compdef bumpgrad\n# zsh completion for bumpgrad (generated by `bumpgrad completion zsh`)\n"
          "_bumpgrad() {\n"
          "    local -a globals\n"
          "    globals=('--isa=[SIMD level]:level:(scalar sse2 avx2 avx512 neon)'\n"
          "             '(-q --quiet)'{-q,--quiet}'[only errors]'\n"
          "             '--progress[progress even on a pipe]'\n"
          "             '(-v --verbose)'{-v,--verbose}'[more detail]')\n"
          "    local cmd i\n"
          "    for ((i = 2; i < CURRENT; i++)); do\n"
          "        case $words[i] in\n"
          "            --isa) ((i++));;\n"
          "            -*) ;;\n"
          "            *) cmd=$words[i]; break;;\n"
          "        esac\n"
          "    done\n"
          "    if [[ -z $cmd ]]; then\n"
          "        _arguments $globals '--help[help]' '--version[version]' ':command:(help",
          fp);
    for (size_t k = 0; k < nnames; k++)
        fprintf(fp, " %s", names[k]);
    fputs(")'\n        return\n    fi\n    case $cmd in\n", fp);
    for (size_t k = 0; k < nspecs; k++) {
        fprintf(fp, "    %s)\n        _arguments $globals \\\n", specs[k]->name);
        visit(specs[k]->opts, fp, zsh_spec, NULL);
        fputs("        '(-h --help)'{-h,--help}'[this help]' \\\n        '*:file:_files';;\n", fp);
    }
    fputs("    *) _files;;\n    esac\n}\n_bumpgrad \"$@\"\n", fp);
}
