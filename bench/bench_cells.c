/*
 * Benchmark of the cell rule's dmi_init and of the step (not a test), built
 * alike against two libdmi builds for an A/B comparison (docs/benchmarks.md):
 * Example 4.3's model (n = 2, tau = 1, friction, its history and forcing as
 * C callbacks) with its kernel cos 2 pi s + cos 10 pi s + cos 20 pi s
 *   init   as a callback under DMI_QUAD_CELL (tanh-sinh on every cell), N
 *          cells: dmi_init of an initialised solver (a restart), repeated;
 *   step   as three exponential terms (the default method: the recursion),
 *          and as a callback under DIRECT and under the default method (the
 *          FFT), N cells: dmi_advance of a run.
 * Each of `rounds` rounds times every case once; the fastest round counts
 * (CPU time of the process: the machine may be shared).  Uses the libdmi 1.3
 * API only, so that the same source builds against the release before.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "dmi.h"
#include "example43.h"
#include "layout.h"

enum { INIT_CELL, STEP_EXP, STEP_DIRECT, STEP_FFT, CASES };
static const char *const NAMES[CASES] = {"init, callback, cell rule", "step, exp (recursion)",
                                         "step, callback, DIRECT", "step, callback, default"};

static dmi_solver *make(size_t N, int c)
{
    dmi_solver *s = NULL;
    int rc = ex43_create(&s, N, c == STEP_EXP ? EX43_KERNEL_EXP : EX43_KERNEL_CALLBACK);
    if (rc == DMI_OK && c == INIT_CELL)
        rc = dmi_set_quadrature(s, DMI_QUAD_CELL);
    if (rc == DMI_OK && c == STEP_DIRECT)
        rc = dmi_set_convolution(s, DMI_CONV_DIRECT);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc != DMI_OK) {
        fprintf(stderr, "bench_cells: %s, N = %zu: %s\n", NAMES[c], N,
                s ? dmi_last_error(s) : dmi_strerror(rc));
        dmi_free(&s);
    }
    return s;
}

int main(int argc, char **argv)
{
    size_t rounds = 5, N = 1000, steps = 200000, reps = 20;
    const cli_arg args[] = {
        {"rounds", CLI_COUNT, &rounds, 1000, "rounds over every case; the fastest counts"},
        {"N", CLI_COUNT, &N, 1000000, "cells of the delay (h = 1 / N)"},
        {"steps", CLI_COUNT, &steps, 0, "steps of each timed run"},
        {"reps", CLI_COUNT, &reps, 0, "dmi_init calls timed per round"}};
    const cli_program prog = {
        "bench_cells",
        "Times dmi_init under the cell rule with a callback kernel, and dmi_advance with the\n"
        "kernel as exponential terms (recursion) and as a callback (DIRECT, default), on\n"
        "Example 4.3's model with N cells.",
        "stdout: one line per case: its name, N, and the best time (ms per dmi_init, ns per\n"
        "step), then the final state's w of each run (the same in both builds).\n"
        "exit status: 0, 1 if a call fails, 2 for a bad argument.",
        args, 4};
    cli_parse(&prog, argc, argv);
    fresh_allocator();
    double best[CASES], w[CASES];
    for (int c = 0; c < CASES; c++)
        best[c] = INFINITY, w[c] = NAN;
    for (size_t r = 0; r < rounds; r++)
        for (int c = 0; c < CASES; c++) {
            dmi_solver *s = make(N, c);
            if (!s)
                return 1;
            int rc = DMI_OK;
            const double t0 = cpu_now();
            if (c == INIT_CELL)
                for (size_t q = 0; q < reps && rc == DMI_OK; q++)
                    rc = dmi_init(s);
            else
                rc = dmi_advance(s, steps);
            const double t = cpu_now() - t0;
            double u[2] = {NAN, NAN};
            if (rc != DMI_OK || dmi_get_state(s, u) != DMI_OK) {
                fprintf(stderr, "bench_cells: %s: %s\n", NAMES[c], dmi_last_error(s));
                return 1;
            }
            best[c] = fmin(best[c], c == INIT_CELL ? t / (double)reps : t / (double)steps);
            w[c] = u[0];
            dmi_free(&s);
        }
    printf("Example 4.3 (n = 2), N = %zu, best of %zu rounds (CPU time)\n", N, rounds);
    for (int c = 0; c < CASES; c++)
        printf("%-28s %10.4f %s   w = %.17g\n", NAMES[c], c == INIT_CELL ? 1e3 * best[c] : 1e9 * best[c],
               c == INIT_CELL ? "ms/init" : "ns/step", w[c]);
    return 0;
}
