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

Errors: the orbit is solved on a mesh and on the same mesh with every interval halved; the
difference of their period, amplitudes, multipliers and u is the error estimate of the finer one
(which is returned): an upper estimate while the convergence is in its asymptotic range (the
finer one's error is that difference over 2^p - 1, p >= m the order).  With ``intervals=None``
the mesh is equidistributed (AUTO, COLSYS: equal integrals of |u^(m+1)|^(1 / (m + 1)),
estimated from the jumps of u^(m) between intervals) and refined until the estimate of the
period (an autonomous orbit; it converges as h^(2m) on smooth orbits) or of the amplitudes (a
forced orbit; h^(m+1): an extremum is inside an interval) is below ``tol``.

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

from .floquet import multipliers as floquet
from .mesh import delay_matrix, equidistribute, periodic_locator
from .signature import read_signature, violations
from .system import (CollocationWarning, Layout, Terms, carried, evaluate,
                                 interval_counts, misdeclared_jumps, node_times, solve,
                                 undeclared_jumps, uniform_fractions)
from .mend import mend
from .orbit import EquationOrbit
from ..core.newton import ShootingError
from ..scheme.orbit import Orbit
from ..scheme.stepmap import build

#: Points a mesh interval of the grid on which the inequalities are checked.
CHECK_POINTS = 8
#: Mesh refinement rounds at most (intervals=None).
MAX_ROUNDS = 6
#: Signature mends at most (a segment split or removed where an inequality breaks).
MENDS = 4
#: Intervals at most.
MAX_INTERVALS = 4000
#: The errors' floor, relative to their quantities (Newton's 1e-12 and the conditioning).
FLOOR = 1e-11
#: The least observed order of the refinement's estimate (log of its fall over log of the mesh's
#: growth): below it the estimate has stopped falling.
LEAST_ORDER = 0.5
#: Quadrature nodes of the delay integral at most on one mesh (about 100 bytes each): a memory
#: spanning many periods (tau / T large) or a very fine mesh is refused before it is built.
MAX_DELAY_NODES = 2e7
#: A forced model's rhs f(t + T, u) against f(t, u) at these many points of the orbit.
FORCING_POINTS = 16


def halved(fractions: list[np.ndarray]) -> list[np.ndarray]:
    """Every interval cut in two."""
    out = []
    for f in fractions:
        mid = 0.5 * (f[:-1] + f[1:])
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


def extrema(lay: Layout, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(max (n,), min (n,)) of each component on the piecewise polynomial: the derivative's
    roots in the intervals next to the largest and smallest nodes."""
    m, n = lay.m, lay.n
    V = lay.split(x)[0]
    k = np.arange(m + 1)
    y = 2 * lay.basis.nodes - 1
    hi, lo = V.max(axis=0).copy(), V.min(axis=0).copy()
    for i in range(n):
        for sign, best in ((1.0, hi), (-1.0, lo)):
            node = int(np.argmax(sign * V[:, i]))
            iv = node // m
            for j in {(iv - 1) % lay.L, iv, (iv + 1) % lay.L}:
                vals = V[(j * m + k) % lay.rows, i]
                c = np.polynomial.polynomial.polyfit(y, vals, m)
                r = np.polynomial.polynomial.polyroots(np.polynomial.polynomial.polyder(c))
                r = r.real[(np.abs(r.imag) < 1e-9) & (np.abs(r.real) <= 1)]
                if r.size:
                    v = np.polynomial.polynomial.polyval(r, c)
                    best[i] = max(best[i], v.max()) if sign > 0 else min(best[i], v.min())
    return hi, lo


def check_inequalities(lay: Layout, terms: Terms, x: np.ndarray, tol: float) -> list[str]:
    """The inequalities the result breaks on a fine grid (CHECK_POINTS a mesh interval)."""
    if lay.signature.switches == 0 and not (np.any(terms.alpha > 0)
                                            or np.any(np.isfinite(terms.lo))
                                            or np.any(np.isfinite(terms.hi))):
        return []
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    e = lay.bounds(b, T)
    grid, us, forces = [], [], []
    loc = periodic_locator(mesh, lay.m)
    for j in range(len(e) - 1):
        count = (len(lay.fractions[j]) - 1) * CHECK_POINTS + 1
        t = np.linspace(e[j], e[j + 1], count)
        u = evaluate(lay, x, t)
        F = -terms.f(t, u)
        if terms.has_kernel:
            G = delay_matrix(t, terms.tau, mesh, T, terms.H, loc, lay.basis, lay.n, lay.rows,
                             pattern=terms.pattern)[0]
            F = F - (G @ V.ravel()).reshape(-1, lay.n)
        grid.append(t)
        us.append(u)
        forces.append(F)
    return violations(lay.piece_modes(b, T), grid, us, forces, terms.alpha, terms.lo, terms.hi,
                      tol)


def _match(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a_j - (the nearest b)| for each a_j."""
    if b.size == 0:
        return np.full(a.shape, np.inf)
    return np.min(np.abs(a[:, None] - b[None, :]), axis=1)


class Solved:
    """A solution on one layout, with its derived quantities."""

    def __init__(self, lay: Layout, terms: Terms, x: np.ndarray, count: int):
        self.lay, self.x = lay, x
        _, self.b, self.T = lay.split(x)
        hi, lo = extrema(lay, x)
        self.amplitude = 0.5 * (hi - lo)
        self.mu = floquet(lay, terms, x, count) if count > 0 else np.empty(0, complex)


def _refine(lay: Layout, terms: Terms, x: np.ndarray, ref: Any, count: int, what: str
            ) -> tuple[Solved, Solved]:
    """The orbit on ``lay`` (from x on another layout) and on ``lay`` halved."""
    xc, _ = solve(lay, terms, x, ref, what=what)
    fine = lay.with_fractions(halved(lay.fractions))
    xf, _ = solve(fine, terms, transfer(lay, xc, fine), ref, what=what)
    return Solved(lay, terms, xc, 0), Solved(fine, terms, xf, 0)


def _errors(c: Solved, f: Solved, reached: float = 0.0) -> dict[str, Any]:
    """The differences of the two levels: the finer's error estimate (each plus ``reached``,
    the accuracy of a coarse solve stopped at its rounding floor, in the units of x)."""
    t = np.linspace(0.0, f.T, 40 * f.lay.L, endpoint=False)
    du = float(np.max(np.abs(evaluate(c.lay, c.x, t * c.T / f.T) - evaluate(f.lay, f.x, t))))
    return with_floor({"period": abs(c.T - f.T) + reached,
                       "amplitude": np.abs(c.amplitude - f.amplitude) + reached,
                       "multipliers": _match(f.mu, c.mu) + reached, "u": du + reached},
                      f.T, f.amplitude, f.mu, float(np.max(np.abs(f.x[:f.lay.rows * f.lay.n]))))


def with_floor(errors: dict[str, Any], T: float, amplitude: np.ndarray, mu: np.ndarray,
               u: float) -> dict[str, Any]:
    """The errors, each at least FLOOR times its quantity's size (at least 1): Newton stops at
    a correction of 1e-12 relative, and the conditioning adds a few digits."""
    errors["period"] = max(errors["period"], FLOOR * max(1.0, T))
    errors["amplitude"] = np.maximum(errors["amplitude"], FLOOR * np.maximum(1.0, amplitude))
    errors["multipliers"] = np.maximum(errors["multipliers"], FLOOR * np.maximum(1.0,
                                                                                   np.abs(mu)))
    errors["u"] = max(errors["u"], FLOOR * max(1.0, u))
    return errors


def _stable(mu: np.ndarray, err: np.ndarray, autonomous: bool, p: float) -> bool | None:
    """All |mu| < 1 but the trivial one (autonomous), verified against the errors; None (with a
    CollocationWarning naming p) when a multiplier's |mu| is within its error of 1."""
    if mu.size == 0:
        return None
    keep = np.ones(mu.size, bool)
    if autonomous:
        keep[int(np.argmin(np.abs(mu - 1)))] = False
    a, e = np.abs(mu[keep]), err[keep]
    if np.any(a > 1 + e):
        return False
    if np.all(a < 1 - e):
        return True
    warnings.warn(f"p = {p!r}: a multiplier's modulus is within its estimated error of 1 "
                  f"({a[np.argmin(np.abs(a - 1))]:.12g}): stability not verified (None)",
                  CollocationWarning, stacklevel=3)
    return None


def collocate(orbit: Orbit, *, degree: int = 4, intervals: int | None = None,
              tol: float = 1e-10, multipliers: int = 10,
              kernel_jumps: tuple[float, ...] = ()) -> EquationOrbit:
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
        autonomous orbit) or of the amplitudes (a forced one) is below ``tol``; the other
        estimates are in ``errors``.
    tol : float
        The error asked (time and state units), > 0.
    multipliers : int
        Leading Floquet multipliers (0: none; ``stable`` is then None).
    kernel_jumps : sequence of float
        The lags in (0, tau) where the kernel jumps: the delay integral's pieces are cut there,
        so the order holds (the orbit keeps them for its continuation).  A jump not given caps
        the order at 1: a callback kernel is sampled and a jump found is warned of
        (CollocationWarning, naming its lag); a lag given where it does not jump is refused.

    Returns
    -------
    EquationOrbit
        The orbit with its period, amplitude, multipliers, stability, mesh, signature and
        estimated errors (those of the returned, finer level).

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
        ``intervals=None``, the estimate at its floor (FLOOR) above ``tol``, stopped falling,
        or needing more than MAX_INTERVALS intervals or MAX_ROUNDS rounds (the message names
        the estimate reached and its mesh).
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
    L = int(intervals) if intervals is not None else max(16, 4 * (bounds.size - 1))
    L0 = max(8, 2 * (bounds.size - 1), L // 2)        # a first solve: the indicator, the phase
    check_cost(terms, m, L0, T0, "the first mesh", "check orbit.period (a period far shorter "
               "than the memory is no orbit of the scheme)")
    lay = lay.with_fractions(uniform_fractions(bounds, L0))
    t_s = np.asarray(orbit.t, dtype=float)

    def scheme(t: np.ndarray) -> np.ndarray:
        tt = np.mod(t, T0)
        return np.column_stack([np.interp(tt, t_s, orbit.u[:, i]) for i in range(terms.n)])
    x0 = np.concatenate([scheme(node_times(lay, b0, T0)).ravel(), b0,
                         [T0] if orbit.autonomous else []])
    ref0 = _reference(lay, x0) if orbit.autonomous else None
    what = f"collocation of the orbit at p = {orbit.p!r}"
    try:
        x1, _ = solve(lay, terms, x0, ref0, what=what)
    except ShootingError as err:
        raise ShootingError(f"{err} -- {too_far(orbit)}", err.residuals) from None
    if orbit.autonomous:
        fell_to_equilibrium(lay, x1, orbit)
    ref = _reference(lay, x1) if orbit.autonomous else None
    count = int(multipliers)
    for attempt in range(MENDS + 1):
        c, f = _levels(lay, terms, x1, ref, L, intervals is not None, tol, count, what, capped)
        if orbit.autonomous:
            fell_to_equilibrium(f.lay, f.x, orbit)
        bad = check_inequalities(f.lay, terms, f.x, 1e-9 * max(1.0, float(np.max(np.abs(f.x)))))
        if not bad:
            return _result(orbit, terms, c, f, count)
        mended = mend(f.lay, terms, f.x) if attempt < MENDS else None
        if mended is None:
            break
        lay, x1 = mended                      # a segment split or removed: solve again
        x1, _ = solve(lay, terms, x1, ref, what=what)
    raise ValueError("collocate: the collocated orbit breaks its signature's inequalities "
                     f"({'; '.join(bad[:4])}) after {attempt} mends of the signature read from "
                     f"the scheme ({', '.join(f.lay.signature.describe())}); refine the scheme's "
                     "orbit (a smaller h) and collocate again")


def _levels(lay: Layout, terms: Terms, x: np.ndarray, ref: Any, L: int, fixed: bool,
            tol: float, count: int, what: str, capped: list[float] | None = None
            ) -> tuple[Solved, Solved]:
    """The orbit on L intervals equidistributed (``fixed``) or refined until the estimate is
    below tol, and on that mesh halved: (coarser, finer).

    The refinement stops with a ValueError that names the estimate reached and its mesh when
    the estimate is at its floor (FLOOR times the period or the amplitudes, at least 1), when
    it has stopped falling (an observed order below LEAST_ORDER), when the observed order (1
    with an undeclared jump of the kernel, ``capped``) says tol needs more than MAX_INTERVALS
    intervals, when the next mesh's delay integral would exceed MAX_DELAY_NODES, or after
    MAX_ROUNDS rounds."""
    last = None
    autonomous = lay.autonomous
    name = "period" if autonomous else "amplitudes"
    for _ in range(MAX_ROUNDS):
        lay2 = lay.with_fractions(adapted(lay, x, L))
        c, f = _refine(lay2, terms, transfer(lay, x, lay2), ref, count, what)
        if fixed:
            return c, f
        d = (abs(c.T - f.T) if autonomous
             else float(np.max(np.abs(c.amplitude - f.amplitude))))
        if d <= tol:
            return c, f
        size = f.T if autonomous else float(np.max(np.abs(f.amplitude)))
        floor = FLOOR * max(1.0, size)
        reached = (f"the estimated error of the {name} is {d:.3g} at {f.lay.L} intervals of "
                   f"degree {lay.m}")
        below = (f"collocate: tol = {tol!r} is below the floor of double precision, "
                 f"{floor:.3g} (FLOOR = {FLOOR:g} times the {name}, at least 1), where a finer "
                 f"mesh no longer lowers the estimate: {reached}; ask tol >= {floor:.2g}")
        if d <= floor:
            raise ValueError(below)
        # the expected order: the period's h^(2m) (superconvergent), an extremum's h^(m+1)
        expected = 2 * lay.m if autonomous else lay.m + 1
        q = 1.0 if capped else None
        if last is not None and last[1] > 0:                       # the observed order
            q = math.log(last[1] / d) / math.log(L / last[0])
            if q < LEAST_ORDER:
                raise ValueError(f"collocate: the estimated error has stopped falling: it was "
                                 f"{last[1]:.3g} at {2 * last[0]} intervals, {reached} "
                                 f"(observed order {q:.2g}): tol = {tol!r} is below what this "
                                 "orbit's collocation reaches (the floor of its conditioning); "
                                 f"ask tol >= {last[1]:.2g}, or a higher degree")
        if q is not None:
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
        grow = (d / tol) ** (1.0 / expected) * 1.2
        if q is not None and q > lay.m:
            grow = (d / tol) ** (1.0 / q) * 1.1
        last = (L, d)
        L = min(MAX_INTERVALS, max(L + 2, math.ceil(L * min(grow, 8.0))))
        lay, x = f.lay, f.x
        if f.lay.L >= MAX_INTERVALS:
            break
        check_cost(terms, lay.m, 2 * L, f.T, f"the next mesh ({reached})",
                   "ask a larger tol, or a higher degree")
    raise ValueError(f"collocate: the estimated error {d:.3g} is still above tol = {tol!r} at "
                     f"{f.lay.L} intervals (MAX_INTERVALS = {MAX_INTERVALS}, MAX_ROUNDS = "
                     f"{MAX_ROUNDS}): ask a larger tol or a higher degree")


def _reference(lay: Layout, x: np.ndarray) -> Any:
    """theta -> r'(theta) (P, n): the derivative in theta = t / T of the orbit x (the phase
    condition's reference), by its polynomial."""
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T) / T
    loc = periodic_locator(mesh, lay.m)
    basis = lay.basis

    def r(theta: np.ndarray) -> np.ndarray:
        i, z, cols = loc(np.asarray(theta, dtype=float))
        B = basis.derivatives(z) / np.diff(mesh)[i][:, None]
        return np.einsum("pk,pkn->pn", B, V[cols])
    return r


def _result(orbit: Orbit, terms: Terms, c: Solved, f: Solved, count: int) -> EquationOrbit:
    """The EquationOrbit of the finer level f, with its multipliers and the coarser's."""
    if count > 0:
        c.mu = floquet(c.lay, terms, c.x, count)
        f.mu = floquet(f.lay, terms, f.x, count)
    return equation_orbit(f, float(orbit.p), orbit.make, _errors(c, f), terms.H.jumps)


def check_jumps(terms: Terms, what: str) -> list[float]:
    """A callback kernel's jumps against ``kernel_jumps``, before any mesh is solved (a bounded
    number of kernel calls: :func:`undeclared_jumps`, :func:`misdeclared_jumps`): a declared
    lag where H does not jump raises a ValueError naming it and the jumps found; a jump found
    and not declared is warned of (CollocationWarning naming its lag).  Returns those."""
    found = undeclared_jumps(terms)
    wrong = misdeclared_jumps(terms)
    if wrong:
        said = "; ".join(f"H does not jump at s = {j!r}" if at is None
                         else f"H's jump near s = {j!r} is at s = {at:.15g}" for j, at in wrong)
        elsewhere = (f"; H jumps at s = {', '.join(f'{j:.15g}' for j in found)}, not declared"
                     if found else "")
        right = sorted(set(j for j in terms.H.jumps if all(j != w for w, _ in wrong))
                       | set(found) | set(at for _, at in wrong if at is not None))
        fix = (f"give kernel_jumps=({', '.join(f'{j:.15g}' for j in right)},)" if right
               else "give kernel_jumps=() (H has no jump found inside (0, tau))")
        raise ValueError(f"{what}: kernel_jumps = {terms.H.jumps!r} is wrong: {said}"
                         f"{elsewhere} (checked by bisection of H on (0, tau)): {fix}, the "
                         "lags where H itself jumps (a kink is not a jump)")
    for j in found:
        warnings.warn(f"{what}: the kernel jumps near the lag s = {j:.10g}, not declared: the "
                      "order of the collocation is capped at 1 there; give the jump "
                      f"(kernel_jumps=({j:.10g},) with its exact lag)", CollocationWarning,
                      stacklevel=3)
    return found


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


def check_cost(terms: Terms, m: int, L: int, T: float, where: str, fix: str) -> None:
    """ValueError when the delay integral on a mesh of L intervals of one period T needs more
    than MAX_DELAY_NODES quadrature nodes: L m collocation times, each with about L (tau / T
    + 1) pieces of m + 1 nodes; the message says where and ``fix``."""
    if not terms.has_kernel:
        return
    nodes = L * m * (L * (terms.tau / T + 1.0) + 2 + len(terms.H.jumps)) * (m + 1)
    if nodes > MAX_DELAY_NODES:
        raise ValueError(f"collocate: the delay integral on {where} would need about "
                         f"{nodes:.3g} quadrature nodes (L = {L} intervals; the memory tau = "
                         f"{terms.tau!r} spans {terms.tau / T:.3g} periods T = {T!r}), more "
                         f"than MAX_DELAY_NODES = {MAX_DELAY_NODES:g} (about 100 bytes each): "
                         f"{fix}")


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


def equation_orbit(f: Solved, p: float, make: Any, errors: dict[str, Any],
                   kernel_jumps: tuple[float, ...] = ()) -> EquationOrbit:
    """The EquationOrbit of a solution (its stability verified against ``errors``)."""
    V, b, T = f.lay.split(f.x)
    return EquationOrbit(p=p, period=T, amplitude=f.amplitude, multipliers=f.mu,
                         stable=_stable(f.mu, errors.get("multipliers", np.full(f.mu.shape,
                                                                                np.inf)),
                                        f.lay.autonomous, p),
                         mesh=f.lay.mesh(b, T), signature=f.lay.signature, switches=b.copy(),
                         make=make, autonomous=f.lay.autonomous, errors=errors,
                         degree=f.lay.m, nodes=V.copy(),
                         fractions=[fr.copy() for fr in f.lay.fractions], carried=f.lay.carried,
                         kernel_jumps=tuple(kernel_jumps))


__all__ = ["collocate", "CollocationWarning"]
