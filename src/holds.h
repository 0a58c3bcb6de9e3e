/*
 * The holds of the built-in operators (holds.h), the resolvent's rule written
 * once for the step and the watch (dmi.c) and the tangent (tangent.c).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_HOLDS_H
#define DMI_HOLDS_H

/* Friction's resolvent holds U_i at 0 when |x| <= lam = h alpha_i (side 0),
 * else it moves x by lam towards 0 (side +1 above lam, -1 below -lam); the
 * box's projection holds U_i at lo_i when x <= lo_i (side -1), at hi_i when
 * x >= hi_i (+1), else U_i = x (0). */
static inline int friction_side(double x, double lam)
{
    return x > lam ? 1 : x < -lam ? -1 : 0;
}

static inline int box_side(double x, double lo, double hi)
{
    return x <= lo ? -1 : x >= hi ? 1 : 0;
}

#endif
