# Periodic orbits of unknown period (autonomous systems): shooting in (state, h), and the orbit
# born at a Hopf point with its parameter free.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Autonomous periodic orbits: the period P = M h with M fixed and the step h unknown.

The model must then take the step: ``make(p, h=h) -> dmi.Solver`` (libdmi 1.2's
``dmi.Solver(n, tau, h=h)``).  Unknowns (x, h); equations F_h(x) - x = 0 and the phase condition
<xdot_0, x_0 - x_ref> = 0 on the last row (the state at t = 0), xdot_0 the guess's velocity there:
a Poincare section through the guess, across the flow.  Newton with GMRES on the bordered
Jacobian (:func:`dmi.analysis.newton.bordered_newton`, D_hF by one difference in h a step).
N = ceil(tau / h) may change with h: the states hold L = ceil(tau / (0.8 h_0)) + 1 rows (h may
fall by 20 %), the older ones by periodicity.

:func:`hopf_orbit` starts the branch born at a Hopf point: the unknowns are (x, h, p), and an
amplitude condition (the half range of one component over the period) replaces the parameter,
so that it works where the branch leaves the Hopf point vertically (piecewise-linear friction)
as well as where it grows like sqrt|p - p_H|.  Its states hold a whole period (L >= M + 1), from
which the amplitude is read.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .._solver import Solver
from ._model import Linearisation
from .equilibria import equilibrium
from .newton import ShootingError, bordered_newton
from .orbit import Orbit, loops, make_orbit
from .branch import Event
from .stability import HopfPoint
from .stepmap import Model, StepMap, build, fixed_step, positive_time


def step_model(make: Model, p: float, h: float) -> Solver:
    """make(p, h=h), with a model that does not take the step named."""
    try:
        return build(make, p, h=h)
    except TypeError as e:
        if "h" in str(e) or "argument" in str(e):
            raise ValueError(f"an autonomous orbit needs a model make(p, h=...) that takes the "
                             f"step ({e})") from e
        raise


class AutonomousMaps:
    """The StepMaps of make(p, h=h) by (h, p) on states of ``rows`` rows, the last few cached;
    a step h <= h_min, or an N + 1 above ``rows``, is refused (ShootingError)."""

    def __init__(self, make: Model, M: int, rows: int, h_min: float):
        self.make, self.M, self.rows, self.h_min = make, int(M), int(rows), float(h_min)
        self._cache: dict[tuple[float, float], StepMap] = {}

    def __call__(self, h: float, p: float) -> StepMap:
        key = (float(h), float(p))
        F = self._cache.get(key)
        if F is None:
            if not h > self.h_min:
                raise ShootingError(f"the period M h went to {self.M * h:.6g} (h = {h:.6g}), "
                                    f"below the least the state holds, {self.M * self.h_min:.6g}"
                                    f": the guess period is too long for the orbit (a period "
                                    f"near the orbit's?), or there is no orbit near the guess",
                                    [])
            s = step_model(self.make, p, h)
            if s.N + 1 > self.rows:
                raise ShootingError(f"the period M h went to {self.M * h:.6g}: its N + 1 = "
                                    f"{s.N + 1} steps of memory exceed the {self.rows} rows the "
                                    "state holds (the guess period is too long for the orbit?)",
                                    [])
            F = StepMap(fixed_step(self.make, h), p, self.M, self.rows, solver=s)
            if len(self._cache) > 5:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = F
        return F


def velocity(U: np.ndarray, h: float) -> np.ndarray:
    """The velocity at t = 0 of one period U (M + 1 rows), by a central difference across it."""
    M = U.shape[0] - 1
    return (U[1] - U[M - 1]) / (2 * h) if M > 1 else (U[1] - U[0]) / h


def phase_row(x: np.ndarray, xdot: np.ndarray, ref: np.ndarray, k: int
              ) -> tuple[float, np.ndarray]:
    """The phase condition <xdot, x_0 - ref> (x_0 the last row of x) and its row over (x, q)."""
    n = xdot.size
    row = np.zeros(x.size + k)
    row[x.size - n:x.size] = xdot
    return float(np.dot(xdot, x[-n:] - ref)), row


def no_equilibrium(o: Orbit, tol: float, what: str) -> Orbit:
    """o, refused (ShootingError) when its amplitude is below 1e3 tol: shooting converged to an
    equilibrium, a constant orbit of any period."""
    amp = float(np.max(o.amplitude))
    scale = max(1.0, float(np.max(np.abs(o.u))))
    if amp <= 1e3 * tol * scale:
        raise ShootingError(f"{what}: converged to an equilibrium, not an orbit (amplitude "
                            f"{amp:.3g}; the state {o.u[0]!r}): start nearer the orbit, or from "
                            "a Hopf point with hopf_orbit", [o.residual])
    return o


