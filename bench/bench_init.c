/*
 * Benchmark of dmi_init and dmi_set_window against N (not a test): Example
 * 4.3's model (n = 2, tau = 1, h = 1/N, friction, its history and forcing
 * as C callbacks) with its kernel cos 2 pi s + cos 10 pi s + cos 20 pi s
 * given as three exponential terms under the default method (the O(1)
 * recursion), and beside it the same exponential kernel under DIRECT, the
 * kernel as a callback (the default method: the FFT with libdmi's GSL, the
 * direct sum without) and no kernel, at N = 10^3, 10^4, 10^5, 10^6.  Each
 * round times, for every N and kernel, dmi_init of an initialised solver
 * (a restart, as dmi.analysis does at every map build) and dmi_set_window
 * with a window of that solver's size, each repeated so that a case takes
 * about 0.05 s; the fastest round counts.  CPU time of the process (the
 * machine may be shared), with glibc's mmap threshold fixed (layout.h), so
 * that every large array is mapped afresh as in a new process.  Prints ns
 * per N for each.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "dmi.h"
#include "example43.h"
#include "layout.h"

enum { EXP, EXP_DIRECT, CALLBACK, NONE, KINDS };
static const char *const NAMES[KINDS] = {"exp (recursion)", "exp, DIRECT", "callback (default)",
                                         "no kernel"};

static dmi_solver *make(size_t N, int kind)
{
    dmi_solver *s = NULL;
    int rc = ex43_create(&s, N, kind == EXP || kind == EXP_DIRECT ? EX43_KERNEL_EXP
                                : kind == CALLBACK                 ? EX43_KERNEL_CALLBACK
                                                                   : EX43_KERNEL_NONE);
    if (rc == DMI_OK && kind == EXP_DIRECT)
        rc = dmi_set_convolution(s, DMI_CONV_DIRECT);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc != DMI_OK)
        dmi_free(&s);
    return s;
}

int main(int argc, char **argv)
{
    size_t rounds = 3;
    const cli_arg args[] = {
        {"rounds", CLI_COUNT, &rounds, 100, "rounds over every N and kernel; the fastest counts"}};
    const cli_program prog = {
        "bench_init",
        "Times dmi_init (a restart) and dmi_set_window against N = 1e3 .. 1e6 with Example\n"
        "4.3's kernel as exponential terms (recursion, and DIRECT), as a callback, and none.",
        "stdout: a table of ns per N of dmi_init and dmi_set_window for every N and kernel.\n"
        "exit status: 0, 1 if a call fails, 2 for a bad argument.",
        args, 1};
    cli_parse(&prog, argc, argv);
    fresh_allocator(); /* every large array mapped afresh, as in a new process */
    enum { NN = 4 };
    const size_t Ns[NN] = {1000, 10000, 100000, 1000000};
    double init_best[NN][KINDS], window_best[NN][KINDS];
    for (int i = 0; i < NN; i++)
        for (int k = 0; k < KINDS; k++)
            init_best[i][k] = window_best[i][k] = INFINITY;
    for (size_t r = 0; r < rounds; r++)
        for (int i = 0; i < NN; i++)
            for (int k = 0; k < KINDS; k++) {
                const size_t N = Ns[i];
                dmi_solver *s = make(N, k);
                double *U = s ? malloc(2 * (N + 1) * sizeof *U) : NULL;
                if (!U || dmi_get_window(s, U) != DMI_OK) {
                    fprintf(stderr, "bench_init: N = %zu, %s: %s\n", N, NAMES[k],
                            s ? dmi_last_error(s) : "out of memory");
                    return 1;
                }
                const size_t reps = N >= 100000 ? 3 : 30000000 / (N * 10);
                int rc = DMI_OK;
                double t0 = cpu_now();
                for (size_t q = 0; q < reps && rc == DMI_OK; q++)
                    rc = dmi_init(s);
                const double t_init = (cpu_now() - t0) / (double)reps;
                t0 = cpu_now();
                for (size_t q = 0; q < reps && rc == DMI_OK; q++)
                    rc = dmi_set_window(s, U);
                const double t_window = (cpu_now() - t0) / (double)reps;
                if (rc != DMI_OK) {
                    fprintf(stderr, "bench_init: N = %zu, %s: %s\n", N, NAMES[k],
                            dmi_last_error(s));
                    return 1;
                }
                init_best[i][k] = fmin(init_best[i][k], t_init);
                window_best[i][k] = fmin(window_best[i][k], t_window);
                free(U);
                dmi_free(&s);
            }
    printf("dmi_init (a restart) and dmi_set_window, ns per N; Example 4.3 (n = 2), best of %zu "
           "rounds (CPU time)\n", rounds);
    printf("%-20s %8s %10s %12s\n", "kernel", "N", "init/N", "set_window/N");
    for (int k = 0; k < KINDS; k++)
        for (int i = 0; i < NN; i++)
            printf("%-20s %8zu %10.1f %12.1f\n", NAMES[k], Ns[i],
                   1e9 * init_best[i][k] / (double)Ns[i], 1e9 * window_best[i][k] / (double)Ns[i]);
    return 0;
}
