# The periodic orbit born at a Hopf point, its parameter free.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The orbit born at a Hopf point: :func:`hopf_orbit`.

The unknowns are (x, h, p), and an amplitude condition (the half range of one component over
the period) replaces the parameter, so that it works where the branch leaves the Hopf point
vertically (piecewise-linear friction) as well as where it grows like sqrt|p - p_H|.  Its
states hold a whole period (L >= M + 1), from which the amplitude is read.  A Hopf point is
checked before anything is built: an event of another kind, or a root off the imaginary axis,
is refused with the reason.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from .core.model import Linearisation
from .shooting.autonomous import no_equilibrium
from .continuation.branch import Event, HopfPoint
from .equilibria.equilibrium import equilibrium
from .equilibria.normal_form import predicted_parameter
from .branches.collocated import equation_branch_start
from .collocation.orbit import EquationOrbit
from .scheme.floquet import Verify
from .core.newton import bordered_newton
from .scheme.orbit import Orbit, make_orbit
from .scheme.problem import AutonomousMaps, phase_row
from .scheme.stepmap import Model, build, fixed_step


def critical_vector(lin: Linearisation, lam: complex) -> np.ndarray:
    """The null vector v (n,) of the scheme's characteristic matrix at the root lam (the last
    row of the mode U^j = z^j v, z = exp(lam h)), |v|_2 = 1, by the SVD."""
    R = lin.characteristic(np.exp(complex(lam) * lin.h))
    _, _, Vh = np.linalg.svd(R)
    return Vh[-1].conj()


def _hopf_of(hopf_point: Any) -> HopfPoint:
    """The HopfPoint of a ``hopf`` Event or a HopfPoint, checked: omega > 0 and its root on the
    imaginary axis; ValueError saying why otherwise."""
    if isinstance(hopf_point, Event):
        if hopf_point.kind != "hopf" or hopf_point.hopf is None:
            raise ValueError(f"hopf_point: an event of kind {hopf_point.kind!r} at p = "
                             f"{hopf_point.p!r} is not a Hopf point ({hopf_point.detail}); "
                             "hopf_orbit starts at a 'hopf' event, where a pair of non-real "
                             "roots crosses the imaginary axis")
        hopf_point = hopf_point.hopf
    if not isinstance(hopf_point, HopfPoint):
        raise ValueError(f"hopf_point = {hopf_point!r}: give a dmi.analysis.HopfPoint (from "
                         "dmi.analysis.hopf or a 'hopf' event's Event.hopf)")
    if not (hopf_point.omega > 0 and math.isfinite(hopf_point.omega)):
        raise ValueError(f"hopf_point.omega = {hopf_point.omega!r}: a Hopf point has omega > 0 "
                         "(omega = 0 is a fold or a branch point)")
    root = complex(hopf_point.root)
    if not abs(root.real) <= 1e-6 * max(1.0, abs(root)):
        raise ValueError(f"hopf_point: its root {root!r} is not on the imaginary axis (Re = "
                         f"{root.real:.3g}): not a Hopf point (a pair that meets on the real "
                         "axis, or a point not located on the branch); locate it with "
                         "dmi.analysis.hopf or continue_equilibrium")
    return hopf_point


