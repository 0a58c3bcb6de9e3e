# The Hopf point of a one-parameter model: where the rightmost root crosses the imaginary axis.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis.hopf (see docs/stability.md for the method): Brent's method on the real part of
the rightmost root (:func:`dmi.analysis.equilibria.stability.roots`), and for the equation's
Hopf points their criticality (:func:`dmi.analysis.equilibria.normal_form.criticality`)."""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import scipy.optimize

from ..._solver import Solver
from ..continuation.branch import HopfPoint
from .normal_form import criticality
from .stability import check_of, roots


def rightmost_real(make: Callable[[float], Solver], p: float, u_eq: Any, count: int = 4,
                   tol: float = 1e-9, of: str = "scheme") -> float:
    """Re of the rightmost root at p (1 / time unit)."""
    return float(roots(make, p, u_eq, count, tol=tol, of=of)[0].real)


def hopf(make: Callable[[float], Solver], p_lo: float, p_hi: float, u_eq: Any, *,
         rtol: float = 1e-10, count: int = 4, tol: float = 1e-9, of: str = "scheme"
         ) -> HopfPoint:
    """The parameter where the rightmost root crosses the imaginary axis.

    Brent's method on Re lambda_1(p), each value from :func:`roots`.

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver``.
    p_lo, p_hi : float
        The bracket (Re lambda_1 of opposite signs at its ends).
    u_eq : array_like or callable
        The equilibrium, or a function ``u_eq(p)``.
    rtol : float
        Tolerance on p, relative.
    count : int
        Roots computed at each p.
    tol : float
        The equilibrium-residual tolerance of :func:`roots`.
    of : {"scheme", "equation"}
        The scheme's roots (default) or the equation's (see :func:`roots`).

    Returns
    -------
    HopfPoint
        ``.p``, ``.omega`` (|Im lambda_1|; 0: a real root crosses, a fold) and ``.root``;
        with ``of="equation"`` also ``.l1``, ``.l1_error``, ``.criticality``, ``.kappa`` and
        ``.crossing_speed`` (:func:`dmi.analysis.equilibria.normal_form.criticality`).

    Raises
    ------
    ValueError
        p_lo = p_hi, or Re lambda_1 has the same sign at both ends (no crossing bracketed); the
        errors of :func:`roots`.
    """
    check_of(of)
    p_lo, p_hi = float(p_lo), float(p_hi)
    if not (math.isfinite(p_lo) and math.isfinite(p_hi)) or p_lo == p_hi:
        raise ValueError(f"dmi.analysis.hopf: [p_lo, p_hi] = [{p_lo!r}, {p_hi!r}] is not an "
                         "interval (two different finite values)")
    g_lo = rightmost_real(make, p_lo, u_eq, count, tol, of)
    g_hi = rightmost_real(make, p_hi, u_eq, count, tol, of)
    if g_lo == 0:
        p = p_lo
    elif g_hi == 0:
        p = p_hi
    elif (g_lo > 0) == (g_hi > 0):
        raise ValueError(f"dmi.analysis.hopf: no crossing bracketed: Re lambda_1 = {g_lo:.6g} at "
                         f"p = {p_lo!r} and {g_hi:.6g} at p = {p_hi!r} (same sign)")
    else:
        scale = max(abs(p_lo), abs(p_hi))
        p = scipy.optimize.brentq(lambda x: rightmost_real(make, x, u_eq, count, tol, of), p_lo,
                                  p_hi,
                                  xtol=rtol * scale * 1e-2, rtol=max(rtol * 1e-2, 4.5e-16),
                                  maxiter=200)
    lam = roots(make, p, u_eq, count, tol=tol, of=of)[0]
    lam = complex(lam.real, abs(lam.imag))
    hp = HopfPoint(p=float(p), omega=abs(lam.imag), root=lam)
    return criticality(make, hp, u_eq, tol=tol) if of == "equation" else hp


__all__ = ["hopf", "rightmost_real"]
