# Continuation of the equation's periodic orbits (collocation) by the one continuation driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Branches of :class:`EquationOrbit`: :func:`continue_equation_orbit` (what
:func:`dmi.analysis.continue_orbit` does with an EquationOrbit) and :func:`equation_branch_start`
(``hopf_orbit(..., of="equation")``).

:class:`EquationBranch` hands the collocation system
(:class:`dmi.analysis.CollocationDiscretisation`) to :func:`dmi.analysis.continuation.driver.continuation`:
the residual and its sparse Jacobian (the driver's tangent predictor and Newton corrector with
SuperLU; a residual that raises ``Degenerate``, a segment's length gone to 0, is a failed
step: the driver halves it), the points (the EquationOrbit with its period, amplitude,
multipliers and signature; on a vertical branch, where the orbit is not isolated at fixed p,
without the merged mesh's error estimate and with ``stable`` None), the events of the
multipliers (``period-doubling``, ``torus``; the fold is the driver's) and of the signature
(``stick-onset`` where the number of a component's stuck or face segments changes,
``grazing`` where the segments change otherwise; located by the driver's
:func:`~dmi.analysis.continuation.driver.locate`, Brent's method on the margin of the breaking
inequality along the branch, :meth:`EquationBranch.between`).  The signature changes by itself,
through the driver's hooks: a point the driver's corrector converged to whose orbit breaks an
inequality of its signature is mended (``accept``: a segment split around the breach, a
vanishing one removed, :func:`dmi.analysis.collocation.mend.mend`) and corrected again at its p (where that is
singular, at the corner of a vertical branch, with p free and the new segment's length held),
up to four times; where a step fails next to a held segment shorter than SHED of the period
(the branch back to a corner), the short held segments are removed and the orbit solved with p
free and its amplitude held just inside (``recover``, :meth:`EquationBranch._shed`; a landing
there: at the landing's p); where a step fails as a forced orbit's switch nears t = 0 (= T),
within SHED of the period, the signature is rotated (the switch moved across to the other end,
:func:`dmi.analysis.collocation.mend.rotated`) and the orbit solved with p free and that switch
held (``recover``, :meth:`EquationBranch._wrap`; a landing: at its p).  The mended point is
the step's (``accept`` returns it on its new unknowns),
the mesh is equidistributed after every step (``adapt``), and the driver restarts its tangent
on the new unknowns (oriented by :meth:`EquationBranch.carry`; a vertical start by
:meth:`EquationBranch.orient`, the amplitude growing).  A branch that fails at the smallest
step says so in its status: the corner (grazing: the component and how near its velocity came
to 0), which way p went there, and what is known of the branch on the other side.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..continuation.branch import Branch, Event, corner_sentence, travel
from ..collocation.adapt import transfer
from .discretisation import CollocationDiscretisation, equation_hopf_orbit
from ..collocation.mend import circle, mend, relaid, removed, rotated, wrapping
from ..collocation.margins import MarginValues, margins
from ..collocation.signature import HI, LO, SLIP_NEG, SLIP_POS, STUCK
from ..collocation.system import CollocationWarning, check_inequalities, solve
from ..continuation.driver import (ContinuationOptions, Curve, Predictor, continuation, locate,
                                   newton_corrector, tangent)
from ..collocation.orbit import EquationOrbit
from ..core.newton import Converge, NewtonOptions, Search, ShootingError

#: Mends (split or removal, then a correction at fixed p) tried on one point at most.
MENDS = 4
#: A held segment shorter than this fraction of the period is removed where a step fails.
SHED = 0.02
#: The amplitude held past such a removal: (1 - SHRINK^k) of the last point's, k = 1, 2, 3.
SHRINK = 1e-3
#: A switch moved across t = 0 (= T) lands at least this fraction of the period past it.
WRAP = 1e-3
#: Newton with a segment's length (or the amplitude) held, p free: converged on the correction,
#: damped, a step that puts the switches out of order (Degenerate, a ValueError) halved.
HELD = NewtonOptions(tol=1e-12, max_iter=40, converge=Converge.CORRECTION, search=Search.DESCENT,
                     reject=(ValueError,), reject_why="every step puts the switches out of order",
                     stall=False)


def _stuck_like(orbit: EquationOrbit) -> np.ndarray:
    """Shape (n,): how many segments hold each component (stuck, or on a face)."""
    modes = np.asarray(orbit.signature.modes)
    return np.count_nonzero((modes == STUCK) | (modes == LO) | (modes == HI), axis=0)


class EquationBranch(CollocationDiscretisation):
    """The collocation discretisation of a branch for
    :func:`dmi.analysis.continuation.driver.continuation` (see the module):
    :class:`CollocationDiscretisation` (its residual and Jacobian) with the driver's hooks:
    ``accept`` and ``recover`` (mends and sheds), ``adapt``, points, events and corners.

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
        self._last: tuple | None = None   # (x, p, layout) of the last point
        self._prev: tuple | None = None   # the same of the point before it
        self._stepped_on: Any = None   # the layout the last step was corrected on

    @property
    def newton(self) -> NewtonOptions:
        """The driver's corrector on this branch: Newton to ``tol`` in ``max_iter``
        iterations, converged on the residual and the last correction."""
        return NewtonOptions(tol=self.tol, max_iter=self.max_iter, converge=Converge.BOTH)

    def _breaks(self, x: np.ndarray, p: float) -> list[str]:
        return check_inequalities(self.lay, self.terms(p), x)

    def accept(self, x: np.ndarray, p: float, step: bool) -> tuple[np.ndarray, float]:
        """The driver's corrected point checked against its signature's inequalities: an orbit
        that breaks its signature is mended (:meth:`_mend`): on a step the mended orbit, on its
        new unknowns, is returned (the driver restarts its tangent); on a point at fixed p (a
        landing, a chord's point) it is kept for :meth:`point` and the point returned as it is.
        One that cannot be mended is refused (the driver halves the step).

        Parameters
        ----------
        x : numpy.ndarray
            The corrected unknowns.
        p : float
            Their parameter.
        step : bool
            A step's point (else a point on a fixed hyperplane).

        Returns
        -------
        tuple
            (x, p), on the mended layout where a step's orbit was mended.

        Raises
        ------
        ShootingError
            The orbit breaks its signature and no mend holds.
        """
        bad = self._breaks(x, p)
        if bad and step:   # a step: the mended orbit is the step's point
            _, pm, lay, ref, xm = self._mend(x, p, bad, free=True)
            self.lay, self.ref = lay, ref
            return xm, pm
        if bad:   # a point landed on at fixed p: mended at that p, for point()
            self._mended = self._mend(x, p, bad, free=False)
        return x, p

    def recover(self, x: np.ndarray, p: float, row: np.ndarray, target: float, step: bool,
                error: Exception) -> tuple[np.ndarray, float] | None:
        """Where the driver's corrector failed from the predictor (x, p): past a corner where
        held segments vanish (:meth:`_shed`), or past a forced orbit's switch that crosses
        t = 0 (:meth:`_wrap`): on a step with p free, the step's point on the new
        unknowns; on a landing (the hyperplane p = target) at that p, the mended orbit kept for
        :meth:`point` and the predictor returned (the unknowns stay).  None otherwise.

        Parameters
        ----------
        x, p : numpy.ndarray, float
            The predictor.
        row : numpy.ndarray
            The hyperplane's row over (x, p).
        target : float
            Its value.
        step : bool
            A step (else a point on a fixed hyperplane).
        error : Exception
            The corrector's failure.

        Returns
        -------
        tuple or None
            (x, p), or None: the failure stands.
        """
        landing = row[-1] == 1.0 and not np.any(row[:-1])
        if not (step or landing):
            return None
        at = None if step else float(target)
        got = self._shed(str(error), at)
        if got is None:
            got = self._wrap(x, p, str(error), at)
        if got is None:
            return None
        xm, pm, lay, ref = got
        if not step:
            self._mended = (x.copy(), pm, lay, ref, xm)
            return x, pm
        self.lay, self.ref = lay, ref
        return xm, pm

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
            bad = check_inequalities(lay, terms, xs)
            if not bad:
                return (x0, p0 if not free else p, lay, ref, xs)
        raise ShootingError(f"p = {p!r}: the orbit breaks its signature ({bad[0]}) and "
                            f"{MENDS} mends did not restore it", [])

    def _shed(self, why: str, at: float | None) -> tuple[np.ndarray, float, Any, Any] | None:
        """The branch past a corner where held segments vanish (a stick-slip branch back to
        grazing, or a landing on p_end before the stick onset the step went past): every held
        (stuck, on a face) segment of the last point shorter than SHED of the period is
        removed, and the orbit on the remaining signature is solved at p = ``at``, or, ``at``
        None, with p free and its deviation from its mean held at (1 - SHRINK^k) of the last
        point's, k = 1, 2, 3 (the orbit on the other side, just inside: at the corner of a
        vertical branch p is fixed and the amplitude is the only way on); its inequalities
        held.  (x, p, layout, ref), or None when the last point has no such segment or no solve
        holds."""
        last = self._last
        if last is None or last[2] is not self.lay:
            return None
        x0, p0, lay = last
        shed = False
        while lay.S >= 2:
            segs, T = circle(lay, x0)
            lengths = [(segs[(j + 1) % len(segs)][1] - sg[1]) % T for j, sg in enumerate(segs)]
            short = [j for j, sg in enumerate(segs) if lengths[j] < SHED * T
                     and np.any(np.isin(sg[0], (STUCK, LO, HI)))]
            if not short:
                break
            try:
                lay, x0 = relaid(lay, self.terms(p0), x0, removed(segs, short[0], T), T)
            except ValueError:
                return None
            shed = True
        if not shed:
            return None
        probe = CollocationDiscretisation(self.make, lay, x0, multipliers=self.count)
        probe.problem = self.problem
        what = f"{why}; the held segments shorter than {SHED} of the period removed"
        if at is not None:
            try:
                xm, _ = solve(lay, self.terms(at), x0, probe.ref, tol=1e-12)
            except (ShootingError, ValueError):
                return None
            tries = [(xm, at)]
        else:
            dev = _spread(lay, x0)
            size = float(np.linalg.norm(dev[:-1]))
            dev[:-1] /= max(size, 1e-300)
            tries = []
            for k in (1, 2, 3):
                try:
                    tries.append(self._held(probe, x0, p0, dev,
                                                float(dev[:-1] @ x0) - SHRINK ** k * size, what))
                except ShootingError:
                    continue
        for xm, pm in tries:
            if not check_inequalities(lay, self.terms(pm), xm):
                return xm, pm, lay, probe.ref
        return None

    def _wrap(self, x: np.ndarray, p: float, why: str, at: float | None
              ) -> tuple[np.ndarray, float, Any, Any] | None:
        """The forced orbit past a switch that crosses t = 0 (= T): on a step, where the last
        point's switch nearest the period's ends lies within SHED of the period of it and the
        predictor (x, p) moves it closer; on a landing (``at``), where the predictor's does;
        the signature rotated (:func:`~dmi.analysis.collocation.mend.rotated`: the same
        segments, the switch moved across to the other side, its distance there max(its
        distance, WRAP of the period)), the orbit solved at p = ``at``, or, ``at`` None, with p
        free and the moved switch held (the branch on the other side, in p beyond the last
        point's as the predictor's); its inequalities held.  (x, p, layout, ref), or None."""
        lay, last = self.lay, self._last
        if lay.autonomous or lay.S == 0:
            return None
        T = lay.period
        if at is None:
            if last is None or last[2] is not lay or x.size != last[0].size:
                return None
            x0, p0, _ = last
        else:
            x0, p0 = x, p
        k, d = wrapping(lay, x0)
        _, b, _ = lay.split(x)
        ahead = float(b[0] if k == 1 else T - b[-1])
        if not (d < SHED * T and (ahead < d or at is not None)):
            return None
        try:
            new, x1, j = rotated(lay, self.terms(p0), x0, max(d, WRAP * T))
        except ValueError:
            return None
        probe = CollocationDiscretisation(self.make, new, x1, multipliers=self.count)
        probe.problem = self.problem
        try:
            if at is not None:
                xm, pm = solve(new, self.terms(at), x1, probe.ref, tol=1e-12)[0], at
            else:
                row = np.zeros(x1.size + 1)
                row[new.rows * new.n + j] = 1.0
                xm, pm = self._held(probe, x1, p0, row, float(row[:-1] @ x1),
                                    f"{why}; switch {k} wrapped across t = 0 (= T)")
        except (ShootingError, ValueError):
            return None
        if at is None and (pm - p0) * (p - p0) <= 0:   # not on in p as the step was
            return None
        if check_inequalities(new, self.terms(pm), xm):
            return None
        return xm, pm, new, probe.ref

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
        return self._held(probe, x, p, row, float(lengths[j]), why)

    def _held(self, probe: CollocationDiscretisation, x: np.ndarray, p: float,
                  row: np.ndarray, target: float, why: str) -> tuple[np.ndarray, float]:
        """Damped Newton (sparse LU; the driver's corrector) on probe's system bordered by
        row . (x, p) = target, p free, from (x, p).  ShootingError when it fails."""
        z0 = np.concatenate([x, [p]])
        try:
            z, _ = newton_corrector(Curve(probe, x.size), z0, row, target, HELD,
                                    what="Newton with the segment's length held",
                                    scale=lambda z: max(1.0, float(np.max(np.abs(z)))))
        except ShootingError as e:
            raise ShootingError(f"the orbit breaks its signature ({why}); with p free on "
                                f"{probe.lay.signature.describe()}: {e}", e.residuals) from e
        return z[:-1], float(z[-1])

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
        self._stepped_on = self.lay
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
        ``stable`` None) and with a CollocationWarning saying why.

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
        self._prev, self._last = self._last, (x.copy(), float(p), self.lay)
        disc: CollocationDiscretisation = self
        m = self._mended
        if m is not None and m[1] == p and m[0].size == x.size and np.all(m[0] == x):
            # a point landed on (p_end, a user point) whose orbit needed a mend: the mended one
            disc = CollocationDiscretisation(self.make, m[2], m[4],
                                             multipliers=self.count)
            disc.problem, disc.ref, x = self.problem, m[3], m[4]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            pt = CollocationDiscretisation.point(disc, x, p)
        if pt is None and disc.estimate:
            disc.estimate = False
            try:
                pt = CollocationDiscretisation.point(disc, x, p)
            finally:
                disc.estimate = True
            if pt is not None:      # one warning for the point: why it has no estimate
                why = "; ".join(str(w.message) for w in caught
                                if issubclass(w.category, CollocationWarning))
                caught = [w for w in caught if not issubclass(w.category, CollocationWarning)]
                warnings.warn(f"p = {p!r}: the point has no error estimate and no stability "
                              f"verdict (stable None){': ' + why if why else ''}",
                              CollocationWarning, stacklevel=2)
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if pt is None:
            raise ShootingError(f"p = {p!r}: the orbit breaks its signature "
                                f"{self.lay.signature.describe()}", [])
        return pt

    def on_current(self, x: np.ndarray, p: float) -> np.ndarray | None:
        """The point before the last step, (x, p), on the layout the step's point was adapted
        to (another mesh of the same signature): interpolated and solved again at p (for the
        driver's location of an event between points whose meshes differ).

        Parameters
        ----------
        x : numpy.ndarray
            The unknowns of the point before the last.
        p : float
            Its parameter.

        Returns
        -------
        numpy.ndarray or None
            The unknowns on the current layout, or None: x is not on the layout the step
            was corrected on, the signatures differ, or the solve fails.
        """
        lay = self._stepped_on
        if (lay is None or lay.size != x.size
                or lay.signature.describe() != self.lay.signature.describe()):
            return None
        try:
            xs, _ = solve(self.lay, self.terms(p), transfer(lay, x, self.lay), self.ref,
                          tol=1e-12)
        except (ShootingError, ValueError):
            return None
        return xs

    def event_functions(self, x: np.ndarray, p: float, point: EquationOrbit
                        ) -> dict[str, float]:
        """The multipliers' test functions (``period-doubling``, ``torus``) verified against
        the multipliers' estimated errors (:func:`dmi.analysis.branches.events.verified_tests`:
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
        from .events import verified_tests   # here: this method's own helper
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
        return _spread(self.lay, x, k)

    def between(self, za: np.ndarray, a: EquationOrbit, zb: np.ndarray, b: EquationOrbit,
                middle: Any) -> list[Event]:
        """The signature's change between two points: ``stick-onset`` when the number of a
        component's held segments (stuck, on a face) changes, else ``grazing``; located
        (:meth:`_locate`) on the side whose signature holds on past the change, where the
        margin of the inequality that breaks there reaches 0, by Brent's method along that
        side's branch;
        reported at that p only when bracketed and converged (the detail gives the bound),
        else at the middle of the two points' p with the detail saying why it is not located.

        Parameters
        ----------
        za, zb : numpy.ndarray
            The points' (x, p) (sizes may differ).
        a, b : EquationOrbit
            The points.
        middle : callable
            The driver's bisection along the branch (not used: the two points may lie on
            different unknowns).

        Returns
        -------
        list of Event
            Zero or one event.
        """
        sa, sb = a.signature.describe(), b.signature.describe()
        if sa == sb or a.signature.rotates_to(b.signature):   # the same, or a switch wrapped
            return []
        ha, hb = _stuck_like(a), _stuck_like(b)
        changed = np.flatnonzero(ha != hb)
        kind = "stick-onset" if changed.size else "grazing"
        comp = int(changed[0]) if changed.size else None
        span = f"signature {sa} -> {sb} between p = {a.p!r} and {b.p!r}"
        try:
            p, bound = self._locate(za, a, zb, b)
        except (ShootingError, ValueError) as e:
            return [Event(kind, 0.5 * (a.p + b.p), 0, comp,
                          f"{span}; not located (placed at the middle): {e}")]
        return [Event(kind, p, 0, comp, f"{span}; located at p = {p!r} to {bound:.1g} (Brent "
                      "on the margin of the breaking inequality along the branch)")]

    def _locate(self, za: np.ndarray, a: EquationOrbit, zb: np.ndarray, b: EquationOrbit
                ) -> tuple[float, float]:
        """(p, bound): where the margin (:func:`_margin`) of the side that holds on (the point
        whose layout is kept: a's, the last but one, or b's, the last) reaches 0 along that
        side's branch (its tangent oriented towards the other point; behind the point where its
        margin is already negative, a mend one step late), by Brent's method on the
        hyperplanes across the tangent; the bound is the p span of a bracket 4 xtol wide
        around the root, its margins of opposite signs.  ValueError or ShootingError (why)
        when the margin is not bracketed within 8 times the points' distance or Brent fails."""
        sides = []
        for z, q, other, kept in ((za, a, b, self._prev), (zb, b, a, self._last)):
            if kept is not None and kept[0].size == z.size - 1 and np.array_equal(kept[0],
                                                                                z[:-1]):
                sides.append((z, q, other, kept[2]))
        for z, q, other, lay in sides:
            probe = CollocationDiscretisation(self.make, lay, z[:-1], multipliers=self.count)
            probe.problem = self.problem
            g0 = _margin(probe, z[:-1], float(z[-1]), other.signature)
            if g0 is None or g0 == 0 or not math.isfinite(g0):
                continue
            # g0 > 0: the margin breaks towards the other point; g0 < 0: it broke already
            # before this point (a mend one step late, e.g. the second of two sticks): behind it
            way = 1.0 if g0 > 0 else -1.0
            curve = Curve(probe, z.size - 1)
            gap = float(np.max(np.abs(other.amplitude - q.amplitude)))
            prev = _spread(lay, z[:-1])
            prev *= math.copysign(gap, float(np.sum(other.amplitude - q.amplitude))) / max(
                curve.norm(prev), 1e-300)
            prev[-1] = other.p - q.p
            t = tangent(curve, z, prev)[0]

            def g(zs: np.ndarray) -> float:
                m = _margin(probe, zs[:-1], float(zs[-1]), other.signature)
                if m is None:
                    raise ValueError("the margin is not defined along the branch")
                return m
            L = abs(other.p - q.p) + gap
            got = locate(probe, z, t, g, g0, [way * s * L for s in (0.5, 1, 2, 4, 8)],
                         self.newton.but(max_iter=2 * self.max_iter))
            if got is None:
                raise ValueError(f"the margin {g0:.3g} of p = {q.p!r} does not reach 0 within "
                                 f"{8 * L:.3g} along its branch")
            p0, p1 = float(got[1][-1]), float(got[2][-1])
            return float(got[0][-1]), max(abs(p1 - p0), 1e-16 * max(1.0, abs(p0)))
        raise ValueError("neither side's orbit has a margin that breaks at this change")

    def corner(self, points: list[EquationOrbit]) -> str:
        """Where a branch that failed at the smallest step ended, in the words of
        :func:`~dmi.analysis.continuation.branch.corner_sentence`: a friction component that slips
        throughout and comes within 1 % of its half range of 0 without crossing it (grazing; a
        reversal, where it crosses 0, is none), or else the component
        that switches into the shortest segment of the last signature (a segment that vanishes
        or appears there); "" for a smooth orbit that does not graze.

        Parameters
        ----------
        points : list of EquationOrbit
            The branch's points so far.

        Returns
        -------
        str
            The sentence for the status, or "".
        """
        last = points[-1]
        towards = travel([q.p for q in points[-4:]])
        graze = _grazing(self, last)
        follow = ("to follow it, start from a scheme's orbit past the corner (periodic_orbit at "
                  "p on either side, then collocate)")
        if towards == "either":
            other = ("the stick-slip branch leaves the corner in p (a vertical branch turns "
                     "there); which way was not computed, since the mended signature's corrector "
                     "failed (below); " + follow)
        else:
            other = (f"the branch on the other side continues towards {towards} p with a "
                     "changed signature, which the mended corrector did not reach (below); "
                     + follow)
        sig = " ".join(last.signature.describe())
        if graze is not None and graze[1] <= 1e-2 * graze[2]:
            return corner_sentence(
                graze[0], last.p, towards,
                f"its orbits slip throughout (signature {sig}) and its velocity comes within "
                f"{graze[1]:.3g} of 0 (half range {graze[2]:.3g}): a grazing", other)
        S = last.signature.switches
        if S == 0:
            return ""
        b = np.asarray(last.switches, dtype=float)
        lengths = np.append(np.diff(b), last.period - b[-1] + b[0])   # segments 1..S-1, then 0
        k = int(np.argmin(lengths)) + 1      # the switch b_k that enters the shortest segment
        i = last.signature.switch(k)[0]
        return corner_sentence(
            i, last.p, towards,
            f"a segment of its signature {sig} appears or vanishes there (the shortest lasts "
            f"{float(lengths.min()):.3g} of the period {last.period:.6g})", other)


def _grazing(disc: CollocationDiscretisation, orbit: EquationOrbit
             ) -> tuple[int, float, float] | None:
    """(i, least |u_i|, half range of u_i) of the friction component that slips throughout and
    comes nearest 0 without crossing it (the least local minimum of |u_i| on a fine grid of the
    orbit whose neighbours have one sign: a touch; the reversals, where u_i crosses 0, are not
    read); None when no friction component slips throughout and touches."""
    alpha = disc.terms(orbit.p).alpha
    modes = np.asarray(orbit.signature.modes)
    best = None
    t = np.linspace(0.0, orbit.period, 2001)[:-1]   # periodic: the last point is the first
    u = orbit.u_at(t)
    for i in np.flatnonzero(alpha > 0):
        if np.all(np.isin(modes[:, i], (SLIP_POS, SLIP_NEG))):
            v = u[:, i]
            before, after = np.roll(v, 1), np.roll(v, -1)
            touch = ((np.abs(v) <= np.abs(before)) & (np.abs(v) <= np.abs(after))
                     & (before * after > 0))
            if not np.any(touch):
                continue
            least = float(np.min(np.abs(v[touch])))
            if best is None or least < best[1]:
                best = (int(i), least, float(orbit.amplitude[i]))
    return best


def _spread(lay: Any, x: np.ndarray, k: int | None = None) -> np.ndarray:
    """(len(x) + 1,): the first k values of x (default the node values of ``lay``), as
    (k / n, n) node values, less their mean; 0 elsewhere."""
    k = lay.rows * lay.n if k is None else k
    V = x[:k].reshape(-1, lay.n)
    out = np.zeros(x.size + 1)
    out[:k] = (V - V.mean(axis=0)).ravel()
    return out


def _margin(disc: CollocationDiscretisation, x: np.ndarray, p: float, other: Any
             ) -> float | None:
    """The least margin, at (x, p) on disc's layout, of the inequalities that break towards
    the signature ``other`` (:func:`dmi.analysis.collocation.margins.margins`: a slip's least
    |u_i|, a box component's least distance to a face, |net force_i| - alpha_i at a reversal,
    a stuck stretch's force against the other bound, a run's least interior value; 0 where
    the orbit sticks, grazes or touches), each its least value on the orbit; None when no
    component has one of these."""
    terms = disc.terms(p)
    out = [MarginValues(disc.lay, m).least(terms, x)[0]
           for m in margins(disc.lay, terms, other)]
    out = [v for v in out if math.isfinite(v)]
    return min(out) if out else None


def continue_equation_orbit(orbit: EquationOrbit, p_end: float, options: ContinuationOptions,
                            *, multipliers: int) -> Branch:
    """:func:`dmi.analysis.continue_orbit` of an EquationOrbit (see its docstring).

    Parameters
    ----------
    orbit : EquationOrbit
        The start.
    p_end : float
        Where the branch ends (exactly).
    options : ContinuationOptions
        The step control, user points, the start's tolerance; the corrector's: Newton to
        min(tol, 1e-12) in max_iter iterations.
    multipliers : int
        Leading multipliers a point.

    Returns
    -------
    Branch
        Its points are EquationOrbits; ``kind`` "autonomous" or "orbits".

    Raises
    ------
    ValueError
        A bad ``p_end``.
    """
    if not math.isfinite(p_end) or p_end == orbit.p:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from the orbit's "
                         f"p = {orbit.p!r}")
    eb, x = EquationBranch.of(orbit, multipliers=multipliers)
    eb.tol = min(float(options.tol), 1e-12)   # the corrector's error well below the collocation's
    eb.max_iter = int(options.max_iter)
    return continuation(eb, x, float(orbit.p), float(p_end), options, newton=eb.newton,
                        predictor=Predictor.TANGENT, make=orbit.make,
                        kind="autonomous" if orbit.autonomous else "orbits")


def equation_branch_start(make: Any, hopf_point: Any, u_eq: Any, amplitude: float,
                          multipliers: int, tol: float, max_iter: int,
                          kernel_jumps: tuple[float, ...] = (), start: float | None = None
                          ) -> EquationOrbit:
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
    kernel_jumps : tuple of float
        The lags where H jumps (:func:`dmi.analysis.collocate`).
    start : float, optional
        The parameter Newton starts from (default the Hopf point's p).

    Returns
    -------
    EquationOrbit
        The start of the collocated branch.
    """
    return equation_hopf_orbit(make, hopf_point, u_eq, amplitude, multipliers=multipliers,
                               tol=min(tol, 1e-12), max_iter=max_iter,
                               kernel_jumps=kernel_jumps, start=start)


__all__ = ["EquationBranch", "continue_equation_orbit", "equation_branch_start"]