def positive_amplitude(value: Any) -> float:
    """The amplitude of hopf_orbit as a float, finite and > 0; ValueError naming it (a half
    range of a state component, state units) otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"amplitude = {value!r} is not a number") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"amplitude = {v}: must be finite and > 0 (the half range (max - min) "
                         "/ 2 of a state component over the period, state units)")
    return v


def predicted_start(hopf_point: HopfPoint, amplitude: float) -> float | None:
    """Where the equation's orbit of the given amplitude (of the component that moves most) is
    predicted, p_H + side (A / kappa_j)^2 (:func:`predicted_parameter`), for a Hopf point that
    has kappa and its side; None (start at p_H) otherwise."""
    if hopf_point.kappa is None or hopf_point.side is None:
        return None
    if not np.max(np.asarray(hopf_point.kappa, dtype=float), initial=0.0) > 0:
        return None
    return predicted_parameter(hopf_point, amplitude)


def hopf_orbit(make: Model, hopf_point: HopfPoint, u_eq: Any, *, amplitude: float,
               steps: int | None = None, component: int | None = None, multipliers: int = 10,
               tol: float = 1e-10, max_iter: int = 30, verify: Verify | None = None,
               of: str = "scheme", kernel_jumps: tuple[float, ...] = ()
               ) -> Orbit | EquationOrbit:
    """The autonomous orbit born at a Hopf point, of a given amplitude, its parameter free.

    An amplitude condition replaces the parameter: the unknowns are the state, the step h (the
    period is M h) and p, the equations the fixed point, a phase condition and the amplitude.
    So the branch may leave the Hopf point as sqrt|p - p_H| (smooth) or vertically
    (piecewise-linear friction, up to grazing).  The first guess is u_eq + a Re(v e^(i omega
    t)) over one period 2 pi / omega, v the null vector of the scheme's characteristic matrix at
    the root.

    ``of="equation"`` starts the equation's branch instead, by collocation
    (:func:`dmi.analysis.equation_hopf_orbit` at the equation's Hopf point, from
    ``hopf(..., of="equation")``): ``make(p)`` needs no h, ``steps`` is not used, the amplitude
    is sqrt(2) times the RMS distance from u_eq of the component that moves most in the critical
    mode (``component`` must be None), and the EquationOrbit returned continues by
    :func:`dmi.analysis.continue_orbit`; Newton starts at the parameter the Hopf point's kappa
    predicts for that amplitude (:func:`dmi.analysis.equilibria.normal_form.predicted_parameter`;
    at p_H where it has no kappa).

    Parameters
    ----------
    make : callable
        The model ``make(p, h=...) -> dmi.Solver``: it must take the step (``of="scheme"``).
    hopf_point : HopfPoint or Event
        From :func:`dmi.analysis.hopf`, or a ``hopf`` event of
        :func:`dmi.analysis.continue_equilibrium` (the Event or its ``Event.hopf``).
    u_eq : array_like
        Shape (n,): the equilibrium at the Hopf point (``Event.u``), corrected by Newton at the
        orbit's step.
    amplitude : float
        The half range (max - min) / 2 over the period of the component ``component`` (state
        units), > 0.
    steps : int, optional
        M, steps a period (>= 8); required for ``of="scheme"``, not used for the equation.
    component : int, optional
        Default: the largest component of the critical eigenvector.
    multipliers : int
        Leading Floquet multipliers to compute.
    tol : float
        Newton's tolerance.
    max_iter : int
        Newton iterations at most.
    verify : dmi.analysis.Verify, optional
        Tolerances and budgets of the multipliers' verification (default ``Verify()``; the
        scheme's orbit only).
    of : {"scheme", "equation"}
        The scheme's orbit by shooting, or the equation's by collocation.
    kernel_jumps : sequence of float
        ``of="equation"`` only: the lags in (0, tau) where H jumps (time units), as for
        :func:`dmi.analysis.collocate`; the branch carries them.

    Returns
    -------
    Orbit or EquationOrbit
        ``autonomous``; its ``p`` is the branch's at that amplitude, its period M h (the
        equation's: an EquationOrbit); continue it with :func:`dmi.analysis.continue_orbit`.

    Raises
    ------
    ValueError
        Bad input: not a HopfPoint (an event of another kind: said so), omega <= 0 (a fold),
        a root off the imaginary axis, amplitude <= 0, steps < 8, a component
        out of range or not moving in the critical mode, a model that does not take h; ``of``
        not "scheme" or "equation", ``component`` or ``verify`` with ``of="equation"``,
        ``kernel_jumps`` with ``of="scheme"`` (the scheme's cell rule locates jumps itself);
        with ``of="equation"``, a ``u_eq`` that is not an equilibrium of the equation at the
        Hopf point.
    ShootingError
        Newton fails (every residual listed).
    """
    hopf_point = _hopf_of(hopf_point)
    a = positive_amplitude(amplitude)
    if of == "equation":
        if component is not None or verify is not None:
            raise ValueError("hopf_orbit(of='equation'): component= and verify= do not apply "
                             "(the component is the critical mode's largest; the verdict is "
                             "the collocation's)")
        return equation_branch_start(make, hopf_point, u_eq, a, multipliers, tol, max_iter,
                                     tuple(kernel_jumps), start=predicted_start(hopf_point, a))
    if len(kernel_jumps):
        raise ValueError("hopf_orbit: kernel_jumps= is for of='equation' (the collocation's "
                         "delay integral); the scheme takes the kernel as libdmi samples it")
    if of != "scheme":
        raise ValueError(f"of = {of!r}: 'scheme' (shooting) or 'equation' (collocation)")
    if steps is None:
        raise ValueError("steps = None: give M, steps a period (>= 8), for the scheme's orbit "
                         "(or of='equation')")
    M = int(steps)
    if M != steps or M < 8:
        raise ValueError(f"steps = {steps!r}: give a whole number of steps a period, >= 8")
    p = float(hopf_point.p)
    h0 = 2 * math.pi / hopf_point.omega / M
    made = fixed_step(make, h0)
    eq = equilibrium(made, p, u_eq, tol=tol, count=4)
    n = eq.u.size
    with Linearisation(lambda: build(made, p), eq.u, (p,), 1e-6) as lin:
        lam = eq.roots[np.argmin(np.abs(eq.roots - 1j * hopf_point.omega))]
        v = critical_vector(lin, lam)
        tau = lin.tau
    c = int(np.argmax(np.abs(v))) if component is None else int(component)
    if not 0 <= c < n:
        raise ValueError(f"component = {component!r}: the model has n = {n} components")
    if abs(v[c]) < 1e-8:
        raise ValueError(f"component {c} does not move in the critical mode (|v_c| = "
                         f"{abs(v[c]):.2g}): choose another")
    omega = abs(lam.imag)
    h0 = 2 * math.pi / omega / M
    rows = max(M + 1, math.ceil(tau / (0.8 * h0)) + 1)
    maps = AutonomousMaps(make, M, rows, 0.8 * h0)
    t = (np.arange(rows) - (rows - 1)) * h0
    s = a / abs(v[c])
    X = eq.u + s * np.real(np.outer(np.exp(1j * omega * t), v))
    x0 = X.ravel()
    xdot = np.real(1j * omega * s * v)
    xdot = xdot / np.linalg.norm(xdot)
    ref = x0[-n:].copy()
    dim = x0.size
    last = slice(dim - (M + 1) * n + c, dim, n)   # component c over the last period

    def conditions(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g1, r1 = phase_row(z[:dim], xdot, ref, 2)
        w = z[last]
        imax, imin = int(np.argmax(w)), int(np.argmin(w))
        r2 = np.zeros(dim + 2)
        idx = np.arange(dim)[last]
        r2[idx[imax]] += 0.5
        r2[idx[imin]] -= 0.5
        return np.array([g1, 0.5 * (w[imax] - w[imin]) - a]), np.vstack([r1, r2])

    what = f"orbit born at the Hopf point p = {p!r}, amplitude {a!r}, M = {M} steps"
    z, res = bordered_newton(lambda q: maps(q[0], q[1]), np.concatenate([x0, [h0, p]]), 2,
                             conditions, tol=tol, max_iter=max_iter, what=what,
                             steps=np.array([1e-7 * h0, 1e-7 * max(1.0, abs(p))]))
    o = make_orbit(maps(z[-2], z[-1]), z[:dim], res, multipliers, autonomous=True,
                   verify=verify)
    return no_equilibrium(o, tol, what)
