/*
 * Benchmark of the delay sum methods on the paper's Example 4.3 (not a test):
 * N = 1000 and 9991 to T = 30, N = 100000 to a shorter T, the default method
 * (DMI_CONV_AUTO) and DMI_CONV_DIRECT in one process.  The solvers are
 * stepped in alternating chunks of CHUNK steps so that a changing machine
 * load hits them alike; short runs are repeated and the fastest repetition
 * counts.  Prints ns per step, the speed-up, the heap memory each solver
 * holds after dmi_init (glibc's mallinfo2), the peak resident set and the
 * maximum relative deviation of the default method's states from DIRECT's.
 * A third solver steps the same model without the delay term, in the same
 * chunks: its cost is what every step pays besides the delay sum (the
 * forcing's cos 8t, the callbacks, the checks, the history), so DIRECT's
 * time over it is the largest speed-up any method of the delay sum can
 * give ("ceiling").
 * Usage: bench_conv [T for N = 100000, default 3]; bench_conv --help
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "cli.h"
#include "run.h"

/* Steps per chunk.  A chunk must be long against the refill of the caches
 * after the other solvers' chunks, which is a cost of the alternation, not
 * of a method: with chunks of 2000 steps the default method measured about
 * 20 % slower at N = 100000 than alone (its largest block, 2048 steps, then
 * starts cold in almost every chunk), with 30000 steps as fast as alone. */
#define CHUNK 30000

/* Heap bytes in use, in MiB (glibc; 0 elsewhere). */
static double heap_mib(void)
{
#ifdef __GLIBC__
    struct mallinfo2 mi = mallinfo2();
    return (double)(mi.uordblks + mi.hblkhd) / 1048576.0;
#else
    return 0;
#endif
}

/* Makes the solver; mem = the heap its creation and dmi_init took. */
static int start(run *r, size_t N, int method, size_t steps, int delay)
{
    r->ex.example = 43;
    r->secs = 0;
    r->w = malloc(2 * steps * sizeof *r->w);
    if (!r->w)
        return DMI_ENOMEM;
    double before = heap_mib();
    int rc = dmi_create(&r->s, 2, 1.0, N);
    if (rc == DMI_OK)
        rc = paper_setup(r->s, &r->ex);
    if (rc == DMI_OK && !delay)
        rc = dmi_set_kernel(r->s, NULL, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(r->s, method);
    if (rc == DMI_OK)
        rc = dmi_init(r->s);
    r->mem = heap_mib() - before;
    return rc;
}

int main(int argc, char **argv)
{
    double Tlong = 3.0;
    const cli_arg args[] = {{"T", CLI_TIME, &Tlong, 100,
                             "end time of the run at N = 100000, at least 1e-5 for one step"}};
    const cli_program prog = {
        "bench_conv",
        "Benchmark (not a test) of the delay sum on the paper's Example 4.3, tau = 1, h = 1/N:\n"
        "DMI_CONV_DIRECT against the default method (AUTO) and a run without the delay term,\n"
        "N = 1000 and 9991 to T = 30, N = 100000 to T.  Takes about a minute with no arguments.",
        "stdout: one table row per N: ns per step of DIRECT, of the default method and of the\n"
        "  run without delay, the speed-up, the ceiling (DIRECT over no delay), the heap each\n"
        "  solver holds (MiB), the maximal relative deviation of the default method from\n"
        "  DIRECT; then the growth of the cost per step and the peak resident set.\n"
        "exit status: 0, 1 if a solver fails, 2 for a bad argument.",
        args, 1};
    cli_parse(&prog, argc, argv);
    if (llround(Tlong * 100000.0) < 1)
        cli_reject(&prog, "T", argv[1], "gives no step at N = 100000 (T >= 1e-5 needed)");
    const size_t Ns[3] = {1000, 9991, 100000};
    const double Ts[3] = {30.0, 30.0, Tlong};
    double fast[3] = {0};
    printf("Example 4.3, tau = 1, h = 1/N; DIRECT vs the default method (AUTO)\n");
    printf("%7s %5s %8s | %10s %10s %8s | %9s %8s | %9s %9s | %9s\n", "N", "T", "steps", "DIRECT",
           "default", "speed-up", "no delay", "ceiling", "heap DIR", "heap def", "max dev");
    printf("%7s %5s %8s | %10s %10s %8s | %9s %8s | %9s %9s | %9s\n", "", "", "", "ns/step",
           "ns/step", "", "ns/step", "", "MiB", "MiB", "rel.");
    for (int k = 0; k < 3; k++) {
        const size_t N = Ns[k], steps = (size_t)llround(Ts[k] * (double)N);
        const size_t reps = steps < 300000 ? 300000 / steps : 1;
        double nd = INFINITY, na = INFINITY, nb = INFINITY;
        run d = {0}, a = {0}, b = {0};
        int rc = DMI_OK;
        for (size_t r = 0; r < reps && rc == DMI_OK; r++) {
            finish(&d); /* (nothing to free in the first repetition) */
            finish(&a);
            finish(&b);
            rc = start(&d, N, DMI_CONV_DIRECT, steps, 1);
            if (rc == DMI_OK)
                rc = start(&a, N, DMI_CONV_AUTO, steps, 1);
            if (rc == DMI_OK)
                rc = start(&b, N, DMI_CONV_AUTO, steps, 0);
            for (size_t p = 0; p < steps && rc == DMI_OK; p += CHUNK) {
                size_t to = p + CHUNK < steps ? p + CHUNK : steps;
                rc = chunk(&d, p, to, now);
                if (rc == DMI_OK)
                    rc = chunk(&a, p, to, now);
                if (rc == DMI_OK)
                    rc = chunk(&b, p, to, now);
            }
            nd = fmin(nd, 1e9 * d.secs / (double)steps);
            na = fmin(na, 1e9 * a.secs / (double)steps);
            nb = fmin(nb, 1e9 * b.secs / (double)steps);
        }
        if (rc != DMI_OK) {
            fprintf(stderr, "bench_conv: N = %zu, T = %g: %s\n", N, Ts[k], dmi_strerror(rc));
            return 1;
        }
        double dev = 0, big = 0;
        for (size_t i = 0; i < 2 * steps; i++) {
            dev = fmax(dev, fabs(d.w[i] - a.w[i]));
            big = fmax(big, fabs(d.w[i]));
        }
        fast[k] = na;
        printf("%7zu %5g %8zu | %10.1f %10.1f %7.1fx | %9.1f %7.1fx | %9.2f %9.2f | %9.2e\n", N,
               Ts[k], steps, nd, na, nd / na, nb, nd / nb, d.mem, a.mem, dev / big);
        fflush(stdout);
        finish(&d);
        finish(&a);
        finish(&b);
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("default method: cost per step grows %.2fx from N = 1000 to N = 100000\n",
           fast[2] / fast[0]);
    printf("peak resident set of the process: %.1f MiB\n", (double)ru.ru_maxrss / 1024.0);
    return 0;
}
