/*
 * Example 4.3's model for the benchmarks of dmi_init and the step
 * (bench_init, bench_cells): n = 2, tau = 1, N cells, friction alpha =
 * (0, 1), the forced oscillator's history and forcing as C callbacks
 * (tests/core/forced_oscillator.h), and the kernel
 * cos 2 pi s + cos 10 pi s + cos 20 pi s in entry (1, 0), as three
 * exponential terms or as a callback.  Uses the libdmi 1.3 API only, so
 * that a benchmark built with it runs against the release before (A/B).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_BENCH_EXAMPLE43_H
#define DMI_BENCH_EXAMPLE43_H

#include <math.h>
#include <stddef.h>

#include "dmi.h"
#include "forced_oscillator.h" /* rhs and history (tests/core) */

#define EX43_PI 3.14159265358979323846

/* How the kernel is given. */
enum { EX43_KERNEL_EXP, EX43_KERNEL_CALLBACK, EX43_KERNEL_NONE };

static int ex43_kernel(double s, double *out, void *user)
{
    (void)user;
    out[2] = cos(2 * EX43_PI * s) + cos(10 * EX43_PI * s) + cos(20 * EX43_PI * s);
    return 0;
}

/* *out = the model with N cells and the kernel given as `kernel` (not yet
 * initialised).  DMI_OK, or the failing call's code (*out may then hold the
 * solver, for its message, or NULL). */
static int ex43_create(dmi_solver **out, size_t N, int kernel)
{
    const double alpha[2] = {0.0, 1.0};
    const double a[3] = {0, 0, 0}, b[3] = {2 * EX43_PI, 10 * EX43_PI, 20 * EX43_PI};
    double C[3 * 4] = {0};
    C[2] = C[6] = C[10] = 1.0;
    *out = NULL;
    int rc = dmi_create(out, 2, 1.0, N);
    if (rc == DMI_OK)
        rc = dmi_set_rhs(*out, rhs, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_history(*out, history, NULL);
    if (rc == DMI_OK)
        rc = dmi_set_friction(*out, alpha);
    if (rc == DMI_OK && kernel == EX43_KERNEL_EXP)
        rc = dmi_set_kernel_exp(*out, 3, a, b, C, NULL);
    if (rc == DMI_OK && kernel == EX43_KERNEL_CALLBACK)
        rc = dmi_set_kernel(*out, ex43_kernel, NULL);
    return rc;
}

#endif
