/*
 * The C side of the Python binding's benchmark (bench_binding.py runs it once
 * per round, interleaved with the Python runs): Example 4.3 (tau = 1,
 * h = 1/N) with its kernel as three exponential terms (paper_set_kernel_exp43,
 * the default method: the recursion) and the built-in friction, the rhs the C
 * function paper_rhs; times dmi_advance over the given steps (CPU time of the
 * process) after dmi_init.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <stdio.h>

#include "cli.h"
#include "paper.h"

int main(int argc, char **argv)
{
    size_t N = 10000, steps = 1000000;
    const cli_arg args[] = {{"N", CLI_COUNT, &N, 1e8, "steps per delay: h = 1/N"},
                            {"steps", CLI_COUNT, &steps, 1e10, "steps timed"}};
    const cli_program prog = {
        "bench_binding",
        "Times Example 4.3 with its kernel as exponential terms, built-in friction and the\n"
        "rhs in C (dmi_advance): the C reference of bench/bench_binding.py.",
        "stdout: one line 'ns_per_step <value>' and the final state 'w v' (%.17g).\n"
        "exit status: 0, 1 if the solver fails, 2 for a bad argument.",
        args, 2};
    cli_parse(&prog, argc, argv);
    paper_example ex = {43};
    dmi_solver *s = NULL;
    int rc = dmi_create(&s, 2, 1.0, N);
    if (rc == DMI_OK)
        rc = paper_setup(s, &ex);
    if (rc == DMI_OK)
        rc = paper_set_kernel_exp43(s);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    double t0 = cpu_now();
    if (rc == DMI_OK)
        rc = dmi_advance(s, steps);
    double secs = cpu_now() - t0;
    double u[2] = {0, 0};
    if (rc == DMI_OK)
        rc = dmi_get_state(s, u);
    if (rc != DMI_OK) {
        fprintf(stderr, "bench_binding: %s\n", s ? dmi_last_error(s) : dmi_strerror(rc));
        dmi_free(&s);
        return 1;
    }
    printf("ns_per_step %.6g\n%.17g %.17g\n", 1e9 * secs / (double)steps, u[0], u[1]);
    dmi_free(&s);
    return 0;
}
