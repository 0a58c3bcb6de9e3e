# The rule of libdmi's built-in resolvents (dry friction, box) in one place: when a component
# holds, the resolvent's derivative, a component's mode in a step and the saltation factor.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The built-in resolvents' rule, as libdmi applies it (src/holds.h: ``friction_side``,
``box_side``; src/dmi.c: ``held_of``), for the analyses and the sensitivities; private to the
package.

Dry friction with the threshold lam = h alpha_i moves the resolvent's argument x by lam towards 0
(side +1 where x > lam, -1 where x < -lam) and *holds* U_i at 0 where |x| <= lam (side 0, ties
included).  The box [lo_i, hi_i] holds U_i at lo_i where x <= lo_i (side -1), at hi_i where x >=
hi_i (+1), and leaves U_i = x between them (0).

Every function is plain arithmetic on floats and compiles with numba (``numba.njit``) unchanged:
no Python objects, and none calls another (numba compiles a function's callees only when they
are compiled themselves).  The arguments x are finite (libdmi refuses a step whose X is not).  The sides, holds, slopes and modes apply elementwise to NumPy arrays as well
as to scalars (no branches on values: a sum of disjoint indicators where the C code has a ``?:``
chain); :func:`crossing`, :func:`saltation_factor` and :func:`salted` take the scalars of one
reversal.

The modes of a component in a step are read from the resolvent's *value* U^{p+1}: in floating
point x - lam is 0 only at x = lam, so a friction component's U_i is exactly 0 where (and only
where) it holds (lam > 0), and a box component's U_i equals a face exactly where it holds there.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

#: A component's mode in a step (:func:`friction_mode`, :func:`box_mode`).  FREE: no built-in
#: resolvent acts (or a box component between its faces); SLIP_POS / SLIP_NEG: friction slips,
#: U_i > 0 / < 0; STUCK: friction holds U_i = 0 for two steps or more; LO / HI: the box holds
#: U_i on a face; REVERSAL: a lone step at U_i = 0 between steps of opposite signs (the scheme's
#: transversal crossing of a velocity reversal, not a stick); TOUCH: a lone step at 0 between
#: steps of the same sign.
FREE, SLIP_POS, SLIP_NEG, STUCK, LO, HI, REVERSAL, TOUCH = 0, 1, -1, 2, 3, 4, 5, 6


def friction_side(x: Any, lam: Any) -> Any:
    """Where the friction resolvent with threshold lam = h alpha (>= 0) puts x: +1 above lam
    (U = x - lam), -1 below -lam (U = x + lam), 0 where it holds U = 0 (|x| <= lam, ties held)."""
    return 1 * (x > lam) - 1 * (x < -lam)


def box_side(x: Any, lo: Any, hi: Any) -> Any:
    """Where the box's projection puts x: -1 held on lo (x <= lo), +1 held on hi (x >= hi and
    above lo), 0 free between them (U = x)."""
    return 1 * ((x >= hi) & (x > lo)) - 1 * (x <= lo)


def friction_held(x: Any, lam: Any) -> Any:
    """True where the friction resolvent holds U_i = 0 (libdmi's ``held_of``): |x| <= lam."""
    return (x <= lam) & (x >= -lam)


def box_held(x: Any, lo: Any, hi: Any) -> Any:
    """True where the box holds U_i on a face (libdmi's ``held_of`` nonzero)."""
    return (x <= lo) | (x >= hi)


def friction_slope(x: Any, lam: Any) -> Any:
    """R'(x) of the friction resolvent: 0.0 where it holds, 1.0 where it slips, and 1.0 for lam = 0
    (R the identity).  At a tie |x| = lam (a kink) it is the held side's, 0.0."""
    return 1.0 * ((x > lam) | (x < -lam) | (lam == 0.0))


def box_slope(x: Any, lo: Any, hi: Any) -> Any:
    """R'(x) of the box's projection: 1.0 between the faces, 0.0 where it holds (at a face
    itself, a kink, the held side's)."""
    return 1.0 * ((x > lo) & (x < hi))


def friction_slope_alpha(x: Any, lam: Any, h: Any) -> Any:
    """dR/d alpha of the friction resolvent at x: -h on the side x > lam, +h below -lam, 0 where
    it holds (R = x -+ h alpha)."""
    return -h * (1 * (x > lam) - 1 * (x < -lam))


def near(x: Any, b: Any, tol: Any) -> Any:
    """True where x lies within tol (relative to max(|x|, |b|)) of the kink b: |X*| at the
    friction's threshold, X* at a face."""
    return np.abs(x - b) <= tol * np.maximum(np.abs(x), np.abs(b))


def friction_mode(prev: Any, now: Any, nxt: Any) -> Any:
    """The mode of a friction component at the step whose value is ``now``, from its values at
    the steps before (``prev``) and after (``nxt``): STUCK where now = 0 and a neighbour is 0 too
    (held for two steps or more), REVERSAL where now = 0 alone between values of opposite signs,
    TOUCH where it is 0 alone between values of the same sign, else SLIP_POS / SLIP_NEG by the
    sign of now."""
    zero = now == 0.0
    stuck = zero & ((prev == 0.0) | (nxt == 0.0))
    lone = zero & (prev != 0.0) & (nxt != 0.0)
    opposite = (prev > 0.0) != (nxt > 0.0)
    same = (prev > 0.0) == (nxt > 0.0)
    # exactly one term is nonzero
    return (SLIP_POS * (now > 0.0) + SLIP_NEG * (now < 0.0) + STUCK * stuck
            + REVERSAL * (lone & opposite) + TOUCH * (lone & same))


def box_mode(u: Any, lo: Any, hi: Any) -> Any:
    """The mode of a box component whose value is u: LO on lo, HI on hi, else FREE."""
    return LO * (u == lo) + HI * ((u == hi) & (u != lo))


def reaches_zero(u0: Any, u1: Any) -> Any:
    """True where a friction component that slips at u0 (!= 0) reaches zero or changes sign in
    the step to u1: where it may stick or reverse."""
    return (u0 != 0.0) & ((u1 == 0.0) | ((u0 > 0.0) != (u1 > 0.0)))


def crossing(u0: float, u1: float) -> float:
    """Where in a step from u0 (!= 0) to u1 the linear interpolation of u reaches 0: the
    fraction u0 / (u0 - u1) of the step."""
    return u0 / (u0 - u1)


def saltation_factor(sign: float, phi: float, alpha: float) -> float:
    """The saltation factor rho = F+ / F- of a friction component reversing from the slip of
    ``sign`` (+1 or -1), phi = f + W (the net force's opposite) at the reversal: the speed towards
    0 before it, sign phi + alpha, and away from 0 after it, sign phi - alpha; nan where they do
    not both have those signs (no reversal can be placed there)."""
    before = sign * phi + alpha
    after = sign * phi - alpha
    if before <= 0.0 or after <= 0.0:
        return math.nan
    return after / before


def salted(rho: float, T: float, h: float, sign: float, dalpha: float) -> float:
    """The sensitivity of a component just after a reversal from the slip of ``sign``: the
    plain tangent T less the friction's own term h sign dalpha, times rho."""
    return rho * (T - h * sign * dalpha)
