# Continuation of the equation's periodic orbits (collocation) by the one continuation driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Branches of :class:`EquationOrbit`: :func:`continue_equation_orbit` (what
:func:`dmi.analysis.continue_orbit` does with an EquationOrbit) and :func:`equation_branch_start`
(``hopf_orbit(..., of="equation")``).

:class:`EquationBranch` hands the collocation system
(:class:`dmi.analysis.CollocationDiscretisation`) to :func:`dmi.analysis.driver.continuation`:
the residual and its sparse Jacobian (the driver's tangent predictor and Newton corrector with
SuperLU; a residual that raises ``Degenerate``, a segment's length gone to 0, is a failed
step: the driver halves it), the points (the EquationOrbit with its period, amplitude,
multipliers and signature; on a vertical branch, where the orbit is not isolated at fixed p,
without the merged mesh's error estimate and with ``stable`` None), the events of the
multipliers (``period-doubling``, ``torus``; the fold is the driver's) and of the signature
(``stick-onset`` where a stuck or face segment appears or goes, ``grazing`` where the segments
change otherwise).  The signature changes by itself: a corrected point whose orbit breaks an
inequality of its signature is mended (a segment split around the breach, a vanishing one
removed: :func:`dmi.analysis.collocation_mend.mend`) and corrected again at its p (where that
is singular, at the corner of a vertical branch, with p free and the new segment's length
held), up to four times; the mended point is the step's (the corrector returns it on its new
unknowns), the mesh is equidistributed after every step (``adapt``), and the driver restarts
its tangent on the new unknowns (oriented by :meth:`EquationBranch.carry`; a vertical start by
:meth:`EquationBranch.orient`, the amplitude growing).  A branch that fails at the smallest
step says so in its status: the corner (grazing: the component and how near its velocity came
to 0), which way p went there, and what is known of the branch on the other side.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .branch import Branch, Event
from .collocation import CollocationWarning, check_inequalities
from .collocation_continuation import CollocationDiscretisation, equation_hopf_orbit
from .collocation_mend import mend
from .collocation_signature import HI, LO, SLIP_NEG, SLIP_POS, STUCK
from .collocation_system import solve
from .driver import Curve, bordered_solve, continuation, newton_corrector
from .equation_orbit import EquationOrbit
from .newton import ShootingError

#: Mends (split or removal, then a correction at fixed p) tried on one point at most.
MENDS = 4


def _stuck_like(orbit: EquationOrbit) -> np.ndarray:
    """Shape (n,): which components are held (stuck, or on a face) on some segment."""
    modes = np.asarray(orbit.signature.modes)
    return np.any((modes == STUCK) | (modes == LO) | (modes == HI), axis=0)


class EquationBranch(CollocationDiscretisation):
    """The collocation discretisation of a branch for :func:`dmi.analysis.driver.continuation`
    (see the module): :class:`CollocationDiscretisation` (its residual and Jacobian) with the
    driver's corrector, mends, points, events and corners.

    Parameters
    ----------
    make, layout, x, multipliers, estimate
        As :class:`CollocationDiscretisation`'s.
    tol : float
        The corrector's tolerance.
    max_iter : int
        The corrector's iterations a step.
    """

    def __init__(self, make: Any, layout: Any, x: np.ndarray, *, multipliers: int = 10,
                 estimate: bool = True, tol: float = 1e-12, max_iter: int = 8):
        super().__init__(make, layout, x, multipliers=multipliers, estimate=estimate)
        self.tol, self.max_iter = float(tol), int(max_iter)
        self._mended: tuple | None = None   # (x, p, layout, ref, x on it) of the last mend
        self._old_nodes: np.ndarray | None = None   # the node values of the last point

    def _breaks(self, x: np.ndarray, p: float) -> list[str]:
        return check_inequalities(self.lay, self.terms(p), x,
                                  1e-9 * max(1.0, float(np.max(np.abs(x)))))

    def correct(self, x: np.ndarray, p: float, row: np.ndarray, target: float, far: float
                ) -> tuple[np.ndarray, float, int]:
        """The driver's Newton corrector on the bordered system, then the inequalities checked:
        an orbit that breaks its signature is mended (:meth:`_mend`): on a step (``far``
        finite) the mended orbit, on its new unknowns, is returned (the driver restarts its
        tangent); on a point landed on at fixed p it is kept for :meth:`point`.  One that
        cannot be mended is refused (the driver halves the step).

        Parameters
        ----------
        x : numpy.ndarray
            The predictor's unknowns.
        p : float
            The predictor's parameter.
        row : numpy.ndarray
            The hyperplane's row over (x, p).
        target : float
            Its value.
        far : float
            How far from the predictor the corrector may go.

        Returns
        -------
        tuple
            (x, p, iterations).

        Raises
        ------
        ShootingError
            Newton fails, or the orbit breaks its signature and no mend holds.
        """
        curve = Curve(self, x.size)
        z, its = newton_corrector(curve, np.concatenate([x, [p]]), row, target, tol=self.tol,
                                  max_iter=self.max_iter, far=far,
                                  what=f"collocation near p = {p!r}")
        xz, pz = z[:-1], float(z[-1])
        bad = self._breaks(xz, pz)
        if bad and math.isfinite(far):   # a step: the mended orbit is the step's point
            _, pm, lay, ref, xm = self._mend(xz, pz, bad, free=True)
            self.lay, self.ref = lay, ref
            return xm, pm, its
        if bad:   # a point landed on at fixed p: mended at that p, for point()
            self._mended = self._mend(xz, pz, bad, free=False)
        return xz, pz, its

    def _mend(self, x: np.ndarray, p: float, bad: list[str], free: bool) -> tuple:
        """(x, p, layout, ref, x on it): the orbit on a mended signature, corrected at fixed p
        or, ``free``, where that fails (at a corner of a vertical branch the new segment has
        length 0 at that p), with p free and the new (shortest) segment's length kept
        (:meth:`_grow`); its inequalities held.  ShootingError naming the breach otherwise."""
        lay, ref = self.lay, self.ref
        xs, x0, p0 = x, x.copy(), p
        for _ in range(MENDS):
            terms = self.terms(p)
            try:
                got = mend(lay, terms, xs)
            except ValueError as e:
                raise ShootingError(f"p = {p!r}: the orbit breaks its signature ({bad[0]}) and "
                                    f"the mend is refused: {e}", []) from e
            if got is None:
                break
            lay, xs = got
            probe = CollocationDiscretisation(self.make, lay, xs,
                                              multipliers=self.count)
            probe.problem = self.problem
            ref = probe.ref
            try:
                xs, _ = solve(lay, terms, xs, ref, tol=1e-12)
            except (ShootingError, ValueError) as e:
                if not free:
                    raise ShootingError(f"p = {p!r}: the orbit breaks its signature "
                                        f"({bad[0]}); on the mended signature "
                                        f"{lay.signature.describe()} the correction at fixed p "
                                        f"failed: {e}", []) from e
                xs, p = self._grow(probe, xs, p, f"{bad[0]}; at fixed p: {e}")
                terms = self.terms(p)
            bad = check_inequalities(lay, terms, xs, 1e-9 * max(1.0, float(np.max(np.abs(xs)))))
            if not bad:
                return (x0, p0 if not free else p, lay, ref, xs)
        raise ShootingError(f"p = {p!r}: the orbit breaks its signature ({bad[0]}) and "
                            f"{MENDS} mends did not restore it", [])

    def _grow(self, probe: CollocationDiscretisation, x: np.ndarray, p: float, why: str
              ) -> tuple[np.ndarray, float]:
        """Newton (sparse LU) on the mended layout with p free and the shortest segment's
        length held at its mended value: the branch past a corner, the new segment growing from
        0 (at grazing of a vertical branch p is the only way out).  ShootingError when it
        fails."""
        lay = probe.lay
        k = lay.rows * lay.n
        _, b, T = lay.split(x)
        S = b.size
        row = np.zeros(x.size + 1)
        lengths = np.append(np.diff(b), b[0] + T - b[-1])   # segment k + 1's, then segment 0's
        j = int(np.argmin(lengths))
        if j < S - 1:
            row[k + j + 1], row[k + j] = 1.0, -1.0
        else:
            row[k], row[k + S - 1] = 1.0, -1.0
            if lay.autonomous:
                row[x.size - 1] = 1.0
        target = float(lengths[j])

        def size(z: np.ndarray) -> float:   # the bordered residual's, inf out of order
            try:
                r = probe.residual(z[:-1], float(z[-1]))
            except ValueError:               # Degenerate: the switches out of order
                return math.inf
            return max(float(np.max(np.abs(r))), abs(float(row @ z) - target))

        z = np.concatenate([x, [p]])
        for _ in range(40):
            r = probe.residual(z[:-1], float(z[-1]))
            J, Jp = probe.jacobian(z[:-1], float(z[-1]))
            try:
                dz = bordered_solve(J, Jp, row, -np.concatenate([r, [float(row @ z) - target]]))
            except ShootingError as e:   # SuperLU: singular
                raise ShootingError(f"the orbit breaks its signature ({why}); with p free on "
                                    f"{lay.signature.describe()}: {e}", []) from e
            if np.max(np.abs(dz)) <= 1e-12 * max(1.0, float(np.max(np.abs(z)))):
                return z[:-1] + dz[:-1], float(z[-1] + dz[-1])
            r0, lam = size(z), 1.0          # damped: halved while the residual grows
            while size(z + lam * dz) >= r0:
                lam *= 0.5
                if lam < 1e-4:
                    raise ShootingError(f"the orbit breaks its signature ({why}); with p free "
                                        f"on {lay.signature.describe()}, the segment's length "
                                        f"held: no descent from residual {r0:.3g}", [])
            z = z + lam * dz
        raise ShootingError(f"the orbit breaks its signature ({why}); with p free on "
                            f"{lay.signature.describe()}, the segment's length held: no "
                            "convergence", [])

    def adapt(self, x: np.ndarray, p: float) -> np.ndarray:
        """After a step: the signature and mesh adapted
        (:meth:`CollocationDiscretisation.adapt`); an orbit whose signature changed there (a
        vanishing segment removed) is corrected again at p, or left as it was where that fails.

        Parameters
        ----------
        x : numpy.ndarray
            The step's unknowns.
        p : float
            Its parameter.

        Returns
        -------
        numpy.ndarray
            The unknowns on the new layout.
        """
        before = self.lay.signature.describe()
        old = (self.lay, self.ref, x)
        xa = super().adapt(x, p)
        if self.lay.signature.describe() != before or xa.size != x.size:
            try:
                xa, _ = solve(self.lay, self.terms(p), xa, self.ref, tol=1e-12)
            except (ShootingError, ValueError):   # keep the orbit on the layout it solved
                self.lay, self.ref, xa = old
            if self._breaks(xa, p):
                self.lay, self.ref, xa = old
        return xa

    def point(self, x: np.ndarray, p: float) -> EquationOrbit:
        """The EquationOrbit at (x, p): with the merged mesh's error estimate, or, where that
        solve fails (a vertical branch: not isolated at fixed p), without it (``errors`` empty,
        ``stable`` None).

        Parameters
        ----------
        x : numpy.ndarray
            A solution at p.
        p : float
            The parameter.

        Returns
        -------
        EquationOrbit
            The point.

        Raises
        ------
        ShootingError
            The orbit breaks its signature (the step's correction should have refused it).
        """
        self._old_nodes = x[:self.lay.rows * self.lay.n].copy()
        disc: CollocationDiscretisation = self
        m = self._mended
        if m is not None and m[1] == p and m[0].size == x.size and np.all(m[0] == x):
            # a point landed on (p_end, a user point) whose orbit needed a mend: the mended one
            disc = CollocationDiscretisation(self.make, m[2], m[4],
                                             multipliers=self.count)
            disc.problem, disc.ref, x = self.problem, m[3], m[4]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CollocationWarning)
            pt = CollocationDiscretisation.point(disc, x, p)
        if pt is None and disc.estimate:
            disc.estimate = False
            try:
                pt = CollocationDiscretisation.point(disc, x, p)
            finally:
                disc.estimate = True
        if pt is None:
            raise ShootingError(f"p = {p!r}: the orbit breaks its signature "
                                f"{self.lay.signature.describe()}", [])
        return pt

    def event_functions(self, x: np.ndarray, p: float, point: EquationOrbit
                        ) -> dict[str, float]:
        """The multipliers' test functions (``period-doubling``, ``torus``) verified against
        the multipliers' estimated errors (:func:`dmi.analysis.orbit_events.verified_tests`:
        0, with an EventWarning, where a test function lies within its multiplier's error; a
        point without error estimates decides nothing); the ``fold`` is left to the driver's
        dp/ds, the signature's changes to :meth:`between`.

        Parameters
        ----------
        x : numpy.ndarray
            The unknowns.
        p : float
            The parameter.
        point : EquationOrbit
            :meth:`point`'s answer there.

        Returns
        -------
        dict
            kind -> value.
        """
        from .orbit_events import verified_tests   # here: this method's own helper
        if point is None or point.multipliers.size == 0:
            return {}
        mu = np.asarray(point.multipliers)
        err = np.asarray(point.errors.get("multipliers", np.full(mu.shape, np.inf)), float)
        if self.lay.autonomous:   # the trivial multiplier left out
            j = int(np.argmin(np.abs(mu - 1)))
            mu, err = np.delete(mu, j), np.delete(err, j)
        return verified_tests(mu, err, p)

    def carry(self, t: np.ndarray, x: np.ndarray) -> np.ndarray:
        """A direction on the new unknowns x (after a signature change) to orient the new
        tangent by: the orbit's deviation from its mean (its amplitude growing or shrinking as
        along the old tangent t), the old tangent's period and p parts.

        Parameters
        ----------
        t : numpy.ndarray
            The tangent on the old unknowns (len(x_old) + 1).
        x : numpy.ndarray
            The new unknowns.

        Returns
        -------
        numpy.ndarray
            len(x) + 1 values.
        """
        old = self._old_nodes
        grow = 0.0
        if old is not None and old.size <= t.size - 1:
            grow = float(np.dot(self._deviation(old, old.size)[:old.size], t[:old.size]))
        out = self.orient(x, 0.0) * (math.copysign(1.0, grow) if grow else 0.0)
        out[-1] = t[-1]
        if self.lay.autonomous:
            out[-2] = t[-2]
        return out

    def orient(self, x: np.ndarray, p: float) -> np.ndarray:
        """The direction a vertical start's tangent is oriented by: the orbit's deviation from
        its mean (its amplitude growing, away from a Hopf point).

        Parameters
        ----------
        x : numpy.ndarray
            The start's unknowns.
        p : float
            Its parameter.

        Returns
        -------
        numpy.ndarray
            len(x) + 1 values.
        """
        return self._deviation(x)

    def _deviation(self, x: np.ndarray, k: int | None = None) -> np.ndarray:
        """(len(x) + 1,): the first k values of x (default the layout's node values), as
        (k / n, n) node values, less their mean; 0 elsewhere."""
        n = self.lay.n
        k = self.lay.rows * n if k is None else k
        V = x[:k].reshape(-1, n)
        out = np.zeros(x.size + 1)
        out[:k] = (V - V.mean(axis=0)).ravel()
        return out

    def between(self, za: np.ndarray, a: EquationOrbit, zb: np.ndarray, b: EquationOrbit,
                middle: Any) -> list[Event]:
        """The signature's change between two points: ``stick-onset`` when a component's held
        segments (stuck, on a face) appear or go, else ``grazing``; placed at the middle of the
        two points' p (the mend happens at the first point past it).

        Parameters
        ----------
        za, zb : numpy.ndarray
            The points' (x, p) (sizes may differ).
        a, b : EquationOrbit
            The points.
        middle : callable
            The driver's bisection along the branch (not used).

        Returns
        -------
        list of Event
            Zero or one event.
        """
        sa, sb = a.signature.describe(), b.signature.describe()
        if sa == sb:
            return []
        ha, hb = _stuck_like(a), _stuck_like(b)
        changed = np.flatnonzero(ha != hb)
        kind = "stick-onset" if changed.size else "grazing"
        comp = int(changed[0]) if changed.size else None
        return [Event(kind, 0.5 * (a.p + b.p), 0, comp,
                      f"signature {sa} -> {sb} between p = {a.p!r} and {b.p!r}")]

    def corner(self, points: list[EquationOrbit]) -> str:
        """Where a branch that failed at the smallest step ended: its last signature, a
        friction component that slips throughout and comes within reach of 0 (grazing), the way
        p went over the last points, and what is known of the branch on the other side.

        Parameters
        ----------
        points : list of EquationOrbit
            The branch's points so far.

        Returns
        -------
        str
            The sentence for the status.
        """
        last = points[-1]
        ps = [q.p for q in points[-4:]]
        vertical = max(ps) - min(ps) <= 1e-7 * max(1.0, abs(last.p))
        way = "larger" if ps[-1] > ps[0] else "smaller"
        how = ("at fixed p (a vertical branch: the orbits' amplitude grows at one p)" if vertical
               else f"towards {way} p")
        graze = _grazing(self, last)
        what = (f"grazing: component {graze[0]} slips throughout and its velocity comes within "
                f"{graze[1]:.3g} of 0" if graze is not None and graze[1] <= 1e-2 * graze[2]
                else "a segment appears or vanishes")
        other = ("the stick-slip branch leaves the corner in p (a vertical branch turns there); "
                 "which way was not computed, since the mended signature's corrector failed "
                 "(above)" if vertical else
                 f"the branch on the other side continues towards {way} p with a changed "
                 "signature, which the mended corrector did not reach (above)")
        return (f"the collocated branch ended at a corner ({what}) of its signature "
                f"{last.signature.describe()} at p = {last.p:.10g}, moving {how} over its last "
                f"points: {other}; to follow it, start from a scheme's orbit past the corner "
                "(periodic_orbit at p on either side, then collocate)")


