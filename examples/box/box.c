/*
 * A state kept in a box: the normal cone of K = [-1, 1] x [-1, 1] x [0, +inf), n = 3.
 *
 *     u' + N_K(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0,     u = z on [-tau, 0],
 *     f(t, u) = M u - g(t),   M = [[0.1, -2, 0], [2, 0.1, 0], [0, 0, 0.5]],
 *     g(t) = (1.5 cos t, 0, 0.8 sin 3t),   H(s) = 0.7 exp(-2 s) I,   tau = 2,   z = (0.5, 0, 0.2).
 *
 * f rotates u and pushes it outwards in the (u1, u2) plane; the normal cone N_K (dmi_set_box: the
 * resolvent is the projection onto K) holds u in K, so u slides along the faces of the box.  The
 * kernel is given as a callback (dmi_set_kernel).  Prints CSV t,u1,u2,u3 to stdout.
 * Build it against the installed library with this folder's CMakeLists.txt (find_package(dmi)).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <dmi.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const double TAU = 2.0;

static int rhs(double t, const double *u, double *out, void *user)
{
    (void)user;
    out[0] = 0.1 * u[0] - 2.0 * u[1] - 1.5 * cos(t);
    out[1] = 2.0 * u[0] + 0.1 * u[1];
    out[2] = 0.5 * u[2] - 0.8 * sin(3.0 * t);
    return 0;
}

static int kernel(double s, double *out, void *user)   /* H(s) = 0.7 exp(-2 s) I, row-major 3 x 3 */
{
    (void)user;
    out[0] = out[4] = out[8] = 0.7 * exp(-2.0 * s);
    return 0;
}

static int history(double t, double *out, void *user)
{
    (void)t;
    (void)user;
    out[0] = 0.5;
    out[2] = 0.2;
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
        printf("usage: box [--help] [N [T [stride]]]\n"
               "  N       steps per tau (tau = %g), h = tau / N (default 1000)\n"
               "  T       end time (default 20)\n"
               "  stride  print every stride-th step (default 50)\n"
               "stdout: CSV t,u1,u2,u3\nexit status: 0, 1 on a library error, 2 on a bad argument\n", TAU);
        return 0;
    }
    for (int i = 1; i < argc; i++)
        if (i > 3 || !parse(argv[i], &args[i - 1])) {
            fprintf(stderr, "box: bad argument '%s' (--help)\n", argv[i]);
            return 2;
        }
    size_t N = (size_t)args[0], stride = (size_t)args[2];
    const double lo[3] = {-1.0, -1.0, 0.0}, hi[3] = {1.0, 1.0, INFINITY};

    dmi_solver *s = NULL;
    int rc = dmi_create(&s, 3, TAU, N);
    if (rc != DMI_OK) {
        fprintf(stderr, "box: %s\n", dmi_strerror(rc));
        return 1;
    }
    if ((rc = dmi_set_rhs(s, rhs, NULL)) == DMI_OK && (rc = dmi_set_box(s, lo, hi)) == DMI_OK &&
        (rc = dmi_set_kernel(s, kernel, NULL)) == DMI_OK &&
        (rc = dmi_set_history(s, history, NULL)) == DMI_OK && (rc = dmi_init(s)) == DMI_OK) {
        size_t steps = (size_t)(args[1] / dmi_get_h(s) + 0.5);
        double u[3];
        printf("t,u1,u2,u3\n");
        for (size_t p = 0; rc == DMI_OK; p += stride) {
            dmi_get_state(s, u);
            printf("%.17g,%.17g,%.17g,%.17g\n", dmi_time(s), u[0], u[1], u[2]);
            if (p + stride > steps)
                break;
            rc = dmi_advance(s, stride);
        }
    }
    if (rc != DMI_OK)
        fprintf(stderr, "box: %s\n", dmi_last_error(s));
    dmi_free(&s);
    return rc == DMI_OK ? 0 : 1;
}
