/*
 * The friction oscillator (4.1) with a viscoelastic memory: the kernel is a
 * Prony series (generalised Maxwell model), one decaying exponential per
 * Maxwell branch,
 *
 *     w'' + b w + int_0^tau H(s) w(t - s) ds + alpha sigma(w') + g(t) ∋ 0,
 *     H(s) = sum_k g_k exp(-s / theta_k),
 *
 * with b = alpha = 1 and g(t) = 1.3 cos 8t of Example 4.3, at rest on
 * [-tau, 0] (a standard linear solid is the series with one branch).  The
 * branches (g_k, theta_k) = (2, 0.02), (1, 0.2), (0.5, 2) relax within
 * tau = 10 (exp(-5) of the slowest is left out).  The kernel is given as
 * exponential terms (dmi_set_kernel_exp: the default method is then the O(1)
 * recursion) and, for comparison, as a callback (the default method is then
 * the FFT); both runs are timed (CPU time) and compared.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "cli.h"
#include "paper.h"

enum { BRANCHES = 3 };
static const double G[BRANCHES] = {2.0, 1.0, 0.5}, THETA[BRANCHES] = {0.02, 0.2, 2.0};
static const double TAU = 10.0;

static int prony_kernel(double s, double *out, void *user)
{
    (void)user;
    for (int k = 0; k < BRANCHES; k++)
        out[2] += G[k] * exp(-s / THETA[k]); /* entry (1, 0): acts on w */
    return 0;
}

/* Runs to step count steps; u gets (w, v) of every step; *secs the CPU time. */
static int run(size_t N, size_t steps, int as_exp, double *u, double *secs)
{
    paper_example ex = {43}; /* the oscillator, b = alpha = 1, g(t) = 1.3 cos 8t, z = 0 */
    double a[BRANCHES], b[BRANCHES] = {0}, C[BRANCHES * 4] = {0};
    for (int k = 0; k < BRANCHES; k++) {
        a[k] = -1.0 / THETA[k];
        C[4 * k + 2] = G[k];
    }
    dmi_solver *s = NULL;
    int rc = dmi_create(&s, 2, TAU, N);
    if (rc == DMI_OK)
        rc = paper_setup(s, &ex);
    if (rc == DMI_OK)
        rc = as_exp ? dmi_set_kernel_exp(s, BRANCHES, a, b, C, NULL)
                    : dmi_set_kernel(s, prony_kernel, NULL);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    clock_t t0 = clock();
    for (size_t p = 0; p < steps && rc == DMI_OK; p++) {
        rc = dmi_step(s);
        dmi_get_state(s, u + 2 * p);
    }
    *secs = (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (rc != DMI_OK)
        fprintf(stderr, "prony: %s\n", s ? dmi_last_error(s) : dmi_strerror(rc));
    dmi_free(&s);
    return rc;
}

int main(int argc, char **argv)
{
    size_t N = 100000;
    double T = 20;
    const cli_arg args[] = {{"N", CLI_COUNT, &N, 1e7, "steps per delay: h = tau / N, tau = 10"},
                            {"T", CLI_TIME, &T, 1e4, "end time (the model's time unit)"}};
    const cli_program prog = {
        "prony",
        "Runs the friction oscillator with a Prony-series (viscoelastic) memory kernel,\n"
        "given as exponential terms (the recursion) and as a callback (the FFT).",
        "stdout: w(T), v(T), the share of sticking steps, the CPU time per step of both\n"
        "runs and their largest deviation.\n"
        "exit status: 0, 1 if a run fails, 2 for a bad argument.",
        args, 2};
    cli_parse(&prog, argc, argv);
    const size_t steps = (size_t)llround(T * (double)N / TAU);
    if (steps == 0)
        cli_reject(&prog, "T", argv[2], "gives no step (T >= tau / (2 N) needed)");
    double *ue = malloc(2 * steps * sizeof *ue), *uf = malloc(2 * steps * sizeof *uf);
    double se = 0, sf = 0;
    if (!ue || !uf) {
        fprintf(stderr, "prony: out of memory for %zu steps\n", steps);
        return 1;
    }
    if (run(N, steps, 1, ue, &se) != DMI_OK || run(N, steps, 0, uf, &sf) != DMI_OK)
        return 1;
    double dev = 0, big = 0;
    size_t sticking = 0;
    for (size_t q = 0; q < 2 * steps; q++) {
        dev = fmax(dev, fabs(ue[q] - uf[q]));
        big = fmax(big, fabs(uf[q]));
    }
    for (size_t p = 0; p < steps; p++)
        sticking += ue[2 * p + 1] == 0.0;
    printf("Prony-series memory, %d branches, tau = %g, N = %zu (h = %g), T = %g: %zu steps\n",
           BRANCHES, TAU, N, TAU / (double)N, T, steps);
    printf("w(T) = %.12f, v(T) = %.12f, sticking in %.1f %% of the steps\n", ue[2 * steps - 2],
           ue[2 * steps - 1], 100.0 * (double)sticking / (double)steps);
    printf("kernel as exponential terms (recursion): %8.1f ns per step\n",
           1e9 * se / (double)steps);
    printf("kernel as a callback (FFT):              %8.1f ns per step (%.1fx)\n",
           1e9 * sf / (double)steps, sf / se);
    printf("largest deviation of the two runs: %.2e of max |U|\n", dev / big);
    free(ue);
    free(uf);
    return 0;
}