def _grazing(disc: CollocationDiscretisation, orbit: EquationOrbit
             ) -> tuple[int, float, float] | None:
    """(i, least |u_i|, half range of u_i) of the friction component that slips throughout and
    comes nearest 0, on a fine grid of the orbit; None when no friction component slips
    throughout."""
    alpha = disc.terms(orbit.p).alpha
    modes = np.asarray(orbit.signature.modes)
    best = None
    t = np.linspace(0.0, orbit.period, 2001)
    u = orbit.u_at(t)
    for i in np.flatnonzero(alpha > 0):
        if np.all(np.isin(modes[:, i], (SLIP_POS, SLIP_NEG))):
            least = float(np.min(np.abs(u[:, i])))
            if best is None or least < best[1]:
                best = (int(i), least, float(orbit.amplitude[i]))
    return best


def continue_equation_orbit(orbit: EquationOrbit, p_end: float, step: float, *,
                            max_points: int, min_step: float | None, max_step: float | None,
                            multipliers: int, tol: float, max_iter: int, at: Any) -> Branch:
    """:func:`dmi.analysis.continue_orbit` of an EquationOrbit (see its docstring).

    Parameters
    ----------
    orbit : EquationOrbit
        The start.
    p_end : float
        Where the branch ends (exactly).
    step : float
        The first step.
    max_points : int
        Points at most.
    min_step, max_step : float or None
        Step bounds.
    multipliers : int
        Leading multipliers a point.
    tol : float
        The corrector's tolerance (at most 1e-12 is used).
    max_iter : int
        The corrector's iterations a step.
    at : iterable of float
        User points.

    Returns
    -------
    Branch
        Its points are EquationOrbits; ``kind`` "autonomous" or "orbits".

    Raises
    ------
    ValueError
        A bad ``step``, ``p_end`` or ``max_points``.
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: must be finite and > 0 (p units)")
    if not math.isfinite(p_end) or p_end == orbit.p:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from the orbit's "
                         f"p = {orbit.p!r}")
    eb, x = EquationBranch.of(orbit, multipliers=multipliers)
    eb.tol = min(float(tol), 1e-12)     # the corrector's error well below the collocation's
    eb.max_iter = int(max_iter)
    return continuation(eb, x, float(orbit.p), float(p_end), step=step, min_step=min_step,
                        max_step=max_step, max_points=max_points, at=at, tol=tol,
                        max_iter=max_iter,
                        predictor="tangent", make=orbit.make,
                        kind="autonomous" if orbit.autonomous else "orbits")


def equation_branch_start(make: Any, hopf_point: Any, u_eq: Any, amplitude: float,
                          multipliers: int, tol: float, max_iter: int) -> EquationOrbit:
    """``hopf_orbit(..., of="equation")``: :func:`equation_hopf_orbit` at the checked Hopf
    point.

    Parameters
    ----------
    make : callable
        ``make(p) -> dmi.Solver`` (no h needed).
    hopf_point : HopfPoint
        The equation's Hopf point.
    u_eq : array_like
        The equilibrium there.
    amplitude : float
        As :func:`equation_hopf_orbit`'s.
    multipliers : int
        Leading multipliers.
    tol : float
        Newton's tolerance (at most 1e-12 is used: the orbit's own accuracy).
    max_iter : int
        Newton iterations at most.

    Returns
    -------
    EquationOrbit
        The start of the collocated branch.
    """
    return equation_hopf_orbit(make, hopf_point, u_eq, amplitude, multipliers=multipliers,
                               tol=min(tol, 1e-12), max_iter=max_iter)


__all__ = ["EquationBranch", "continue_equation_orbit", "equation_branch_start"]