def autonomous_orbit(make: Model, p: float, guess: Any, guess_period: float, *,
                     steps: int | None = None, tol: float = 1e-10, max_iter: int = 30,
                     multipliers: int = 10) -> Orbit:
    """See :func:`dmi.analysis.periodic_orbit` with ``period=None``.  ``steps``: M (default
    round(guess_period / h) with the h of ``make(p)``).  ``guess``: a state (N + 1 rows of the
    solver ``make(p, h=guess_period / M)``, or n values) or such a solver run near the orbit (its
    window is taken as it is: any phase)."""
    P0 = positive_time("guess_period", guess_period)
    M = int(steps) if steps is not None else max(1, round(P0 / build(make, p).h))
    if M < 1:
        raise ValueError(f"steps = {steps}: must be >= 1")
    h0 = P0 / M
    s0 = step_model(make, p, h0)
    rows = max(s0.N + 1, math.ceil(s0.tau / (0.8 * h0)) + 1)
    maps = AutonomousMaps(make, M, rows, 0.8 * h0)
    F0 = maps(h0, p)
    n = F0.n
    if isinstance(guess, Solver):
        if guess.n != F0.n or abs(guess.h - h0) > 1e-12 * h0 or guess.N != F0.N:
            raise ValueError(f"guess: a solver with h = {guess.h!r}, N = {guess.N}; expected the "
                             f"model's at h = guess_period / M = {h0!r} (N = {F0.N})")
        x0 = guess.get_window().ravel()
    else:
        x0 = np.asarray(guess, dtype=float).ravel()
        if x0.size == n:
            x0 = np.tile(x0, F0.N + 1)
        if x0.size % n or not F0.N + 1 <= x0.size // n:
            raise ValueError(f"guess has {x0.size} values ({np.shape(guess)}); give n = {n} "
                             f"values (a constant window), or k >= N + 1 = {F0.N + 1} rows of "
                             f"n = {n} (an (k, {n}) array or k {n} values), the last at t = 0")
    x0 = F0.extend(x0)
    xdot = velocity(F0.trajectory(x0), h0)
    if not np.any(xdot):
        raise ValueError("the guess does not move at t = 0: no phase condition (an equilibrium?)")
    xdot = xdot / np.linalg.norm(xdot)
    ref = x0[-n:].copy()
    what = f"autonomous orbit at p = {p!r}, M = {M} steps, guess period {P0!r}"

    def spread(x: np.ndarray) -> float:   # how far the state's rows differ: 0 at equilibrium
        X = x.reshape(-1, n)
        return float(np.max(X.max(axis=0) - X.min(axis=0)))

    spreads = [spread(x0)]
    try:
        z, res = bordered_newton(lambda q: maps(q[0], p), np.concatenate([x0, [h0]]), 1,
                                 lambda z: _one(phase_row(z[:-1], xdot, ref, 1)), tol=tol,
                                 max_iter=max_iter, what=what, steps=np.array([1e-7 * h0]),
                                 check=lambda z: spreads.append(spread(z[:-1])))
    except ShootingError as e:
        if min(spreads) <= 1e-3 * spreads[0]:   # Newton went for a constant state
            raise ShootingError(f"{what}: Newton went to an equilibrium, not an orbit (the "
                                f"state's rows came to differ by {min(spreads):.3g}, from "
                                f"{spreads[0]:.3g} in the guess), then failed: {e}; start nearer "
                                "the orbit, or from a Hopf point with hopf_orbit",
                                e.residuals) from e
        raise
    o = make_orbit(maps(z[-1], p), z[:-1], res, multipliers, autonomous=True)
    no_equilibrium(o, tol, what)
    k = loops(o.u)
    if k > 1:
        warnings.warn(f"{what}: the orbit found repeats {k} times in its M steps (its least "
                      f"period is about {o.period / k:.6g}, the orbit's {o.period:.6g}): give a "
                      f"guess_period near the period sought, or steps = M / {k}",
                      RuntimeWarning, stacklevel=3)
    return o


def _one(gr: tuple[float, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    return np.array([gr[0]]), gr[1][None, :]


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


def hopf_orbit(make: Model, hopf_point: HopfPoint, u_eq: Any, *, amplitude: float, steps: int,
               component: int | None = None, multipliers: int = 10, tol: float = 1e-10,
               max_iter: int = 30) -> Orbit:
    """The autonomous orbit born at a Hopf point, of a given amplitude, its parameter free.

    An amplitude condition replaces the parameter: the unknowns are the state, the step h (the
    period is M h) and p, the equations the fixed point, a phase condition and the amplitude.
    So the branch may leave the Hopf point as sqrt|p - p_H| (smooth) or vertically
    (piecewise-linear friction, up to grazing).  The first guess is u_eq + a Re(v e^(i omega
    t)) over one period 2 pi / omega, v the null vector of the scheme's characteristic matrix at
    the root.

    Parameters
    ----------
    make : callable
        The model ``make(p, h=...) -> dmi.Solver``: it must take the step.
    hopf_point : HopfPoint or Event
        From :func:`dmi.analysis.hopf`, or a ``hopf`` event of
        :func:`dmi.analysis.continue_equilibrium` (the Event or its ``Event.hopf``).
    u_eq : array_like
        Shape (n,): the equilibrium at the Hopf point (``Event.u``), corrected by Newton at the
        orbit's step.
    amplitude : float
        The half range (max - min) / 2 over the period of the component ``component`` (state
        units), > 0.
    steps : int
        M, steps a period (>= 8).
    component : int, optional
        Default: the largest component of the critical eigenvector.
    multipliers : int
        Leading Floquet multipliers to compute.
    tol : float
        Newton's tolerance.
    max_iter : int
        Newton iterations at most.

    Returns
    -------
    Orbit
        ``autonomous``; its ``p`` is the branch's at that amplitude, its period M h; continue it
        with :func:`dmi.analysis.continue_orbit`.

    Raises
    ------
    ValueError
        Bad input: not a HopfPoint (an event of another kind: said so), omega <= 0 (a fold),
        a root off the imaginary axis, amplitude <= 0, steps < 8, a component
        out of range or not moving in the critical mode, a model that does not take h.
    ShootingError
        Newton fails (every residual listed).
    """
    hopf_point = _hopf_of(hopf_point)
    a = positive_amplitude(amplitude)
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
    o = make_orbit(maps(z[-2], z[-1]), z[:dim], res, multipliers, autonomous=True)
    return no_equilibrium(o, tol, what)
