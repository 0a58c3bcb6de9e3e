/*
 * A program using libdmi as an outside user does: built from an installed
 * prefix only (tests/abi/install_consumer.sh).  Checks the version and one
 * scheme with the delay term against the recurrence (3.12)-(3.13) written
 * out here: n = 1, A = 0, f = 0, H(s) = c, z = 1 on [-tau, 0], so
 *     U^{p+1} = U^p - h * h c sum_{l=0}^{N-1} U^{p-l}.
 * Prints "ok" and exits 0 on success.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <dmi.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

enum { N = 8, STEPS = 40 };

static int kernel(double s, double *out, void *user)
{
    (void)s;
    out[0] = *(const double *)user;
    return 0;
}

static int history(double t, double *out, void *user)
{
    (void)t;
    (void)user;
    out[0] = 1.0;
    return 0;
}

static int fail(const char *what)
{
    fprintf(stderr, "consumer: %s\n", what);
    return 1;
}

int main(void)
{
    char expected[32];
    snprintf(expected, sizeof expected, "%d.%d.%d", DMI_VERSION_MAJOR, DMI_VERSION_MINOR,
             DMI_VERSION_PATCH);
    if (strcmp(dmi_version(), expected) != 0)
        return fail("dmi_version() differs from the header's version");

    dmi_solver *s = NULL;
    if (dmi_create(&s, 1, 1.0, 0) != DMI_EINVAL || s != NULL)
        return fail("dmi_create accepted N = 0");

    const double c = 3.0, tau = 1.0, h = tau / N;
    if (dmi_create(&s, 1, tau, N) != DMI_OK || dmi_set_kernel(s, kernel, (void *)&c) != DMI_OK ||
        dmi_set_history(s, history, NULL) != DMI_OK || dmi_init(s) != DMI_OK ||
        dmi_advance(s, STEPS) != DMI_OK)
        return fail(dmi_last_error(s));

    double U[N + STEPS + 1]; /* U[k] = U^{k - N} */
    for (int k = 0; k <= N; k++)
        U[k] = 1.0;
    for (int p = 0; p < STEPS; p++) {
        double sum = 0;
        for (int l = 0; l < N; l++)
            sum += U[N + p - l];
        U[N + p + 1] = U[N + p] - h * (h * c * sum);
    }
    double u;
    if (dmi_get_state(s, &u) != DMI_OK)
        return fail(dmi_last_error(s));
    dmi_free(&s);
    if (!(fabs(u - U[N + STEPS]) <= 1e-13 * fabs(U[N + STEPS])) || U[N + STEPS] == 1.0) {
        fprintf(stderr, "consumer: U^%d = %.17g, expected %.17g\n", STEPS, u, U[N + STEPS]);
        return 1;
    }
    printf("ok (libdmi %s, U^%d = %.17g)\n", dmi_version(), STEPS, u);
    return 0;
}
