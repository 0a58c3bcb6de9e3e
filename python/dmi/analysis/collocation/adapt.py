# Mesh adaptation of a collocated orbit: the indicator, the equidistribution, the adaptation step
# between solves, and the error estimates with the refinement they steer.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Where the mesh of a collocated orbit comes from and how good the orbit on it is; private to the
package (:mod:`dmi.analysis.collocation.collocate` and the collocated branch use it).

- The indicator (:func:`indicator`): |u^(m+1)|^(1 / (m + 1)) on each interval, from the jumps of the
  piecewise constant u^(m) (AUTO's); :func:`equidistribute` puts equal integrals of it on each new
  interval (AUTO, COLSYS), :func:`adapted` does so piece by piece of a nonsmooth orbit.
- The adaptation step (:func:`readapted`): an orbit moved onto its mesh equidistributed again (the
  same intervals), between the steps of a branch.
- The estimate (:func:`estimate`; a refinement's always checked): the orbit on a mesh and on
  that mesh with every interval halved (:func:`halved`) or every pair merged (:func:`merged`);
  the difference of their period, amplitudes, multipliers and u is the finer one's error
  estimate; with a third level (the
  coarser's mesh merged, its ``coarser``) the period, amplitudes and multipliers by Richardson's
  extrapolation where the three levels are steady (:func:`extrapolated`); where they are not,
  the mesh is graded (GRADED: a steep orbit), or every mesh is asked (collocate's ``check``),
  the period, amplitudes and u from the finer against its own mesh halved (:func:`checked`:
  CHECK_SAFETY times their difference; the multipliers too where the check has them).  An
  autonomous orbit's two solutions are compared after aligning their phase (:func:`aligned`):
  its phase is free, and a shift along a steep orbit is no error of its shape.
- A fixed mesh (:func:`fixed_levels`, collocate's ``intervals=L``): L intervals equidistributed,
  solved with that mesh halved (the orbit returned) and merged (:func:`two_levels`).
- The refinement (:func:`refined`): from a first mesh that depends on tol
  (:func:`first_intervals`), rounds of the orbit on a mesh equidistributed anew and on that mesh
  halved (its check); the first whose check's estimate (:func:`round_error`) meets tol is
  returned (its multipliers' estimate from the check's, or where those fail from its mesh
  merged once and twice, :func:`lower`); the next mesh by the order the rounds show
  (:func:`next_intervals`, :func:`rounds_order`), with the stopping rules and the cost check of
  the delay integral (:func:`check_cost`).  A round's difference to its check split among its
  intervals (an autonomous orbit's, :func:`contributions`: the dual-weighted residual) reshapes
  the next mesh (:func:`reshaped`): a switch whose interval carries most of it is graded in the
  rounds after (:func:`hot_ends`, :func:`graded`, :func:`regraded`), and where a few intervals
  carry enough of it, the next round is the same mesh with those halved (:func:`repaired`).

May import: :mod:`.mesh`, :mod:`.signature`, :mod:`.system` (no module of the package above them).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from .mesh import _legendre_form
from .system import (GRADED, Layout, Terms, assemble, check_inequalities, evaluate, factored,
                     interval_counts, node_times, reference, solve)
from ..core.newton import ShootingError

#: Mesh refinement rounds at most (intervals=None).
MAX_ROUNDS = 6
#: Intervals at most.
MAX_INTERVALS = 4000
#: The errors' floor, relative to their quantities (at least 1): Newton's 1e-12 and the solve's
#: rounding; the multipliers' (their eigenproblem, and a stick-slip orbit's switching columns by
#: differences, which every level shares) and the levels' estimates of the period, amplitudes and
#: u (below 1e-11 relative Richardson's rule has been seen below the true error: 0.972 times it
#: on van der Pol at degree 6, 12 intervals, 3.9e-12 relative).
FLOOR = 1e-11
#: The floor of a checked estimate of the period, amplitudes and u (the finer level against its
#: mesh halved), relative: the solve's rounding (`bench_meshes.py --rounding`: periods whose
#: truncation is below rounding spread by 1.4e-14 relative on van der Pol, 3.7e-13 on the
#: relaxation oscillation over degrees 6 to 8) with a margin of about 3.
CHECKED_FLOOR = 1e-12
#: The least observed order of the refinement's estimate (log of its fall over log of the mesh's
#: growth): below it the estimate has stopped falling.
LEAST_ORDER = 0.5
#: An estimate that has not fallen (LEAST_ORDER) says it has stopped falling only over a growth
#: of the mesh of LEAST_GROWTH at least and below CONDITIONED (relative to the period or the
#: amplitudes, at least 1); a smaller step or a larger estimate (not yet in the asymptotic range,
#: or the meshes' lottery: the rounds' meshes are not nested, and on the relaxation oscillation
#: at degree 6 and 1e-8 the round of 71 intervals has the estimate 1.7e-8 where the round of 64
#: before it has 1.0e-8) grows again by the expected order.
LEAST_GROWTH = 1.2
CONDITIONED = 1e-9
#: The least observed order (from three levels) a Richardson estimate trusts.
LEAST_RICHARDSON = 1.0
#: The coarsest of three levels farther than this (relative, at least 1) from the middle one
#: is not yet in the asymptotic range (a relaxation oscillation on 18 intervals of degree 6:
#: 2e-2 off, its order seen 12.6, the true 3).
ROUGH = 1e-3
#: The Richardson estimate's safety factor over |d2| / (2^q - 1).
SAFETY = 8.0
#: The first round's intervals where tol <= FIRST_TOL at degree FIRST_DEGREE (van der Pol of
#: degree 4 meets 1e-8 on twice that); a looser tol or a higher degree starts coarser
#: (:func:`first_intervals`), on LEAST_POINTS / m intervals at least (rounded: LEAST_POINTS
#: collocation points), within 4 to LEAST_FIRST.
FIRST_INTERVALS = 16
FIRST_TOL = 1e-8
FIRST_DEGREE = 4
LEAST_POINTS = 24
LEAST_FIRST = 8
#: The check's safety factor over |x_f - x_F| (:func:`checked`): never below the checked level's
#: error where the check's is at most half of it (an order of 1 from a mesh to its halving).
CHECK_SAFETY = 2.0
#: A multiplier's two-level difference (its levels not steady, or two levels) counts this many
#: times as the finer level's error estimate: a multiplier's convergence is not always monotone
#: (van der Pol without memory, degree 4, L = 12: the middle level 2.0e-11 from the truth, the
#: finer 3.5e-10, their difference 0.943 times the finer's error).
TWO_LEVEL_SAFETY = 2.0
#: The next mesh's growth over what the order says (:func:`next_intervals`; the check's estimate
#: is about twice the true error, so a mesh aimed at tol lands at about half of it).
MARGIN = 1.1
#: A refinement's round whose check is farther than ROUGH from it in the period (an autonomous
#: orbit), or could not be solved, while no round was nearer, grows the mesh by this factor at
#: most (the round says nothing of the order).
FAR_GROWTH = 4
#: An interval at a piece's end (a switch) carrying at least this share of the round's difference
#: to its check in the period (:func:`contributions`) is graded towards that end
#: (:func:`graded`): a weakly singular kernel s^-beta makes the solution (t - t_s)^(j + 2 - beta)
#: past a switch where its j-th derivative jumps (7/2 at the fractional belt's slip onset),
#: which the equidistribution of u^(m+1) does not see, and that interval's share of the period
#: falls at the order 3.5 instead of 2m.
HOT_SHARE = 0.5
#: The order assumed of a graded end's share (one more level halves that end's interval; 3.5
#: seen on the fractional belt, 2 assumed).
GRADE_ORDER = 2.0
#: The levels of a graded end at most (2^-24 of its interval: past that the mesh's times lose
#: their digits).
GRADE_MOST = 24
#: A round's hottest intervals are halved in place of a new mesh (:func:`repaired`) where at most
#: this part of its intervals (at least 2) carries enough of its difference to its check: on the
#: relaxation oscillation the mesh's lottery puts a third to three quarters of a round's
#: difference into one or two intervals of the steep stretch.
REPAIR_PART = 4
#: A refinement whose last round meets tol on more than this many times the intervals its
#: estimate says suffice (at the expected order, with MARGIN; at least :func:`least_intervals`)
#: tries that fewer (:func:`coarsened`): a round aimed at tol lands below it, and one order of
#: magnitude of the period's error is only (10)^(1/(2 m)) in the intervals (1.47 at degree 3).
#: Not tried where the round's estimate is at the floor of rounding (it says nothing of the
#: order there).
COARSER = 1.25
#: Quadrature nodes of the delay integral at most on one mesh (about 100 bytes each): a memory
#: spanning many periods (tau / T large) or a very fine mesh is refused before it is built.
MAX_DELAY_NODES = 2e7


def equidistribute(mesh: np.ndarray, indicator: np.ndarray, L: int) -> np.ndarray:
    """A mesh of L intervals over [mesh[0], mesh[-1]] on which the piecewise constant density
    ``indicator`` (per interval of ``mesh``, >= 0) has equal integrals (as AUTO and COLSYS), a
    floor of 1 % of its mean keeping quiet stretches meshed."""
    h = np.diff(mesh)
    d = np.maximum(indicator, 1e-2 * max(float(np.sum(indicator * h) / np.sum(h)), 1e-300))
    cum = np.concatenate([[0.0], np.cumsum(d * h)])
    target = np.linspace(0.0, cum[-1], L + 1)
    new = np.interp(target, cum, mesh)
    new[0], new[-1] = mesh[0], mesh[-1]
    return new


def halved(fractions: list[np.ndarray], only: np.ndarray | None = None) -> list[np.ndarray]:
    """Every interval cut in two, or those whose indices (counted over the pieces in turn, as
    the mesh's) are in ``only``."""
    out = []
    first = 0
    for f in fractions:
        mid = 0.5 * (f[:-1] + f[1:])
        if only is not None:
            mid = mid[np.isin(np.arange(first, first + mid.size), only)]
        first += f.size - 1
        out.append(np.sort(np.concatenate([f, mid])))
    return out


def merged(fractions: list[np.ndarray]) -> list[np.ndarray]:
    """Every pair of intervals made one (a piece of an odd count keeps its last interval)."""
    out = []
    for f in fractions:
        g = f[::2]
        out.append(g if g[-1] == f[-1] else np.append(g, f[-1]))
    return out


def transfer(lay: Layout, x: np.ndarray, new: Layout) -> np.ndarray:
    """x's orbit on the layout ``new`` (same signature, b's and T)."""
    _, b, T = lay.split(x)
    V = evaluate(lay, x, node_times(new, b, T))
    return np.concatenate([V.ravel(), x[lay.rows * lay.n:]])


def indicator(lay: Layout, x: np.ndarray) -> np.ndarray:
    """(L,): |u^(m+1)|^(1/(m+1)) estimated on each interval from the jumps of the piecewise
    constant u^(m) to its neighbours in the same piece (AUTO's indicator); an interval alone in
    its piece takes |u^(m)| / h (no neighbour to difference with)."""
    m = lay.m
    V, b, T = lay.split(x)
    h = np.diff(lay.mesh(b, T))
    k = np.arange(m + 1)
    cols = (np.arange(lay.L)[:, None] * m + k[None, :]) % lay.rows
    top = np.einsum("k,lkn->ln", lay.basis.top, V[cols]) / h[:, None] ** m   # u^(m) (L, n)
    piece = lay.piece_of_interval()
    jump = np.zeros(lay.L)
    same = piece[1:] == piece[:-1]
    if lay.signature.switches == 0:                        # one piece: around the circle
        d = np.linalg.norm(np.roll(top, -1, axis=0) - top, axis=1)
        dist = 0.5 * (h + np.roll(h, -1))
        g = d / dist
        jump = np.maximum(g, np.roll(g, 1))
    else:
        d = np.linalg.norm(top[1:] - top[:-1], axis=1) / (0.5 * (h[1:] + h[:-1]))
        d = np.where(same, d, 0.0)
        jump[:-1] = np.maximum(jump[:-1], d)
        jump[1:] = np.maximum(jump[1:], d)
        alone = np.ones(lay.L, bool)
        alone[:-1] &= ~same
        alone[1:] &= ~same
        jump = np.where(alone, np.linalg.norm(top, axis=1) / h, jump)
    return jump ** (1.0 / (m + 1))


def adapted(lay: Layout, x: np.ndarray, L: int) -> list[np.ndarray]:
    """Fractions of L intervals (about) equidistributing :func:`indicator` piece by piece."""
    rho = indicator(lay, x)
    _, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    e = lay.bounds(b, T)
    piece = lay.piece_of_interval()
    h = np.diff(mesh)
    weight = np.array([np.sum((rho * h)[piece == j]) for j in range(len(lay.fractions))])
    # a floor: a quarter of the share of the piece's length (a quiet piece stays meshed)
    weight = np.maximum(weight, 0.25 * np.diff(e) / T * weight.sum())
    counts = interval_counts(weight, L)
    out = []
    for j, c in enumerate(counts):
        sel = piece == j
        pm = np.concatenate([mesh[:-1][sel], [mesh[1:][sel][-1]]])
        new = equidistribute(pm, rho[sel], int(c))
        out.append((new - e[j]) / (e[j + 1] - e[j]))
        out[-1][0], out[-1][-1] = 0.0, 1.0
    return out


def readapted(lay: Layout, x: np.ndarray) -> tuple[Layout, np.ndarray]:
    """The adaptation step: the layout on the mesh that equidistributes x's :func:`indicator`
    again (the same intervals, piece by piece), and x moved onto it."""
    new = lay.with_fractions(adapted(lay, x, lay.L))
    return new, transfer(lay, x, new)


def extrema(lay: Layout, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(max (n,), min (n,)) of each component on the piecewise polynomial: the derivative's
    roots in the intervals next to the largest and smallest nodes."""
    m, n = lay.m, lay.n
    V = lay.split(x)[0]
    k = np.arange(m + 1)
    A = _legendre_form(m)[0]            # the interval's polynomial in y = 2 z - 1 from its nodes
    hi, lo = V.max(axis=0).copy(), V.min(axis=0).copy()
    for i in range(n):
        for sign, best in ((1.0, hi), (-1.0, lo)):
            node = int(np.argmax(sign * V[:, i]))
            iv = node // m
            for j in {(iv - 1) % lay.L, iv, (iv + 1) % lay.L}:
                vals = V[(j * m + k) % lay.rows, i]
                c = A @ vals                          # its Legendre coefficients
                r = np.polynomial.legendre.legroots(np.polynomial.legendre.legder(c))
                r = r.real[(np.abs(r.imag) < 1e-9) & (np.abs(r.real) <= 1)]
                if r.size:
                    v = np.polynomial.legendre.legval(r, c)
                    best[i] = max(best[i], v.max()) if sign > 0 else min(best[i], v.min())
    return hi, lo


class Solved:
    """A solution on one layout, with its derived quantities: b, T, the amplitudes and the
    multipliers ``mu`` (given; none by default), ``coarser``, the solution on its mesh with
    pairs merged (the estimate's third level; None unless :func:`two_levels` set it), and
    ``check``, the solution on its mesh halved (:func:`checked`; None unless set),
    ``unchecked``, why a check asked for was not made (not solved, or its solution breaks the
    signature's inequalities; None), and ``finer``, the refinement's round a coarser try
    replaced (:func:`coarsened`; None)."""

    def __init__(self, lay: Layout, x: np.ndarray, mu: np.ndarray | None = None):
        self.lay, self.x = lay, x
        _, self.b, self.T = lay.split(x)
        self._amplitude: np.ndarray | None = None
        self.mu = np.empty(0, complex) if mu is None else mu
        self.coarser: Solved | None = None
        self.check: Solved | None = None
        self.unchecked: str | None = None
        self.finer: Solved | None = None

    @property
    def amplitude(self) -> np.ndarray:
        """(max - min) / 2 of each component (:func:`extrema`), computed when first asked."""
        if self._amplitude is None:
            hi, lo = extrema(self.lay, self.x)
            self._amplitude = 0.5 * (hi - lo)
        return self._amplitude

    @property
    def scale(self) -> float:
        """The period (an autonomous orbit) or the largest amplitude (a forced one), at least 1:
        what the floors and CONDITIONED are relative to."""
        return max(1.0, self.T if self.lay.autonomous else float(np.max(np.abs(self.amplitude))))


def _match(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a_j - (the nearest b)| for each a_j."""
    if b.size == 0:
        return np.full(a.shape, np.inf)
    return np.min(np.abs(a[:, None] - b[None, :]), axis=1)


def extrapolated(x0: Any, x1: Any, x2: Any, most: float, bounded: bool = True,
                 fallback: float = 1.0) -> Any:
    """The error estimate of x2 from three levels of one quantity, the mesh halved from each to
    the next (Richardson's): d1 = x0 - x1 and d2 = x1 - x2 fall by 2^q; where they have one sign
    and the observed order q is in [LEAST_RICHARDSON, ``most``] while x0 is within ROUGH of x1
    (relative, at least 1), SAFETY |d2| / (2^q - 1), at most |d2|; elsewhere ``fallback`` |d2|
    (the two-level difference: the coarsest level is not yet in the asymptotic range).  ``most`` is
    the theory's order; ``bounded``: it bounds the order (the period's and the multipliers'
    superconvergent 2 m), so an order seen above it is no asymptotic range, as one below
    LEAST_RICHARDSON; not ``bounded`` (the amplitudes' m + 1, an extremum's generic order,
    exceeded where it falls near a mesh point): an order up to ``most`` + 1 is taken, capped at
    ``most``.  On equidistributed meshes the order seen between levels swings (6 to 9 for the
    period at degree 4): SAFETY covers a local order up to 3 below the one seen."""
    d1 = np.abs(np.asarray(x0) - np.asarray(x1))
    d2 = np.abs(np.asarray(x1) - np.asarray(x2))
    same = np.real(np.conj(np.asarray(x0) - np.asarray(x1)) * (np.asarray(x1) - np.asarray(x2))) > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.log2(d1 / d2)
    near = d1 <= ROUGH * np.maximum(1.0, np.abs(np.asarray(x1)))
    top = most if bounded else most + 1.0
    trusted = same & near & np.isfinite(q) & (q >= LEAST_RICHARDSON) & (q <= top)
    qq = np.minimum(np.where(trusted, q, 1.0), most)
    est = np.where(trusted, np.minimum(d2, SAFETY * d2 / (2.0 ** qq - 1.0)), fallback * d2)
    return est if np.ndim(est) else float(est)


def estimate(c: Solved | None, f: Solved, reached: float = 0.0,
             coarser: Solved | None = None) -> dict[str, Any]:
    """The finer's error estimate (each plus ``reached``, the accuracy of a coarse solve
    stopped at its rounding floor, in the units of x): the differences of the two levels, or
    with a third level (``coarser``, default ``c.coarser``: c's mesh with pairs merged) the
    period, amplitudes and multipliers (where the coarser has them) by :func:`extrapolated` (a
    multiplier's two-level difference, with or without a third level, TWO_LEVEL_SAFETY times);
    where f has its ``check`` (f's mesh halved, :func:`checked`), the period, amplitudes and u
    from it, and the multipliers where the check has them (or where there is no c; inf where
    neither has them): CHECK_SAFETY |f - check|.  ``u`` compares two levels at equal phase
    (:func:`gap`).  c may be None only where f has its check."""
    F = f.check
    if c is None and F is None:
        raise ValueError("estimate: a coarser level or a check is needed")
    errors: dict[str, Any] = {"multipliers": np.full(f.mu.shape, np.inf)}
    if c is not None:
        m = f.lay.m
        g = coarser if coarser is not None else c.coarser
        errors["multipliers"] = TWO_LEVEL_SAFETY * _match(f.mu, c.mu)
        if g is not None and f.mu.size and g.mu.size and c.mu.size:
            mc = c.mu[np.argmin(np.abs(f.mu[:, None] - c.mu[None, :]), axis=1)]
            mg = g.mu[np.argmin(np.abs(mc[:, None] - g.mu[None, :]), axis=1)]
            errors["multipliers"] = extrapolated(mg, mc, f.mu, 2 * m, fallback=TWO_LEVEL_SAFETY)
        if F is None:                       # the levels' period, amplitudes and u
            errors.update(period=abs(c.T - f.T), amplitude=np.abs(c.amplitude - f.amplitude),
                          u=gap(c, f))
            if g is not None:
                errors["period"] = extrapolated(g.T, c.T, f.T, 2 * m)
                errors["amplitude"] = extrapolated(g.amplitude, c.amplitude, f.amplitude,
                                                   m + 1, bounded=False)
    if F is not None:
        errors["period"] = CHECK_SAFETY * abs(f.T - F.T)
        errors["amplitude"] = CHECK_SAFETY * np.abs(f.amplitude - F.amplitude)
        errors["u"] = CHECK_SAFETY * gap(f, F)
        if F.mu.size and f.mu.size:
            errors["multipliers"] = CHECK_SAFETY * _match(f.mu, F.mu)
    for k in errors:
        errors[k] = errors[k] + reached
    return with_floor(errors, f.T, f.amplitude, f.mu,
                      float(np.max(np.abs(f.x[:f.lay.rows * f.lay.n]))), F is not None)


def gap(a: Solved, b: Solved) -> float:
    """max |u_a - u_b| at equal phase theta = t / T (40 phases an interval of b), an autonomous
    orbit's a after aligning its phase to b's (:func:`aligned`)."""
    theta = np.linspace(0.0, 1.0, 40 * b.lay.L, endpoint=False)
    fine = evaluate(b.lay, b.x, theta * b.T)
    shift = aligned(a, theta[::5], fine[::5]) if b.lay.autonomous else 0.0    # 8 an interval
    return float(np.max(np.abs(evaluate(a.lay, a.x, (theta + shift) * a.T) - fine)))


def aligned(c: Solved, theta: np.ndarray, target: np.ndarray, rounds: int = 8) -> float:
    """The phase shift s (a fraction of the period) that brings the orbit c closest to the
    values ``target`` at the phases ``theta`` (least squares: sum |u_c((theta + s) T) -
    target|^2 least, by Gauss-Newton from s = 0); 0 when the shift found does not lower the
    largest difference (an autonomous orbit's phase is free: two solutions of one orbit differ
    by a shift that is no error of its shape)."""
    slope = reference(c.lay, c.x)                          # d u_c / d theta
    diff = evaluate(c.lay, c.x, theta * c.T) - target
    start = float(np.max(np.abs(diff)))
    s = 0.0
    for _ in range(rounds):
        R = slope(np.mod(theta + s, 1.0))
        norm = float(np.sum(R * R))
        if norm == 0.0:
            break
        step = -float(np.sum(diff * R)) / norm
        s += step
        diff = evaluate(c.lay, c.x, (theta + s) * c.T) - target
        if abs(step) <= 1e-13:
            break
    return s if abs(s) < 0.25 and float(np.max(np.abs(diff))) < start else 0.0


def with_floor(errors: dict[str, Any], T: float, amplitude: np.ndarray, mu: np.ndarray,
               u: float, checked: bool = False) -> dict[str, Any]:
    """The errors, each at least its floor times its quantity's size (at least 1): FLOOR, or
    for the period, the amplitudes and u where they are ``checked`` (the finer level against
    its mesh halved), CHECKED_FLOOR."""
    floor = CHECKED_FLOOR if checked else FLOOR
    errors["period"] = max(errors["period"], floor * max(1.0, T))
    errors["amplitude"] = np.maximum(errors["amplitude"], floor * np.maximum(1.0, amplitude))
    errors["multipliers"] = np.maximum(errors["multipliers"], FLOOR * np.maximum(1.0,
                                                                                   np.abs(mu)))
    errors["u"] = max(errors["u"], floor * max(1.0, u))
    return errors


def one_level(lay: Layout, terms: Terms, start: tuple[Layout, np.ndarray], ref: Any,
              what: str = "collocation") -> Solved:
    """The orbit on ``lay`` from ``start`` (a solution on another layout)."""
    return Solved(lay, solve(lay, terms, transfer(*start, lay), ref, what=what)[0])


def merged_level(s: Solved, terms: Terms, ref: Any, what: str = "collocation"
                 ) -> Solved | None:
    """The orbit on s's mesh with every pair of intervals merged, from s's solution; None where
    that merges nothing or the solve fails (Newton, or a model's f not finite there)."""
    low = s.lay.with_fractions(merged(s.lay.fractions))
    if low.L == s.lay.L:
        return None
    try:
        return one_level(low, terms, (s.lay, s.x), ref, what)
    except (ShootingError, ValueError):
        return None


def two_levels(lay: Layout, terms: Terms, start: tuple[Layout, np.ndarray], ref: Any, what: str
               ) -> tuple[Solved, Solved]:
    """The orbit on ``lay`` (from ``start``, a solution on another layout) and on ``lay``
    halved (from the first's solution, or where Newton fails from there, from ``start``), the
    first with its ``coarser`` level: ``lay`` with pairs merged (:func:`merged_level`)."""
    c = one_level(lay, terms, start, ref, what)
    fine = lay.with_fractions(halved(lay.fractions))
    try:
        xf, _ = solve(fine, terms, transfer(lay, c.x, fine), ref, what=what)
    except ShootingError:                    # a coarse level far off (a steep orbit)
        xf, _ = solve(fine, terms, transfer(*start, fine), ref, what=what)
    c.coarser = merged_level(c, terms, ref, what)
    return c, Solved(fine, xf)


def checked(f: Solved, terms: Terms, ref: Any) -> Solved | None:
    """The orbit on f's mesh halved (2 N where f has N), solved from f's solution (its
    first factorisation usually serves every Newton step: f is its error away), so that |f -
    check| is f's error to a factor 1 +- (the check's error / f's); None where Newton fails
    there, its delay integral would need more than MAX_DELAY_NODES quadrature nodes or its
    solution breaks the signature's inequalities (:func:`~.system.check_inequalities`, as
    collocate checks the orbit it returns), with the reason in f's ``unchecked``."""
    fine = f.lay.with_fractions(halved(f.lay.fractions))
    if delay_nodes(terms, f.lay.m, fine.L, f.T) > MAX_DELAY_NODES:
        f.unchecked = (f"its delay integral would need more than MAX_DELAY_NODES = "
                       f"{MAX_DELAY_NODES:g} quadrature nodes")
        return None
    try:
        x = solve(fine, terms, transfer(f.lay, f.x, fine), ref)[0]
        broken = check_inequalities(fine, terms, x)
    except (ShootingError, ValueError) as err:   # Newton fails; a model's f not finite there
        f.unchecked = f"{type(err).__name__}: {err}"
        return None
    if broken:
        f.unchecked = ("its solution breaks the signature's inequalities ("
                       + "; ".join(broken[:2]) + ")")
        return None
    return Solved(fine, x)


def difference(a: Solved, b: Solved) -> float:
    """|a - b| in the period (an autonomous orbit) or the largest in the amplitudes (a forced
    one): what a refinement steers by."""
    return (abs(a.T - b.T) if a.lay.autonomous
            else float(np.max(np.abs(a.amplitude - b.amplitude))))


def level_error(c: Solved, f: Solved) -> tuple[float, float, float | None]:
    """The estimated error of f's period (an autonomous orbit) or largest amplitude error (a
    forced one): CHECK_SAFETY times its difference to f's ``check`` where f has one, else from
    the three levels; the two levels' difference of it, and the order its three levels show
    (None: two levels, or not steady)."""
    two = difference(c, f)
    d, seen = two, None
    g = c.coarser
    if g is not None:
        if f.lay.autonomous:
            x = (g.T, c.T, f.T)
            d = float(extrapolated(*x, 2 * f.lay.m))
        else:
            i = int(np.argmax(np.abs(c.amplitude - f.amplitude)))
            x = (g.amplitude[i], c.amplitude[i], f.amplitude[i])
            d = float(np.max(extrapolated(g.amplitude, c.amplitude, f.amplitude, f.lay.m + 1,
                                          bounded=False)))
        d1, d2 = abs(x[0] - x[1]), abs(x[1] - x[2])
        seen = math.log2(d1 / d2) if d < d2 and d2 > 0 else None
    if f.check is not None:
        d = CHECK_SAFETY * difference(f, f.check)
    return d, two, seen


def checked_round(c: Solved, f: Solved, terms: Terms, ref: Any, every: bool = False
                  ) -> tuple[float, float, float | None]:
    """:func:`level_error` of the levels (c, f) of a fixed mesh, f checked first
    (:func:`checked`) where its mesh is graded (``Layout.interval_ratio`` at least GRADED), its
    three levels are not steady or ``every`` mesh is to be checked."""
    d, two, seen = level_error(c, f)
    if seen is None or every or c.lay.interval_ratio() >= GRADED:
        f.check = checked(f, terms, ref)
        d = level_error(c, f)[0]
    return d, two, seen


def lower(f: Solved, terms: Terms, ref: Any) -> Solved | None:
    """The orbit on f's mesh with pairs merged with its own ``coarser``, that mesh merged again
    (:func:`merged_level`; None where that fails): the levels of f's multipliers' estimate, and
    of its period's where f's check could not be solved; None where the first merged solve fails
    or merges nothing."""
    c = merged_level(f, terms, ref)
    if c is not None:
        c.coarser = merged_level(c, terms, ref)
    return c


def round_error(c: Solved | None, f: Solved) -> float:
    """A refinement round's estimated error of f's period (an autonomous orbit) or largest
    amplitude error (a forced one): CHECK_SAFETY times its difference to f's ``check``, else
    the levels' (:func:`level_error`, c from :func:`lower`); inf where there are neither."""
    if f.check is not None:
        return CHECK_SAFETY * difference(f, f.check)
    return math.inf if c is None else level_error(c, f)[0]


def near_check(f: Solved) -> bool:
    """Whether f's check is within ROUGH (relative, at least 1) of f in the period (an
    autonomous orbit; a forced one's period is fixed): the round is in the asymptotic range,
    its estimate says the order to grow by.  False without a check."""
    F = f.check
    return F is not None and (not f.lay.autonomous
                              or abs(f.T - F.T) <= ROUGH * max(1.0, abs(F.T)))


def contributions(f: Solved, terms: Terms, ref: Any) -> np.ndarray | None:
    """(L,): each interval's share of f's check's period less f's (the dual-weighted residual:
    the check's orbit put into f's equations, weighted by the solution psi of J^T psi = e_T,
    J f's Jacobian; the shares sum to that difference to first order); None without a check,
    for a forced orbit (its period is fixed), where J is singular or the shares are not
    finite."""
    F = f.check
    if F is None or not f.lay.autonomous:
        return None
    lay = f.lay
    e = np.zeros(lay.size)
    e[-1] = 1.0                                     # T, the last unknown
    try:
        psi = factored(lay, terms, f.x, ref, "collocate", []).solve(e, trans="T")
        r = assemble(lay, terms, transfer(F.lay, F.x, lay), ref, jacobian=False)[0]
    except (ShootingError, ValueError):          # singular; the check's b out of f's order
        return None
    cells = lay.L * lay.m * lay.n
    eta = (psi[:cells] * r[:cells]).reshape(lay.L, -1).sum(axis=1)
    return eta if np.all(np.isfinite(eta)) else None


def hot_ends(lay: Layout, eta: np.ndarray) -> list[tuple[int, int, float]]:
    """The pieces' end intervals carrying at least HOT_SHARE of sum |eta| (their shares of the
    period's difference, :func:`contributions`): (piece, side (0 its start, 1 its end),
    eta there); none for an orbit without switches (no ends).  The ends are the switches and
    t = 0 and T; a piece of one interval is taken at its start (past a switch, where the
    memory's singular part acts)."""
    if lay.signature.switches == 0:
        return []
    total = float(np.sum(np.abs(eta)))
    first = np.cumsum([0] + [fr.size - 1 for fr in lay.fractions])   # each piece's first interval
    out = []
    for j in range(len(lay.fractions)):
        for side, i in ((0, first[j]), (1, first[j + 1] - 1)):
            if abs(eta[i]) >= HOT_SHARE * total and (side == 0 or i != first[j]):
                out.append((j, side, float(eta[i])))
    return out


def graded(fractions: list[np.ndarray], ends: dict[tuple[int, int], int]) -> list[np.ndarray]:
    """The fractions with the interval at each end in ``ends`` ((piece, side) -> k) cut k
    times towards that end, each cut halving what is left of the end interval."""
    out = [f.copy() for f in fractions]
    for (j, side), k in ends.items():
        f = out[j]
        if side == 0:
            cuts = f[1] * 0.5 ** np.arange(1, k + 1)
        else:
            cuts = 1.0 - (1.0 - f[-2]) * 0.5 ** np.arange(1, k + 1)
        out[j] = np.sort(np.concatenate([f, cuts]))
    return out


def regraded(lay: Layout, eta: np.ndarray, tol: float, ends: dict[tuple[int, int], int]
             ) -> float | None:
    """Where one of the pieces' end intervals carries at least HOT_SHARE of the round's
    difference to its check (its shares ``eta``, :func:`contributions`; :func:`hot_ends`), that
    end's grading in ``ends`` deepened by the levels that bring its share, CHECK_SAFETY |eta|, to
    tol / 4 at GRADE_ORDER (at least one); returns the estimate of the rest (CHECK_SAFETY times
    the sum of the other intervals' |eta|) where no hot end was graded before (a graded end hot
    again: the grading did not take its share away, the mesh grows as without), else None."""
    hot = hot_ends(lay, eta)
    if not hot:
        return None
    again = any((j, side) in ends for j, side, _ in hot)
    for j, side, v in hot:
        k = math.ceil(math.log2(max(CHECK_SAFETY * abs(v) / (0.25 * tol), 2.0)) / GRADE_ORDER)
        ends[(j, side)] = min(GRADE_MOST, ends.get((j, side), 0) + k)
    rest = float(np.sum(np.abs(eta))) - sum(abs(v) for _, _, v in hot)
    return None if again else CHECK_SAFETY * rest


def repaired(lay: Layout, eta: np.ndarray, tol: float, d: float, grow: int
             ) -> list[np.ndarray] | None:
    """The round's fractions with its hottest intervals halved (the fewest, by their shares
    ``eta`` of the difference to its check, :func:`contributions`) whose halving brings the
    estimate to tol / MARGIN, each halved interval's share taken to fall by 2^(m+1) (u's local
    order: the period's share falls at least so); None where that needs more than a
    REPAIR_PART-th of the intervals (at least 2: the error is spread), more intervals than
    ``grow`` (the next mesh it replaces), or where the shares say less than half the round's
    estimate d (CHECK_SAFETY |sum eta| < d / 2: the linearisation does not hold)."""
    if CHECK_SAFETY * abs(float(np.sum(eta))) < 0.5 * d:
        return None
    a = np.abs(eta)
    order = np.argsort(-a)
    left = CHECK_SAFETY * (a.sum() - np.cumsum(a[order]) * (1.0 - 2.0 ** -(lay.m + 1)))
    enough = np.flatnonzero(left <= tol / MARGIN)
    if (enough.size == 0 or enough[0] + 1 > max(2, lay.L // REPAIR_PART)
            or lay.L + enough[0] + 1 > grow):
        return None
    return halved(lay.fractions, order[:enough[0] + 1])


def reshaped(f: Solved, terms: Terms, ref: Any, d: float, tol: float, grow: int,
             ends: dict[tuple[int, int], int]) -> tuple[float | None, list[np.ndarray] | None]:
    """What a round's shares of the difference to its check (:func:`contributions`, where the
    round is near its check) make of the next mesh (``grow`` intervals without them): (the
    rest's estimate where a piece's end was graded (:func:`regraded`, ``ends`` deepened), the
    round's fractions with its hottest intervals halved (:func:`repaired`)), each else None.
    Not computed for an orbit without switches whose estimate d, fallen by 2^(m+1) in every
    interval, would still miss tol (no halving of a part of its intervals can meet it)."""
    if not near_check(f) or (f.lay.signature.switches == 0
                             and d * 2.0 ** -(f.lay.m + 1) > tol / MARGIN):
        return None, None
    eta = contributions(f, terms, ref)
    if eta is None:
        return None, None
    rest = regraded(f.lay, eta, tol, ends)
    return rest, (repaired(f.lay, eta, tol, d, grow) if rest is None else None)


def coarsened(f: Solved, d: float, tol: float, expected: int, ends: dict[tuple[int, int], int],
              terms: Terms, ref: Any, what: str) -> Solved | None:
    """The orbit on fewer intervals than f's round (its estimate d <= tol), where its estimate
    at the ``expected`` order says more than COARSER times fewer suffice (aimed at tol /
    MARGIN, as :func:`repaired` aims: (MARGIN d / tol)^(1/expected) times f's intervals, its
    graded ends' levels left out; at least :func:`least_intervals`): that mesh equidistributed
    from f's check F (``ends`` graded as f's were), checked (:func:`checked`), with f as its
    ``finer``; returned where it keeps the signature's inequalities, its estimate meets tol
    and its estimates of the period, the amplitudes and u (:func:`estimate`) cover their
    distances to F (:func:`covered`); None otherwise (not solved, not checked, not that
    accurate, or no fewer intervals: f stays)."""
    F = f.check
    base = f.lay.L - sum(ends.values())
    fewer = max(least_intervals(f.lay.m, len(f.lay.fractions)),
                math.ceil(base * (MARGIN * d / tol) ** (1.0 / expected)))
    if F is None or COARSER * fewer > base:
        return None
    lay = F.lay.with_fractions(graded(adapted(F.lay, F.x, fewer), ends))
    if lay.L >= f.lay.L:
        return None
    try:
        g = one_level(lay, terms, (F.lay, F.x), ref, what)
        if check_inequalities(g.lay, terms, g.x):
            return None
    except (ShootingError, ValueError):
        return None
    g.check, g.finer = checked(g, terms, ref), f
    return g if round_error(None, g) <= tol and covered(g) else None


def covered(g: Solved, multipliers: bool = False) -> bool:
    """Whether the estimates of g, a coarser try (:func:`coarsened`), as :func:`estimate`
    reports them (with their floors), cover g's distance to its ``finer`` round's check F (more
    than twice as fine as g: it stands for the truth; a try whose check is not yet in the
    asymptotic range fails this): the period's its distance plus the round's own distance to F
    (which bounds F's error where the round's estimate holds, an order of at least 1 from the
    round to F), every amplitude's and u's (phase-aligned, :func:`gap`) their distances, or
    with ``multipliers`` each multiplier's its distance to the nearest of F's.  F's own error is
    left out but in the period: the round's distance to F in u or an amplitude is the round's
    error, which the try, equidistributed from F, may have less of (van der Pol at eps = 5,
    degree 4, 1e-6: the round of 64 grown from a far round 1.5e-4 from F in u, the try on 50
    1.6e-5)."""
    f, F = g.finer, g.finer.check
    errors = estimate(None, g)
    if multipliers:
        return bool(np.all(_match(g.mu, F.mu) <= errors["multipliers"]))
    return bool(abs(g.T - F.T) + abs(f.T - F.T) <= errors["period"]
                and np.all(np.abs(g.amplitude - F.amplitude) <= errors["amplitude"])
                and gap(g, F) <= errors["u"])


def rounds_order(last: tuple[int, float] | None, L: int, d: float, scale: float, tol: float,
                 floor: float, capped: list[float] | None, reached: str, below: str
                 ) -> float | None:
    """The order the last two rounds' estimates show (the last round's (L, estimate) and this
    round's L and d; 1 with an undeclared jump of the kernel, ``capped``; None where unknown or
    too small a step or too early to tell); a ValueError where it says the estimate has stopped
    falling (below LEAST_ORDER over a growth of LEAST_GROWTH at least, below CONDITIONED
    relative to ``scale``) or that tol needs more than MAX_INTERVALS intervals (``below``, the
    floor's message, where tol is below ``floor``)."""
    q = 1.0 if capped else None
    if last is not None and last[1] > 0 and math.isfinite(d):
        q = math.log(last[1] / d) / math.log(L / last[0])
        if q < LEAST_ORDER and (L < LEAST_GROWTH * last[0] or d > CONDITIONED * scale):
            q = 1.0 if capped else None
        elif q < LEAST_ORDER:
            raise ValueError(f"collocate: the estimated error has stopped falling: it was "
                             f"{last[1]:.3g} at {last[0]} intervals and is {d:.3g}; "
                             f"{reached} (observed order {q:.2g}): tol = {tol!r} is below "
                             "what this orbit's collocation reaches (the floor of its "
                             f"conditioning); ask tol >= {min(last[1], d):.2g}, or a higher "
                             "degree")
    if q is not None and math.isfinite(d):
        need = L * (d / tol) ** (1.0 / q)
        if need > MAX_INTERVALS and tol < floor:
            raise ValueError(below)
        if need > MAX_INTERVALS:
            why, fix = (f"at the observed order {q:.2g}", "ask a larger tol, or a "
                        "higher degree")
            if capped:
                why = (f"with the kernel's jump at s = {capped[0]:.10g} not declared (the "
                       "order capped at 1)")
                fix = f"give kernel_jumps=({capped[0]:.10g},), or ask a larger tol"
            raise ValueError(f"collocate: {reached}; {why}, tol = {tol!r} needs about "
                             f"{need:.2g} intervals, more than MAX_INTERVALS = "
                             f"{MAX_INTERVALS}: {fix}")
    return q


def next_intervals(L: int, d: float, aim: float, expected: int, q: float | None, m: int
                   ) -> int:
    """The next round's intervals from this round's L and estimate d, to bring it to ``aim``:
    at the two rounds' order ``q`` where above m (at most ``expected`` + 2) with a margin of
    1.1, else at ``expected`` with MARGIN; at least L + 2, at most 8 L and MAX_INTERVALS."""
    grow = (d / aim) ** (1.0 / expected) * MARGIN
    if q is not None and q > m:
        grow = (d / aim) ** (1.0 / min(q, expected + 2)) * 1.1
    return min(MAX_INTERVALS, max(L + 2, math.ceil(L * min(grow, 8.0))))


def first_intervals(tol: float, m: int, pieces: int, steep: bool) -> int:
    """The first round's intervals: FIRST_INTERVALS at tol <= FIRST_TOL or for a ``steep``
    orbit (its first solve needed more than its first mesh); for a looser tol fewer, as the
    period's error falls (h^(2 m): L^(2 m) tol kept; a forced orbit's amplitudes, h^(m+1), would
    allow fewer still); above FIRST_DEGREE fewer, the period's error taken as (A / L)^(2 m) with
    the A of FIRST_INTERVALS at FIRST_TOL and degree FIRST_DEGREE (7.4 at degree 6 and 1e-8:
    7 intervals, 12 returned for van der Pol); at least :func:`least_intervals` (of the
    signature's ``pieces``)."""
    higher = min(1.0, FIRST_TOL ** (1.0 / (2 * FIRST_DEGREE) - 1.0 / (2 * m)))
    L = FIRST_INTERVALS * min(1.0, (FIRST_TOL / tol) ** (1.0 / (2 * m)) * higher)
    return max(least_intervals(m, pieces), FIRST_INTERVALS if steep else 0, round(L))


def least_intervals(m: int, pieces: int) -> int:
    """The fewest intervals a refinement solves on: LEAST_POINTS / m (rounded, within 4 to
    LEAST_FIRST: 6 at degree 4, 8 at degree 3), at least 4 for each of the signature's
    ``pieces``."""
    return max(4, min(LEAST_FIRST, round(LEAST_POINTS / m)), 4 * pieces)


def levels(lay: Layout, terms: Terms, x: np.ndarray, ref: Any, L: int, fixed: bool,
           tol: float, what: str, capped: list[float] | None = None, every: bool = False
           ) -> tuple[Solved | None, Solved]:
    """The orbit on L intervals equidistributed (``fixed``: :func:`fixed_levels`) or refined
    until its checked estimate is below tol (:func:`refined`): (coarser, finer), the finer the
    orbit returned."""
    if fixed:
        return fixed_levels(lay, terms, x, ref, L, what, every)
    return refined(lay, terms, x, ref, L, tol, what, capped)


def fixed_levels(lay: Layout, terms: Terms, x: np.ndarray, ref: Any, L: int, what: str,
                 every: bool = False) -> tuple[Solved, Solved]:
    """The orbit on L intervals equidistributed and on that mesh halved: (coarser, finer), the
    coarser with its own ``coarser`` (its mesh merged; None where that solve failed), the finer
    with its ``check`` (its mesh halved, :func:`checked`) where the mesh is graded
    (``Layout.interval_ratio`` at least GRADED: a steep orbit), the three levels are not steady
    (no Richardson estimate) or ``every`` mesh is to be checked (a check that cannot be solved
    leaves the levels' estimate and its reason in the finer's ``unchecked``)."""
    c, f = two_levels(lay.with_fractions(adapted(lay, x, L)), terms, (lay, x), ref, what)
    checked_round(c, f, terms, ref, every)
    return c, f


def refined(lay: Layout, terms: Terms, x: np.ndarray, ref: Any, L: int, tol: float,
            what: str, capped: list[float] | None = None) -> tuple[Solved | None, Solved]:
    """The refinement: from L intervals, rounds of the orbit on a mesh equidistributed from the
    last round's check (:func:`adapted`) and on that mesh halved (:func:`checked`), until the
    check's estimate of the first meets tol (:func:`round_error`): (None, f), f the orbit
    returned with its ``check``; where f's check cannot be solved, the estimate is the levels'
    (f's mesh merged once and twice, :func:`lower`; returned as the coarser, with the reason in
    f's ``unchecked``).  The next mesh grows by the order the two last rounds' estimates show
    (above m, at most the theory's + 2), else by the theory's (the period's h^(2m), an
    extremum's h^(m+1); 1 with an undeclared jump of the kernel, ``capped``), with MARGIN more,
    by at most 8 times, and by at most FAR_GROWTH after a round whose check is more than ROUGH
    off it in the period (or was not solved) while no round was nearer, or that has no
    estimate (its check and merged level not solved): such a round says nothing of the order,
    and its estimate is left out of the rounds' order.  A round of an autonomous orbit with
    switches whose end interval of a piece carries most of the difference to its check
    (:func:`regraded`) has that end graded in every later round, and the next mesh grows for
    the other intervals' shares only; where halving a few of a round's intervals predicts tol
    (:func:`repaired`), the next round is that mesh (the rounds' order starts anew after
    either).  A last round that meets tol on more than COARSER times the intervals its estimate
    says suffice is followed by a try on that fewer (:func:`coarsened`; not where its estimate
    is at the floor of rounding), returned where it keeps the signature's inequalities, its
    check meets tol and its estimates cover their distances to the round's check (the period's
    plus the round's own distance to it; the multipliers' are covered where they are computed,
    :func:`~.collocate.kept_coarser`).

    A first round on fewer than FIRST_INTERVALS intervals (a loose tol or a high degree) whose
    solve fails, or whose check and merged level both fail (no estimate), is done again on
    twice its intervals, at most FIRST_INTERVALS (not counted as a round of MAX_ROUNDS).

    The refinement stops with a ValueError that names the estimate reached and its mesh when
    the estimate is at the floor of rounding (CHECKED_FLOOR times the period or the
    amplitudes, at least 1; FLOOR for the levels' estimate) or meets a tol below that floor,
    when it has stopped falling (an observed order below LEAST_ORDER over a growth of
    LEAST_GROWTH at least, below CONDITIONED), when the observed order (1 with an undeclared
    jump of the kernel, ``capped``) says tol needs more than MAX_INTERVALS intervals, when the
    next mesh's check would need more than MAX_DELAY_NODES quadrature nodes, or after
    MAX_ROUNDS rounds."""
    last = None                                    # the last round's (L, estimate)
    autonomous = lay.autonomous
    name = "period" if autonomous else "amplitudes"
    # the expected order: the period's h^(2m) (superconvergent), an extremum's h^(m+1)
    expected = 2 * lay.m if autonomous else lay.m + 1
    rounds = 0
    ends: dict[tuple[int, int], int] = {}         # the graded ends of pieces: levels
    repair = None
    while rounds < MAX_ROUNDS:
        new = (lay.with_fractions(repair) if repair is not None else
               lay.with_fractions(graded(adapted(lay, x, L), ends)))
        try:
            f = one_level(new, terms, (lay, x), ref, what)
        except ShootingError:
            if rounds > 0 or L >= FIRST_INTERVALS:
                raise
            L = min(2 * L, FIRST_INTERVALS)        # a loose tol's first mesh too coarse: not
            continue                               # a round
        f.check = checked(f, terms, ref)
        c = lower(f, terms, ref) if f.check is None else None
        d = round_error(c, f)
        if rounds == 0 and not math.isfinite(d) and L < FIRST_INTERVALS:
            L = min(2 * L, FIRST_INTERVALS)        # no estimate on a first mesh that coarse:
            continue                               # not a round either
        rounds += 1
        which = (("CHECKED_FLOOR", CHECKED_FLOOR) if f.check is not None else
                 ("FLOOR", FLOOR))                 # the levels' floor where the check failed
        floor = which[1] * f.scale
        if d <= tol and floor <= tol:
            g = (coarsened(f, d, tol, expected, ends, terms, ref, what) if d > floor
                 else None)                        # an estimate at the floor: no order in it
            return c, g or f
        reached = (f"the estimated error of the {name} is {d:.3g} at {f.lay.L} intervals of "
                   f"degree {lay.m}")
        if f.check is None:
            reached += f" (the levels' estimate: its check not solved, {f.unchecked})"
        below = (f"collocate: tol = {tol!r} is below the floor of double precision, {floor:.3g} "
                 f"({which[0]} = {which[1]:g} times the {name}, at least 1), where a finer mesh "
                 f"no longer lowers the estimate: {reached}; ask tol >= {floor:.2g}")
        if d <= floor or d <= tol:                 # an estimate at the floor, above tol
            raise ValueError(below)
        q = rounds_order(last, L, d, f.scale, tol, floor, capped, reached, below)
        L2 = next_intervals(L, d, tol, expected, q, lay.m)
        rest, repair = reshaped(f, terms, ref, d, tol, L2, ends)
        if rest is not None:                       # an end graded: the rest's growth, and the
            L2 = next_intervals(L, rest, tol, expected, None, lay.m)
            last = None                            # rounds' order starts anew
        elif not math.isfinite(d) or last is None and not near_check(f):
            L2 = min(L2, FAR_GROWTH * L)           # far off: the round says nothing of the order
        else:
            last = (L, d)
        start = f.check if f.check is not None and repair is None else f
        if repair is not None:                     # the same mesh, its hottest intervals
            L2, last = sum(len(r) - 1 for r in repair), None           # halved
        lay, x, L = start.lay, start.x, L2
        if f.lay.L >= MAX_INTERVALS:
            break
        check_cost(terms, lay.m, 2 * (L + (0 if repair else sum(ends.values()))), f.T,
                   f"the next mesh's check ({reached})", "ask a larger tol, or a higher degree")
    raise ValueError(f"collocate: the estimated error {d:.3g} is still above tol = {tol!r} at "
                     f"{f.lay.L} intervals (MAX_INTERVALS = {MAX_INTERVALS}, MAX_ROUNDS = "
                     f"{MAX_ROUNDS}): ask a larger tol or a higher degree")


def delay_nodes(terms: Terms, m: int, L: int, T: float) -> float:
    """About how many quadrature nodes the delay integral on a mesh of L intervals of one
    period T needs (0 without a kernel): L m collocation times, each with about L (tau / T +
    1) pieces of m + 1 nodes."""
    if not terms.has_kernel:
        return 0.0
    return L * m * (L * (terms.tau / T + 1.0) + 2 + len(terms.H.jumps)) * (m + 1)


def check_cost(terms: Terms, m: int, L: int, T: float, where: str, fix: str) -> None:
    """ValueError when the delay integral on a mesh of L intervals of one period T needs more
    than MAX_DELAY_NODES quadrature nodes (:func:`delay_nodes`); the message says where and
    ``fix``."""
    nodes = delay_nodes(terms, m, L, T)
    if nodes > MAX_DELAY_NODES:
        raise ValueError(f"collocate: the delay integral on {where} would need about "
                         f"{nodes:.3g} quadrature nodes (L = {L} intervals; the memory tau = "
                         f"{terms.tau!r} spans {terms.tau / T:.3g} periods T = {T!r}), more "
                         f"than MAX_DELAY_NODES = {MAX_DELAY_NODES:g} (about 100 bytes each): "
                         f"{fix}")
