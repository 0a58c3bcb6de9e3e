/*
 * The command line of the programs in bench/ and examples/: optional
 * positional arguments, --help, and one message for a bad argument.  The one
 * place where these programs parse their arguments.
 *
 *   static size_t N = 9991;
 *   static const cli_arg args[] = {
 *       {"N", CLI_COUNT, &N, 0, "steps per delay: h = tau/N"}};
 *   static const cli_program prog = {"ex43", "Runs Example 4.3.", "CSV rows t,w,v.",
 *                                    args, 1};
 *   cli_parse(&prog, argc, argv);
 *
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_CLI_H
#define DMI_CLI_H

#include <stddef.h>

typedef enum {
    CLI_COUNT, /* size_t, decimal digits, 1 <= value <= max (max 0: SIZE_MAX) */
    CLI_TIME,  /* double, finite, 0 < value <= max (max 0: no bound) */
    CLI_PATH   /* const char *, any non-empty string (a file the program writes) */
} cli_kind;

typedef struct {
    const char *name; /* as in the usage line, e.g. "N" */
    cli_kind kind;
    void *value;      /* size_t *, double * or const char **: holds the default, gets the value */
    double max;       /* the largest value accepted (CLI_COUNT, CLI_TIME); 0: no bound */
    const char *help; /* what it means and its unit (--help adds the default and max) */
} cli_arg;

typedef struct {
    const char *name;    /* the program's name */
    const char *purpose; /* what it does (one or more lines) */
    const char *output;  /* what it prints, where, and its exit status ("stdout: ...") */
    const cli_arg *args; /* the optional positional arguments, in order */
    size_t n_args;
} cli_program;

/*
 * Parses argv into the arguments' values.  "--help" or "-h" anywhere: prints
 * the usage to stdout and exits with 0.  A bad or surplus argument: prints
 * "<program>: <name> = '<text>': <why>" and the usage line to stderr and
 * exits with 2.  Returns only if every argument is good.
 */
void cli_parse(const cli_program *prog, int argc, char **argv);

/*
 * Rejects an argument that parsed but does not fit the others (e.g. a T
 * that gives no step): prints "<program>: <name> = '<text>': <why>" and the
 * usage line to stderr and exits with 2.
 */
void cli_reject(const cli_program *prog, const char *name, const char *text, const char *why);

#endif
