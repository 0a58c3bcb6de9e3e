/*
 * The callbacks of the forced oscillator of the internals' tests (test_watch,
 * test_lazy): u' = (-u_1, u_0 + 1.3 cos 8t) - ..., history u(t) = (0.1 t,
 * 0.2) for t <= 0 (moving at t = 0: |0.2| > h alpha, slipping).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_TEST_FORCED_OSCILLATOR_H
#define DMI_TEST_FORCED_OSCILLATOR_H

#include <math.h>

static int rhs(double t, const double *u, double *out, void *user)
{
    (void)user;
    out[0] = -u[1];
    out[1] = u[0] + 1.3 * cos(8 * t);
    return 0;
}

static int history(double t, double *out, void *user)
{
    (void)user;
    out[0] = 0.1 * t;
    out[1] = 0.2;
    return 0;
}

#endif
