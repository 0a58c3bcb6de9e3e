/*
 * One paper example (EXAMPLE = 41, 42 or 43, set by the build: programs ex41,
 * ex42, ex43): writes the CSV to stdout, "t,w,v,w_exact,v_exact" for 4.1 and
 * 4.2 (from t = -tau), "t,w,v" for 4.3 (from t = 0), and a summary to stderr.
 * Usage: exNN [N [T [stride]]]   (defaults 9991, 10 (30 for 4.3), 1); exNN --help
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "cli.h"
#include "paper.h"

#ifndef EXAMPLE
#error "define EXAMPLE as 41, 42 or 43"
#endif

#define STR_(x) #x
#define STR(x) STR_(x)

#if EXAMPLE == 43
#define WHAT "Example 4.3 of the paper: the friction oscillator (4.1) with kernel\n" \
             "H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s and forcing 1.3 cos 8t (no exact solution)"
#define T_DEFAULT 30
#define ROWS "\"t,w,v\", then one row per stride-th step t_p from\n" \
             "  t = 0 to T (T*N/stride + 2 lines: with no arguments about 300,000 lines;\n" \
             "  pipe it to a file or give a stride)"
#elif EXAMPLE == 42
#define WHAT "Example 4.2 of the paper: the friction oscillator (4.1) with H = 1 and the\n" \
             "forcing (4.9) of the exact solution (4.10)"
#else
#define WHAT "Example 4.1 of the paper: the friction oscillator (4.1) with H = 1 and the\n" \
             "forcing (4.7) of the exact solution (4.8)"
#endif
#if EXAMPLE != 43
#define T_DEFAULT 10
#define ROWS "\"t,w,v,w_exact,v_exact\", then one row per\n" \
             "  stride-th t_p from t = -tau to T\n" \
             "  ((1 + T)*N/stride + 2 lines: with no arguments about 110,000 lines)"
#endif

int main(int argc, char **argv)
{
    const int ex = EXAMPLE;
    size_t N = 9991, stride = 1;
    double T = T_DEFAULT;
    const cli_arg args[] = {
        {"N", CLI_COUNT, &N, 1e9, "steps per delay: h = tau/N with tau = 1"},
        {"T", CLI_TIME, &T, 1e6, "end time"},
        {"stride", CLI_COUNT, &stride, 0, "write only every stride-th step"}};
    const cli_program prog = {
        "ex" STR(EXAMPLE),
        "Integrates " WHAT ",\nb = alpha = tau = 1, with libdmi's implicit Euler scheme (3.12)-(3.13).",
        "stdout: CSV with the header " ROWS ".\n"
        "stderr: a summary (h, steps, maximal errors if exact, static and dynamic phases).\n"
        "exit status: 0, 1 if the solver fails, 2 for a bad argument.",
        args, sizeof args / sizeof args[0]};
    cli_parse(&prog, argc, argv);
    paper_result r;
    int rc = paper_run(ex, N, T, DMI_CONV_AUTO, stdout, stride, &r);
    if (rc != DMI_OK) {
        fprintf(stderr, "ex%d: N = %zu, T = %g: %s\n", ex, N, T, dmi_strerror(rc));
        return 1;
    }
    fprintf(stderr, "example %d.%d: h = 1/%zu, %zu steps, ", ex / 10, ex % 10, N, r.steps);
    if (paper_has_exact(ex))
        fprintf(stderr, "max error %.4e (w %.4e, v %.4e), ", r.max_err_state, r.max_err_w,
                r.max_err_v);
    fprintf(stderr, "%zu static and %zu dynamic phases\n", r.static_phases, r.dynamic_phases);
    return 0;
}
