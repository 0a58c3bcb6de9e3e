/*
 * Benchmark of exponential-sum kernels (not a test): Example 4.3
 * (tau = 1, h = 1/N) with its kernel cos 2 pi s + cos 10 pi s + cos 20 pi s
 * given as three exponential terms (dmi_set_kernel_exp) under the default
 * method (AUTO, which takes the recursion), at N = 10^3, 10^4, 10^5, 10^6,
 * beside the same model without the delay term, the kernel as a callback
 * under the default method (the FFT) and under DIRECT.  The first two are
 * stepped in alternating chunks of CHUNK steps (which goes first alternates
 * too), so machine load hits them alike; each counts its fastest chunk (wall
 * time), and the ratio of the two is also given as the median, over all
 * pairs of neighbouring chunks, of the pair's ratio, which a drift of the
 * machine's speed during the run moves less; the FFT runs after
 * them (alternating with it, its megabytes of spectra evict their data) and
 * DIRECT last, with at most 10^9 / N steps, each its fastest repetition
 * (process CPU time).  All of it is repeated (reps times).  The trajectories
 * are written to memory touched before the clock starts (first touches are
 * page faults, a cost per step of the benchmark, not of the solver), and
 * with glibc the allocator's mmap threshold is fixed at its initial value,
 * so that every N allocates as a fresh process does.  Prints
 * ns per step and the ratios, and the largest deviation of the recursion's
 * states from the FFT's, relative to max |U|.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "layout.h"
#include "run.h"

#define CHUNK 10000

enum { REC, NODELAY, FFT, DIRECT, KINDS };

static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static int start(run *r, size_t N, int kind, size_t steps)
{
    r->ex.example = 43;
    r->secs = 0;
    r->w = malloc(2 * steps * sizeof *r->w);
    if (!r->w)
        return DMI_ENOMEM;
    memset(r->w, 0, 2 * steps * sizeof *r->w);
    int rc = dmi_create(&r->s, 2, 1.0, N);
    if (rc == DMI_OK)
        rc = paper_setup(r->s, &r->ex);
    if (rc == DMI_OK && kind == REC)
        rc = paper_set_kernel_exp43(r->s);
    if (rc == DMI_OK && kind == NODELAY)
        rc = dmi_set_kernel(r->s, NULL, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(r->s, kind == DIRECT ? DMI_CONV_DIRECT : DMI_CONV_AUTO);
    if (rc == DMI_OK)
        rc = dmi_init(r->s);
    return rc;
}

int main(int argc, char **argv)
{
    size_t steps = 300000, reps = 5;
    const cli_arg args[] = {{"steps", CLI_COUNT, &steps, 1e8,
                             "steps of each method at each N (DIRECT: at most 10^9 / N)"},
                            {"reps", CLI_COUNT, &reps, 100,
                             "repetitions; the fastest chunk or repetition counts"}};
    const cli_program prog = {
        "bench_exp",
        "Times Example 4.3 with its kernel as three exponential terms (default method: the\n"
        "recursion) at N = 1e3 .. 1e6, beside the model without the delay term, the kernel\n"
        "as a callback (default method: FFT) and DIRECT.",
        "stdout: a table of ns per step and ratios (a few seconds to a minute).\n"
        "exit status: 0, 1 if a solver fails, 2 for a bad argument.",
        args, 2};
    cli_parse(&prog, argc, argv);
    fresh_allocator(); /* every N allocates as a fresh process does */

    static const char *names[KINDS] = {"exp (rec)", "no delay", "callback (FFT)", "DIRECT"};
    printf("Example 4.3, tau = 1, h = 1/N, %zu steps per method (DIRECT: at most 1e9/N), "
           "%zu repetitions;\nrecursion and no delay: fastest chunk of %d steps (wall time), interleaved; "
           "FFT, DIRECT: fastest repetition (CPU time)\n", steps, reps, CHUNK);
    printf("%8s | %10s %10s %8s %8s | %14s %10s | %11s\n", "N", names[REC], names[NODELAY],
           "rec/nodel", "paired", names[FFT], names[DIRECT], "dev rec-FFT");
    const size_t Ns[4] = {1000, 10000, 100000, 1000000}, chunks = (steps + CHUNK - 1) / CHUNK;
    double rec[4], worst_over = 0, worst_paired = 0;
    double *pair = malloc(reps * chunks * sizeof *pair); /* each pair's ratio rec / no delay */
    if (!pair) {
        fprintf(stderr, "bench_exp: out of memory\n");
        return 1;
    }
    for (int k = 0; k < 4; k++) {
        const size_t N = Ns[k], dsteps = steps < 1000000000 / N ? steps : 1000000000 / N;
        double ns[KINDS] = {INFINITY, INFINITY, INFINITY, INFINITY}, dev = 0, big = 0;
        int rc = DMI_OK;
        size_t npair = 0;
        for (size_t rep = 0; rep < reps && rc == DMI_OK; rep++) {
            run r[KINDS] = {{0}};
            for (int i = 0; i < FFT + 1 && rc == DMI_OK; i++)
                rc = start(&r[i], N, i, steps);
            for (size_t p = 0; p < steps && rc == DMI_OK; p += CHUNK) {
                const size_t to = p + CHUNK < steps ? p + CHUNK : steps;
                for (int j = 0; j < NODELAY + 1 && rc == DMI_OK; j++) {
                    const int i = (int)((p / CHUNK + rep) % 2) ? NODELAY - j : j;
                    r[i].secs = 0;
                    rc = chunk(&r[i], p, to, now);
                    ns[i] = fmin(ns[i], 1e9 * r[i].secs / (double)(to - p));
                }
                if (rc == DMI_OK)
                    pair[npair++] = r[REC].secs / r[NODELAY].secs;
            }
            if (rc == DMI_OK)
                rc = chunk(&r[FFT], 0, steps, cpu_now);
            for (size_t q = 0; rc == DMI_OK && q < 2 * steps; q++) {
                dev = fmax(dev, fabs(r[REC].w[q] - r[FFT].w[q]));
                big = fmax(big, fabs(r[FFT].w[q]));
            }
            ns[FFT] = fmin(ns[FFT], 1e9 * r[FFT].secs / (double)steps);
            for (int i = 0; i < FFT + 1; i++)
                finish(&r[i]);
            if (rc == DMI_OK)
                rc = start(&r[DIRECT], N, DIRECT, dsteps);
            if (rc == DMI_OK)
                rc = chunk(&r[DIRECT], 0, dsteps, cpu_now);
            ns[DIRECT] = fmin(ns[DIRECT], 1e9 * r[DIRECT].secs / (double)dsteps);
            finish(&r[DIRECT]);
        }
        if (rc != DMI_OK) {
            fprintf(stderr, "bench_exp: N = %zu: %s\n", N, dmi_strerror(rc));
            free(pair);
            return 1;
        }
        qsort(pair, npair, sizeof *pair, by_value);
        const double paired = npair ? pair[npair / 2] : NAN;
        rec[k] = ns[REC];
        worst_over = fmax(worst_over, ns[REC] / ns[NODELAY]);
        worst_paired = fmax(worst_paired, paired);
        printf("%8zu | %10.1f %10.1f %8.2fx %7.2fx | %14.1f %10.1f | %11.2e\n", N, ns[REC],
               ns[NODELAY], ns[REC] / ns[NODELAY], paired, ns[FFT], ns[DIRECT], dev / big);
        fflush(stdout);
    }
    double lo = rec[0], hi = rec[0];
    for (int k = 1; k < 4; k++) {
        lo = fmin(lo, rec[k]);
        hi = fmax(hi, rec[k]);
    }
    printf("recursion: slowest / fastest N = %.2fx; at most %.2fx the model without delay "
           "(fastest chunks), %.2fx (median of paired chunks)\n", hi / lo, worst_over, worst_paired);
    free(pair);
    return 0;
}
