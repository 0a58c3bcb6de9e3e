/*
 * The command line of the programs in bench/ and examples/ (cli.h).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "cli.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void usage_line(const cli_program *prog, FILE *out)
{
    fprintf(out, "usage: %s [--help]", prog->name);
    for (size_t i = 0; i < prog->n_args; i++)
        fprintf(out, " [%s", prog->args[i].name);
    for (size_t i = 0; i < prog->n_args; i++)
        fputc(']', out);
    fputc('\n', out);
}

static void help(const cli_program *prog)
{
    usage_line(prog, stdout);
    printf("\n%s\n", prog->purpose);
    if (prog->n_args > 0)
        printf("\narguments (optional, in this order):\n");
    for (size_t i = 0; i < prog->n_args; i++) {
        const cli_arg *a = &prog->args[i];
        printf("  %-10s %s", a->name, a->help);
        if (a->kind == CLI_COUNT)
            printf(" (default %zu", *(const size_t *)a->value);
        else if (a->kind == CLI_TIME)
            printf(" (default %g", *(const double *)a->value);
        else if (*(const char *const *)a->value)
            printf(" (default %s", *(const char *const *)a->value);
        else
            printf(" (default: none");
        if (a->max > 0)
            printf(", at most %.15g", a->max);
        puts(")");
    }
    printf("\n%s\n", prog->output);
}

/* After the message of a bad command line: the usage line and a pointer to
 * --help on stderr, exit status 2. */
static void refuse(const cli_program *prog)
{
    usage_line(prog, stderr);
    fprintf(stderr, "(%s --help explains the arguments)\n", prog->name);
    exit(2);
}

void cli_reject(const cli_program *prog, const char *name, const char *text, const char *why)
{
    fprintf(stderr, "%s: %s = '%s': %s\n", prog->name, name, text, why);
    refuse(prog);
}

/* Sets *a's value from text and returns NULL, or returns why text is not a value of a
 * (in why, of size n, when the message holds the bound). */
static const char *parse(const cli_arg *a, const char *text, char *why, size_t n)
{
    char *end;
    errno = 0;
    switch (a->kind) {
    case CLI_COUNT: {
        if (!isdigit((unsigned char)text[0]))
            return "must be a whole number >= 1 (decimal digits)";
        unsigned long long v = strtoull(text, &end, 10);
        if (*end != '\0')
            return "must be a whole number >= 1 (decimal digits)";
        if (v == 0)
            return "must be >= 1";
        if (errno != 0 || v > SIZE_MAX)
            return "is too large";
        if (a->max > 0 && (double)v > a->max) {
            snprintf(why, n, "must be at most %.15g", a->max);
            return why;
        }
        *(size_t *)a->value = (size_t)v;
        return NULL;
    }
    case CLI_TIME: {
        double v = strtod(text, &end);
        if (text[0] == '\0' || *end != '\0' || isnan(v))
            return "must be a number > 0";
        if (!(v > 0))
            return "must be > 0";
        if (!isfinite(v))
            return "must be finite";
        if (a->max > 0 && v > a->max) {
            snprintf(why, n, "must be at most %.15g", a->max);
            return why;
        }
        *(double *)a->value = v;
        return NULL;
    }
    case CLI_PATH:
        if (text[0] == '\0')
            return "must be a file name";
        *(const char **)a->value = text;
        return NULL;
    }
    return "has an unknown kind (a bug in the program)";
}

void cli_parse(const cli_program *prog, int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
            help(prog);
            exit(0);
        }
    for (int i = 1; i < argc; i++) {
        if ((size_t)(i - 1) >= prog->n_args) {
            fprintf(stderr, "%s: too many arguments: '%s' (at most %zu)\n", prog->name, argv[i],
                    prog->n_args);
            refuse(prog);
        }
        const cli_arg *a = &prog->args[i - 1];
        char buf[64];
        const char *why = parse(a, argv[i], buf, sizeof buf);
        if (why)
            cli_reject(prog, a->name, argv[i], why);
    }
}
