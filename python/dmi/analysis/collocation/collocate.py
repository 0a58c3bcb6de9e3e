# Periodic orbits of the equation (not of the scheme) by orthogonal collocation, from an orbit of
# the scheme: smooth orbits and the multi-segment orbits of dry friction and boxes.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""collocate: the equation's periodic orbit from the scheme's.

The orbit of u' + A(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0 is a continuous periodic
piecewise polynomial of degree m, collocated at the m Gauss-Legendre points of each mesh interval
(:mod:`dmi.analysis.collocation.system`); the delay integral is taken on the polynomial itself,
wrapping as many periods as tau / T needs (:mod:`dmi.analysis.collocation.mesh`).  With the
built-in friction or box the period is cut into segments whose modes (slip +-, stuck, on a face,
free) are read from the scheme's orbit, the segments' ends unknowns with their switching
conditions (:mod:`dmi.analysis.collocation.signature`); every inequality is checked on a fine grid
of the result: a breach splits a segment, a vanishing segment is removed
(:mod:`dmi.analysis.collocation.mend`) and the orbit is solved again; an orbit that breaks one is
never returned.  Multipliers: the discretised
monodromy operator with the saltation at the switches (:mod:`dmi.analysis.collocation.floquet`).

Errors: with ``intervals=None`` the mesh is equidistributed (AUTO, COLSYS: equal integrals of
|u^(m+1)|^(1 / (m + 1)), estimated from the jumps of u^(m) between intervals) and refined in
rounds: each solves the orbit on its mesh and on that mesh with every interval halved (its
check), and twice their difference is the orbit's error estimate
(:func:`dmi.analysis.collocation.adapt.checked`); the first orbit whose estimate of the period
(an autonomous orbit; it converges as h^(2m) on smooth orbits) or of the amplitudes (a forced
one; h^(m+1): an extremum is inside an interval) is below ``tol`` is returned, or where it is
far below, an orbit on fewer intervals whose estimates cover their distances to its check
(:func:`dmi.analysis.collocation.adapt.coarsened`, :func:`kept_coarser`;
:mod:`dmi.analysis.collocation.adapt`: the indicator, the equidistribution, the estimate and
the refinement); its multipliers' estimate is twice their
difference to the check's (those from a few products of the check's monodromy operator from
the orbit's eigenvectors prolonged to the halved mesh, :func:`~.floquet.on_halved`, where their
residuals verify them, else from the check's monodromy matrix), or where the check's cannot be
computed from its mesh with pairs merged, once and twice (Richardson's extrapolation where the
three levels converge steadily, else twice the two levels' difference).
With ``intervals=L`` the orbit is solved on L intervals equidistributed, on that mesh halved
(the orbit returned) and with pairs merged; the difference of the two finer levels is the
estimate of the finer one, or, where the three levels converge steadily, Richardson's estimate
from the order they show (:func:`dmi.analysis.collocation.adapt.estimate`): an upper estimate
while the convergence is in its asymptotic range; where they do not, or the mesh is graded (a
steep orbit: intervals within a piece GRADED = 6 times apart or more), and on every mesh with
``check=True``, the check's, as in a refinement.

Kernels: exponential sums and the truncation at tau exactly; a fitted kernel's near part
s^-beta C on (0, delta] (``set_kernel_fit`` of a fitted PowerKernel) by product integration
(:mod:`dmi.analysis.collocation.mesh`); jumps of H inside (0, tau) given as ``kernel_jumps`` cut
the pieces.  Limits: a jump not given caps the order at 1 (a callback kernel is sampled for jumps
before any mesh is solved, a CollocationWarning names the lag found, and a declared lag where H
does not jump is refused); a user resolvent (``set_resolvent``) has no A to
collocate (use ``refine_orbit``); near cells of any other form are refused.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .adapt import (Solved, check_cost, covered, equidistribute, estimate, first_intervals,
                    levels, lower)
from .floquet import multipliers as floquet, on_halved, pairs
from .mend import mend
from .orbit import EquationOrbit, equation_orbit
from .signature import read_signature
from .system import (CollocationWarning, Layout, Terms, carried, check_inequalities,
                     check_jumps, node_times, reference, solve, uniform_fractions)
from ..core.newton import ShootingError
from ..scheme.orbit import Orbit
from ..scheme.stepmap import build

#: Signature mends at most (a segment split or removed where an inequality breaks).
MENDS = 4
#: A forced model's rhs f(t + T, u) against f(t, u) at these many points of the orbit.
FORCING_POINTS = 16


def collocate(orbit: Orbit, *, degree: int = 4, intervals: int | None = None,
              tol: float = 1e-10, multipliers: int = 10,
              kernel_jumps: tuple[float, ...] = (), check: bool = False) -> EquationOrbit:
    """The equation's periodic orbit near an orbit of the scheme, by orthogonal collocation.

    Piecewise polynomials of degree m on L mesh intervals of one period, collocated at the
    Gauss-Legendre points; the delay integral on the periodic polynomial; for an autonomous orbit
    the period is an unknown with an integral phase condition; with the built-in friction or box
    the period's segments (slip +-, stuck, on a face) are read from the scheme's orbit and their
    ends are unknowns fixed by switching conditions (module docstring: method, errors, limits).

    Parameters
    ----------
    orbit : Orbit
        An orbit of the scheme (:func:`dmi.analysis.periodic_orbit`, :func:`hopf_orbit`, a
        branch's point), forced or autonomous.
    degree : int
        m, the polynomials' degree (2 to 8).
    intervals : int, optional
        L, the mesh's intervals (equidistributed once, not refined; the orbit returned has 2 L,
        the estimate's finer level); None: refined until the estimated error of the period (an
        autonomous orbit) or of the amplitudes (a forced one) is below ``tol``, the estimate
        checked (twice the difference to the orbit on the mesh halved); the other estimates
        are in ``errors``.
    tol : float
        The error asked (time and state units), > 0.
    multipliers : int
        Leading Floquet multipliers (0: none; ``stable`` is then None).
    kernel_jumps : sequence of float
        The lags in (0, tau) where the kernel jumps: the delay integral's pieces are cut there,
        so the order holds (the orbit keeps them for its continuation).  A jump not given caps
        the order at 1: a callback kernel is sampled and a jump found is warned of
        (CollocationWarning, naming its lag); a lag given where it does not jump is refused.
    check : bool
        True: every estimate from the orbit returned against its mesh halved (twice their
        difference), the multipliers' too: the period's 1.7-8.02 times the true error on every
        mesh of ``bench_meshes.py --scan`` (the upper end where the true error is near the
        floor), u's and the multipliers' about 2 times; with ``intervals=L`` 1.2-2.1 times the
        CPU (the solve on the mesh halved; ``bench_meshes.py --check-cost``).  False: with
        ``intervals=None`` the same (the refinement checks every round, its multipliers too);
        with ``intervals=L`` the check's only where the three levels are not steady (an order
        seen above the period's 2 m is not steady) or the mesh is graded, elsewhere
        Richardson's estimate from the three levels, which overstates the period's error up to
        some 650 times there (none below it on the scan's 231 meshes), and u's and the
        multipliers' from the two or three levels (a multiplier's two-level difference counted
        twice).  ``stable`` is judged against the
        multipliers' estimate, so a verdict the levels leave undecided (None) may be decided
        with ``check=True``.

    Returns
    -------
    EquationOrbit
        The orbit with its period, amplitude, multipliers, stability, mesh, signature and
        estimated errors (those of the orbit returned).

    Warns
    -----
    CollocationWarning
        The returned orbit's check (its mesh halved: every round of a refinement; with
        ``intervals=L`` where its levels are not steady, the mesh is graded, or ``check``) could
        not be solved or its solution breaks the signature's inequalities, or the check's
        multipliers asked for could not be computed: the message says why, and the estimate is
        the levels'; a callback kernel's undeclared jump (``kernel_jumps``).

    Raises
    ------
    TypeError
        ``orbit`` is not an Orbit of the scheme.
    ValueError
        Bad degree, intervals, tol or kernel_jumps (a declared lag where a callback kernel
        does not jump); an orbit whose period is not finite, not steps h, or not a period of
        the model's forcing; a model ``make(p)`` of another dimension; a constant autonomous
        orbit (an equilibrium); a memory spanning so many periods that the delay integral would
        exceed MAX_DELAY_NODES; a model with a user resolvent (use ``refine_orbit``) or with
        near cells not of a fitted PowerKernel; a result that still breaks an inequality of its
        signature after MENDS mends (the message names it; refine the scheme's orbit); with
        ``intervals=None``, the estimate at the floor of rounding (CHECKED_FLOOR) above ``tol``,
        stopped falling, or needing more than MAX_INTERVALS intervals or MAX_ROUNDS rounds (the
        message names the estimate reached and its mesh).
    ShootingError
        Newton fails; from the scheme's orbit (the first solve), or onto the equilibrium, with
        a message saying that the scheme's orbit is too far from the equation's and what to
        do.
    """
    if not isinstance(orbit, Orbit):
        raise TypeError(f"collocate: give an Orbit of the scheme (periodic_orbit, hopf_orbit), "
                        f"not {type(orbit).__name__}")
    m = int(degree)
    if m != degree or not 2 <= m <= 8:
        raise ValueError(f"collocate: degree = {degree!r}: give a whole number in 2..8")
    if intervals is not None and (int(intervals) != intervals or intervals < 4):
        raise ValueError(f"collocate: intervals = {intervals!r}: give a whole number >= 4, or "
                         "None to adapt")
    if not (tol > 0 and math.isfinite(tol)):
        raise ValueError(f"collocate: tol = {tol!r}: give a finite tol > 0")
    T0 = checked_period(orbit)
    terms = Terms(build(orbit.make, orbit.p), kernel_jumps)
    check_orbit(orbit, terms)
    capped = check_jumps(terms, "collocate")
    sig, b0 = read_signature(orbit.u, orbit.h, terms.alpha, terms.lo, terms.hi)
    lay = Layout(m, terms.n, sig, [], bool(orbit.autonomous), T0, carried(terms, sig))
    bounds = lay.bounds(b0, T0)
    pieces = bounds.size - 1
    L = int(intervals) if intervals is not None else 4 * pieces
    L0 = max(8, 2 * pieces, L // 2)        # a first solve: the indicator, the phase
    what = f"collocation of the orbit at p = {orbit.p!r}"
    lay, x1 = first_solve(orbit, terms, lay, b0, L0, what)
    if intervals is None:
        L = first_intervals(tol, m, pieces, lay.L > L0)
    ref = reference(lay, x1) if orbit.autonomous else None
    count = int(multipliers)
    for attempt in range(MENDS + 1):
        c, f = levels(lay, terms, x1, ref, L, intervals is not None, tol, what, capped,
                      bool(check))
        if orbit.autonomous:
            fell_to_equilibrium(f.lay, f.x, orbit)
        bad = check_inequalities(f.lay, terms, f.x)
        if not bad:
            return _result(orbit, terms, c, f, count, bool(check), ref)
        mended = mend(f.lay, terms, f.x) if attempt < MENDS else None
        if mended is None:
            break
        lay, x1 = mended                      # a segment split or removed: solve again
        x1, _ = solve(lay, terms, x1, ref, what=what)
    raise ValueError("collocate: the collocated orbit breaks its signature's inequalities "
                     f"({'; '.join(bad[:4])}) after {attempt} mends of the signature read from "
                     f"the scheme ({', '.join(f.lay.signature.describe())}); refine the scheme's "
                     "orbit (a smaller h) and collocate again")


def first_solve(orbit: Orbit, terms: Terms, lay: Layout, b0: np.ndarray, L0: int, what: str
                ) -> tuple[Layout, np.ndarray]:
    """The first solve from the scheme's orbit, on L0 equal intervals of each piece; where
    Newton fails there (a steep orbit, a relaxation oscillation, on too coarse a mesh), again on
    2 L0 and 4 L0 intervals, a smooth orbit's graded to the scheme's speed |u'| (equal arc
    length) and, where both fail, equal (a scheme's period far off the equation's puts its
    steep stretches elsewhere).  ShootingError saying what to do when the last fails too."""
    T0 = float(orbit.period)
    t_s = np.asarray(orbit.t, dtype=float)
    U = np.asarray(orbit.u, dtype=float)
    bounds = lay.bounds(b0, T0)

    def scheme(t: np.ndarray) -> np.ndarray:
        tt = np.mod(t, T0)
        return np.column_stack([np.interp(tt, t_s, U[:, i]) for i in range(terms.n)])
    failed: ShootingError | None = None
    finer = (2 * L0, 4 * L0)
    tries = [(L0, False)] + [(c, lay.S == 0) for c in finer] + (
        [(c, False) for c in finer] if lay.S == 0 else [])
    for count, graded in tries:
        try:
            check_cost(terms, lay.m, count, T0, "the first mesh", "check orbit.period (a "
                       "period far shorter than the memory is no orbit of the scheme)")
        except ValueError:
            if failed is None:
                raise
            continue                              # too fine a first mesh: the next try
        if graded:
            speed = np.linalg.norm(np.diff(U, axis=0), axis=1) / np.diff(t_s)
            fractions = [equidistribute(t_s, speed, count) / T0]
        else:
            fractions = uniform_fractions(bounds, count)
        lay = lay.with_fractions(fractions)
        x0 = np.concatenate([scheme(node_times(lay, b0, T0)).ravel(), b0,
                             [T0] if orbit.autonomous else []])
        try:
            x1, _ = solve(lay, terms, x0, reference(lay, x0) if orbit.autonomous else None,
                          what=what)
        except ShootingError as err:
            failed = failed or err                # the first mesh's failure is the one said
            continue
        if orbit.autonomous:
            fell_to_equilibrium(lay, x1, orbit)
        return lay, x1
    assert failed is not None
    raise ShootingError(f"{failed} -- {too_far(orbit)}", failed.residuals) from None


def _result(orbit: Orbit, terms: Terms, c: Solved | None, f: Solved, count: int, check: bool,
            ref: Any) -> EquationOrbit:
    """The EquationOrbit of f (the orbit returned), with its multipliers and, with ``check`` or
    where there are no coarser levels (a refinement), its check's (f's mesh halved, for the
    multipliers' checked estimate: :func:`check_multipliers`); where there are none, the coarser
    levels' (the third, where it was solved, for the extrapolated estimate; a refinement's from
    f's mesh merged once and twice, :func:`~.adapt.lower`, made here); where neither, the
    multipliers' estimate is inf, and a CollocationWarning says so."""
    if f.unchecked is not None:
        kept = "three" if c is not None and c.coarser is not None else "two"
        warnings.warn(f"collocate: the orbit on {f.lay.L} intervals is not checked on its mesh "
                      f"halved ({2 * f.lay.L} intervals): {f.unchecked}; its estimate is the "
                      f"{kept} levels'", CollocationWarning, stacklevel=3)
    if count > 0:
        if f.finer is not None:
            f = kept_coarser(f, terms, count)
        if f.check is not None and (check or c is None) and not f.mu.size:
            try:
                check_multipliers(f, terms, count)
            except (RuntimeError, ValueError, np.linalg.LinAlgError) as err:
                if c is None:
                    c = lower(f, terms, ref)
                kept = ("the levels'" if c is not None else "none: the orbit's mesh merged "
                        "could not be solved either (inf)")
                warnings.warn(f"collocate: the multipliers of the check ({f.check.lay.L} "
                              f"intervals) could not be computed ({type(err).__name__}: {err}); "
                              f"the multipliers' estimate is {kept}", CollocationWarning,
                              stacklevel=3)
        if not f.mu.size:
            f.mu = floquet(f.lay, terms, f.x, count)
        if c is not None and (f.check is None or not f.check.mu.size):  # the levels' estimate
            c.mu = floquet(c.lay, terms, c.x, count)
            if c.coarser is not None:
                c.coarser.mu = floquet(c.coarser.lay, terms, c.coarser.x, count)
    return equation_orbit(f, float(orbit.p), orbit.make, estimate(c, f), terms.H.jumps)


def kept_coarser(g: Solved, terms: Terms, count: int) -> Solved:
    """g, a refinement's coarser try (:func:`~.adapt.coarsened`), with its multipliers and its
    check's (:func:`check_multipliers`) where their estimates cover their distances to those of
    its finer round's check (:func:`~.adapt.covered`, computed from the round's); else the
    round, with its multipliers and its check's (none where either level's failed: the caller
    computes the round's as for any orbit)."""
    f = g.finer
    try:
        check_multipliers(g, terms, count)
        check_multipliers(f, terms, count)
    except (RuntimeError, ValueError, np.linalg.LinAlgError):
        f.mu = f.check.mu = np.empty(0, complex)
        return f
    return g if covered(g, multipliers=True) else f


def check_multipliers(f: Solved, terms: Terms, count: int) -> None:
    """f's ``count`` multipliers with their eigenvectors (:func:`~.floquet.pairs`), and its
    check's from them (:func:`~.floquet.on_halved`: a few products of the check's monodromy
    operator from f's eigenvectors prolonged), or where those are not verified or the check's
    state is beyond a dense decomposition (ARPACK's there), by :func:`~.floquet.multipliers`;
    set as f.mu and f.check.mu."""
    F = f.check
    assert F is not None
    f.mu, V = pairs(f.lay, terms, f.x, count)
    mu = None if V is None else on_halved(F.lay, F.x, f.lay, f.x, terms, f.mu, V)
    F.mu = mu if mu is not None else floquet(F.lay, terms, F.x, count)


def checked_period(orbit: Orbit) -> float:
    """The orbit's period, checked to be finite, > 0 and steps h (t and u of steps + 1 rows):
    ValueError naming the field otherwise (an Orbit edited by hand)."""
    T = float(orbit.period)
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"collocate: orbit.period = {orbit.period!r}: a period is finite and > "
                         "0 (steps h of the scheme's orbit); make the orbit with "
                         "periodic_orbit or hopf_orbit")
    M, h = int(orbit.steps), float(orbit.h)
    if not (M >= 1 and math.isfinite(h) and h > 0 and abs(M * h - T) <= 1e-9 * T):
        raise ValueError(f"collocate: orbit.period = {T!r} is not its steps h = {M} x {h!r} = "
                         f"{M * h!r}: an Orbit edited by hand; make the orbit with "
                         "periodic_orbit (at the forcing's period, or a multiple of it) or "
                         "hopf_orbit, whose period is the scheme's M steps")
    u, t = np.asarray(orbit.u), np.asarray(orbit.t)
    if u.ndim != 2 or u.shape[0] != M + 1 or t.shape != (M + 1,):
        raise ValueError(f"collocate: orbit.u has shape {u.shape} and orbit.t {t.shape}; an "
                         f"orbit of {M} steps has ({M + 1}, n) and ({M + 1},): an Orbit edited "
                         "by hand; make it with periodic_orbit or hopf_orbit")
    if not np.all(np.isfinite(u)):
        raise ValueError("collocate: orbit.u is not finite: make the orbit with periodic_orbit "
                         "or hopf_orbit")
    return T


def check_orbit(orbit: Orbit, terms: Terms) -> None:
    """The orbit against its model ``make(p)``: the same dimension; a forced orbit's period a
    period of the rhs (f(t + T, u) = f(t, u) at FORCING_POINTS points of the orbit, to 1e-8
    relative); an autonomous orbit not constant (an equilibrium).  ValueError saying which."""
    u = np.asarray(orbit.u, dtype=float)
    if u.shape[1] != terms.n:
        raise ValueError(f"collocate: the orbit has {u.shape[1]} components (orbit.u's columns) "
                         f"but its model orbit.make(p = {orbit.p!r}) has n = {terms.n}: the orbit "
                         "is of another model; collocate the orbit with the make it was found "
                         "with")
    T = float(orbit.period)
    if orbit.autonomous:
        spread = constant_spread(u)
        if spread is not None:
            raise ValueError(f"collocate: the orbit at p = {orbit.p!r} is constant (its states "
                             f"differ by {spread:.3g}): an equilibrium of the model, {u[0]!r}, "
                             "not an orbit (a constant state is periodic with any period); for "
                             "its stability use dmi.analysis.equilibrium, for the orbits born "
                             "at a Hopf point hopf_orbit")
        return
    if not terms.has_rhs:
        return
    k = np.linspace(0, orbit.steps, FORCING_POINTS, endpoint=False).astype(int)
    t = np.asarray(orbit.t, dtype=float)[k]
    f0 = terms.solver.eval_rhs_many(t, u[k])
    f1 = terms.solver.eval_rhs_many(t + T, u[k])
    miss = np.max(np.abs(f1 - f0), axis=1)
    size = max(1.0, float(np.max(np.abs(f0))))
    c = int(np.argmax(miss))
    if miss[c] > 1e-8 * size:
        raise ValueError(f"collocate: the orbit's period T = {T!r} is not a period of the "
                         f"model's forcing at p = {orbit.p!r}: f(t + T, u) differs from f(t, u) "
                         f"by {miss[c]:.3g} at t = {float(t[c])!r}, u = {u[k[c]]!r} ({miss[c] / size:.2g}"
                         " relative); a forced orbit's period is the forcing's or a multiple of "
                         "it: make the orbit with periodic_orbit at that period")


def too_far(orbit: Orbit) -> str:
    """What to do when Newton's method does not reach the equation's orbit from the scheme's."""
    base = (f"the scheme's orbit (h = {orbit.h:.3g}, {orbit.steps} steps a period) is too far "
            "from the equation's for Newton's method to start from it (the scheme's answers "
            "are O(h) off the equation's)")
    if not orbit.autonomous:
        return base + ": refine the scheme's orbit (a smaller h) and collocate again"
    return (base + "; near a Hopf point the scheme's Hopf point is O(h) off the equation's, and "
            "at this p the equation may have no orbit of this amplitude: refine the scheme's "
            "orbit (a smaller h) and collocate again, or start on the equation's branch, hp = "
            "hopf(make, p_lo, p_hi, u_eq, of='equation'), then hopf_orbit(make, hp, u_eq, "
            "amplitude=..., of='equation') and continue_orbit")


def constant_spread(U: np.ndarray) -> float | None:
    """The spread max_i (max U_i - min U_i) of states U (rows) that are constant, i.e. differ
    by at most 1e-9 max(1, |U|); None when they move."""
    spread = float(np.max(U.max(axis=0) - U.min(axis=0)))
    return spread if spread <= 1e-9 * max(1.0, float(np.max(np.abs(U)))) else None


def fell_to_equilibrium(lay: Layout, x: np.ndarray, orbit: Orbit) -> None:
    """ShootingError when the collocated autonomous orbit x is constant (its node values
    differ by at most 1e-9 max(1, |u|)) while the scheme's orbit moves: Newton fell onto the
    equilibrium, which every period solves."""
    V = lay.split(x)[0]
    spread = constant_spread(V)
    if spread is None:
        return
    raise ShootingError(f"collocation of the orbit at p = {orbit.p!r}: Newton's method fell "
                        f"onto an equilibrium, {V[0]!r} (the collocated states differ by "
                        f"{spread:.3g}; the scheme's orbit has the amplitudes "
                        f"{orbit.amplitude!r}), not an orbit: {too_far(orbit)}", [])


__all__ = ["collocate", "CollocationWarning"]
