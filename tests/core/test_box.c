/*
 * The box operator A = normal cone of K = prod [lo_i, hi_i] (dmi_set_box) on
 * an n = 3 system with a full 3x3 kernel: every U^p lies in K, the
 * scheme is of order one (Proposition 3.11), and libdmi agrees with a plain
 * computation of (3.12)-(3.13) written here.
 *
 *   f(t, u) = B u + g(t), g(t) = (-1.5 cos 3t, 2 sin 2t, 0.2 + 2 cos 2t),
 *   H_ij(s) = (1 + i + 2j)/4 cos((1 + i + j) s) + 0.3 (i - j) s,
 *   z(t) = (0.2 cos t, 0.1 sin 3t, 0.3 + 0.1 t) (in K),  tau = 1, T = 4,
 *   K = [-0.4, 0.5] x ]-inf, 0.3] x [-0.2, +inf[.
 *
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core_test.h"

enum { n = 3 };
static const double T_END = 4;
static const double LO[n] = {-0.4, -INFINITY, -0.2};
static const double HI[n] = {0.5, 0.3, INFINITY};
static const double B[n][n] = {{0.5, -1.0, 0.2}, {1.0, 0.3, -0.4}, {-0.2, 0.6, 0.1}};

static int box_rhs(double t, const double *u, double *out, void *user)
{
    (void)user;
    const double g[n] = {-1.5 * cos(3 * t), 2 * sin(2 * t), 0.2 + 2 * cos(2 * t)};
    for (int i = 0; i < n; i++)
        out[i] = B[i][0] * u[0] + B[i][1] * u[1] + B[i][2] * u[2] + g[i];
    return 0;
}

static int box_kernel(double s, double *out, void *user)
{
    (void)user;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            out[i * n + j] = (1 + i + 2 * j) / 4.0 * cos((1 + i + j) * s) + 0.3 * (i - j) * s;
    return 0;
}

static int box_history(double t, double *out, void *user)
{
    (void)user;
    out[0] = 0.2 * cos(t);
    out[1] = 0.1 * sin(3 * t);
    out[2] = 0.3 + 0.1 * t;
    return 0;
}

static size_t steps_for(size_t N)
{
    return (size_t)llround(T_END * (double)N);
}

/* libdmi with h = 1/N: U^p, p = 0..M, into traj[(M + 1) n]. */
static int dmi_box(size_t N, double *traj)
{
    dmi_solver *s = NULL;
    int rc = dmi_create(&s, n, 1.0, N);
    if (rc == DMI_OK)
        rc = dmi_set_rhs(s, box_rhs, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_kernel(s, box_kernel, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_history(s, box_history, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_box(s, LO, HI);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    for (size_t p = 0; rc == DMI_OK && p <= steps_for(N); p++) {
        if (p > 0)
            rc = dmi_step(s);
        if (rc == DMI_OK)
            rc = dmi_get_state(s, traj + p * n);
    }
    dmi_free(&s);
    return rc;
}

/* The scheme written out with plain arrays: u[(N + p) n + i] = U_i^p. */
static int plain_box(size_t N, double *traj)
{
    const size_t M = steps_for(N);
    const double h = 1.0 / (double)N;
    double *u = malloc((N + M + 1) * n * sizeof *u), *Hs = malloc(N * n * n * sizeof *Hs);
    if (!u || !Hs) {
        free(u);
        free(Hs);
        return -1;
    }
    for (size_t k = 0; k <= N; k++)
        box_history(-(double)k * h, u + (N - k) * n, NULL);
    for (size_t l = 0; l < N; l++)
        box_kernel((double)l * h, Hs + l * n * n, NULL);
    for (size_t p = 0; p < M; p++) {
        const double *U = u + (N + p) * n;
        double f[n], W[n] = {0, 0, 0};
        box_rhs((double)p * h, U, f, NULL);
        for (size_t l = 0; l < N; l++)
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++)
                    W[i] += Hs[l * n * n + i * n + j] * u[(N + p - l) * n + j];
        for (int i = 0; i < n; i++) {
            W[i] *= h;
            double x = U[i] - h * f[i] - h * W[i];
            u[(N + p + 1) * n + i] = fmin(fmax(x, LO[i]), HI[i]);
        }
    }
    for (size_t k = 0; k < (M + 1) * n; k++)
        traj[k] = u[N * n + k];
    free(u);
    free(Hs);
    return 0;
}

/* Counts of U^p on each bound; 0 if some U^p is outside K. */
static int in_box(const double *traj, size_t M, size_t at_lo[n], size_t at_hi[n])
{
    int inside = 1;
    for (int i = 0; i < n; i++)
        at_lo[i] = at_hi[i] = 0;
    for (size_t p = 0; p <= M; p++)
        for (int i = 0; i < n; i++) {
            double x = traj[p * n + i];
            inside &= x >= LO[i] && x <= HI[i];
            at_lo[i] += x == LO[i];
            at_hi[i] += x == HI[i];
        }
    return inside;
}

static double *run(size_t N)
{
    double *traj = malloc((steps_for(N) + 1) * n * sizeof *traj);
    if (traj && dmi_box(N, traj) != DMI_OK) {
        free(traj);
        traj = NULL;
    }
    return traj;
}

/* max over t_p = p / N, i of |U_i(t_p) - fine U_i(t_p)|, fine with h = 1/(r N). */
static double error_against(const double *traj, size_t N, const double *fine, size_t r)
{
    double e = 0;
    for (size_t p = 0; p <= steps_for(N); p++)
        for (int i = 0; i < n; i++)
            e = fmax(e, fabs(traj[p * n + i] - fine[p * r * n + i]));
    return e;
}

static void test_first_order_in_box(void)
{
    const size_t N0 = 40, R = 64;
    double *fine = run(R * N0);
    CU_ASSERT_PTR_NOT_NULL_FATAL(fine);
    size_t at_lo[n], at_hi[n];
    CU_ASSERT(in_box(fine, steps_for(R * N0), at_lo, at_hi));
    /* the constraints are active: each finite bound is reached, none always */
    for (int i = 0; i < n; i++) {
        printf("\n  h = 1/%zu: component %d at its lower bound %zu times, at its upper bound %zu "
               "times",
               R * N0, i, at_lo[i], at_hi[i]);
        if (isfinite(LO[i]))
            CU_ASSERT(at_lo[i] > 0 && at_lo[i] < steps_for(R * N0) / 2);
        if (isfinite(HI[i]))
            CU_ASSERT(at_hi[i] > 0 && at_hi[i] < steps_for(R * N0) / 2);
    }
    double err[3];
    for (int k = 0; k < 3; k++) {
        size_t N = N0 << k;
        double *traj = run(N);
        CU_ASSERT_PTR_NOT_NULL_FATAL(traj);
        CU_ASSERT(in_box(traj, steps_for(N), at_lo, at_hi));
        err[k] = error_against(traj, N, fine, R >> k);
        printf("\n  h = 1/%zu: max error against h = 1/%zu: %.4e", N, R * N0, err[k]);
        free(traj);
    }
    for (int k = 0; k < 2; k++) {
        double order = log2(err[k] / err[k + 1]);
        printf("\n  observed order between h = 1/%zu and 1/%zu: %.4f", N0 << k, N0 << (k + 1),
               order);
        CU_ASSERT(order >= 0.8 && order <= 1.2);
    }
    printf("\n");
    free(fine);
}

static void test_against_plain(void)
{
    const size_t N = 20, M = steps_for(N);
    double *a = run(N), *b = malloc((M + 1) * n * sizeof *b);
    if (!a || !b || plain_box(N, b) != 0) {
        free(a);
        free(b);
        CU_FAIL_FATAL("run failed");
    }
    double d = 0, scale = 0;
    for (size_t k = 0; k < (M + 1) * n; k++) {
        d = fmax(d, fabs(a[k] - b[k]));
        scale = fmax(scale, fabs(b[k]));
    }
    size_t at_lo[n], at_hi[n];
    CU_ASSERT(in_box(b, M, at_lo, at_hi));
    printf("\n  h = 1/%zu: max |libdmi - plain| = %.3e (max |U| = %.3f)\n", N, d, scale);
    CU_ASSERT(d <= 1e-12);
    CU_ASSERT(scale > 0.1);
    free(a);
    free(b);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"box, n = 3, full kernel: U^p in K, first order (Proposition 3.11)",
         test_first_order_in_box},
        {"box, n = 3, full kernel: libdmi = plain computation at h = 1/20", test_against_plain},
        {NULL, NULL}};
    return core_main(argc, argv, "core: box operator", tests);
}
