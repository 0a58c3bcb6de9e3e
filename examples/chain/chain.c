/*
 * A two-mass chain with dry friction and a viscoelastic (Prony-series) memory, n = 4.
 *
 * Mass m1 hangs on a spring k1 to the wall and on a spring k2 to mass m2; both slide with dry
 * friction (forces mu1, mu2); m1 is driven by F cos(omega t) and held by a viscoelastic support
 * whose force is a Prony series of three Maxwell branches acting on the past displacement,
 * sum_k g_k int_0^tau exp(-s / theta_k) x1(t - s) ds (m2 feels the same branches at half
 * strength).  With u = (x1, x2, v1, v2):
 *
 *     u' + A(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0,
 *     A(u) = (0, 0, mu1/m1 sigma(v1), mu2/m2 sigma(v2))          (dmi_set_friction)
 *     f(t, u) = (-v1, -v2, ((k1 + k2) x1 - k2 x2 - F cos(omega t)) / m1, k2 (x2 - x1) / m2)
 *     H(s) = sum_k exp(-s / theta_k) C_k,  C_k(2, 0) = g_k / m1,  C_k(3, 1) = g_k / (2 m2)
 *                                                                 (dmi_set_kernel_exp)
 * At rest before t = 0 with x1 = 0.5 (dmi_set_history).  Prints CSV t,x1,x2,v1,v2 to stdout.
 * Build it against the installed library with this folder's CMakeLists.txt (find_package(dmi)).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <dmi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { BRANCHES = 3 };
static const double M1 = 1.0, M2 = 0.5, K1 = 4.0, K2 = 2.0, MU1 = 1.2, MU2 = 0.5;
static const double F = 1.5, OMEGA = 1.7, TAU = 5.0;
static const double G[BRANCHES] = {3.0, 1.0, 0.5}, THETA[BRANCHES] = {0.05, 0.5, 2.0};

static int rhs(double t, const double *u, double *out, void *user)
{
    (void)user;
    out[0] = -u[2];
    out[1] = -u[3];
    out[2] = ((K1 + K2) * u[0] - K2 * u[1] - F * cos(OMEGA * t)) / M1;
    out[3] = K2 * (u[1] - u[0]) / M2;
    return 0;
}

static int history(double t, double *out, void *user)   /* z(t) on [-tau, 0]: at rest, x1 = 0.5 */
{
    (void)t;
    (void)user;
    out[0] = 0.5;
    return 0;
}

static int parse(const char *text, double *x)
{
    char *end;
    *x = strtod(text, &end);
    return end != text && *end == '\0' && *x > 0 && *x < 1e9;
}

int main(int argc, char **argv)
{
    double args[3] = {1000, 20, 50};   /* N (steps per tau), T, stride */
    if (argc > 1 && (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h"))) {
        printf("usage: chain [--help] [N [T [stride]]]\n"
               "  N       steps per tau (tau = %g), h = tau / N (default 1000)\n"
               "  T       end time (default 20)\n"
               "  stride  print every stride-th step (default 50)\n"
               "stdout: CSV t,x1,x2,v1,v2\nexit status: 0, 1 on a library error, 2 on a bad argument\n", TAU);
        return 0;
    }
    for (int i = 1; i < argc; i++)
        if (i > 3 || !parse(argv[i], &args[i - 1])) {
            fprintf(stderr, "chain: bad argument '%s' (--help)\n", argv[i]);
            return 2;
        }
    size_t N = (size_t)args[0], stride = (size_t)args[2];

    /* H(s) = sum_k exp(a_k s) C_k with a_k = -1/theta_k, b_k = 0 (no oscillation) */
    double a[BRANCHES], b[BRANCHES] = {0}, C[BRANCHES * 16] = {0};
    for (int k = 0; k < BRANCHES; k++) {
        a[k] = -1.0 / THETA[k];
        C[k * 16 + 2 * 4 + 0] = G[k] / M1;          /* row v1, column x1 */
        C[k * 16 + 3 * 4 + 1] = G[k] / (2.0 * M2);  /* row v2, column x2 */
    }
    const double alpha[4] = {0.0, 0.0, MU1 / M1, MU2 / M2};

    dmi_solver *s = NULL;
    int rc = dmi_create(&s, 4, TAU, N);
    if (rc != DMI_OK) {
        fprintf(stderr, "chain: %s\n", dmi_strerror(rc));
        return 1;
    }
    if ((rc = dmi_set_rhs(s, rhs, NULL)) == DMI_OK && (rc = dmi_set_friction(s, alpha)) == DMI_OK &&
        (rc = dmi_set_kernel_exp(s, BRANCHES, a, b, C, NULL)) == DMI_OK &&
        (rc = dmi_set_history(s, history, NULL)) == DMI_OK && (rc = dmi_init(s)) == DMI_OK) {
        size_t steps = (size_t)(args[1] / dmi_get_h(s) + 0.5);
        double u[4];
        printf("t,x1,x2,v1,v2\n");
        for (size_t p = 0; rc == DMI_OK; p += stride) {
            dmi_get_state(s, u);
            printf("%.17g,%.17g,%.17g,%.17g,%.17g\n", dmi_time(s), u[0], u[1], u[2], u[3]);
            if (p + stride > steps)
                break;
            rc = dmi_advance(s, stride);
        }
    }
    if (rc != DMI_OK)
        fprintf(stderr, "chain: %s\n", dmi_last_error(s));
    dmi_free(&s);
    return rc == DMI_OK ? 0 : 1;
}
