# Pseudo-arclength continuation of periodic orbits and their events.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Continuation of a periodic orbit of the scheme in its parameter p.

Pseudo-arclength on z = (x, p), x the shooting state (:mod:`dmi.analysis.shooting`): a secant
predictor z + ds t (the first step: x at p + step), then a corrector on  F_p(x) - x = 0,
<t, z - z_pred> = 0.  The corrector is Newton-Picard: the previous point's multipliers leave a
basis Q of the dominant subspace and its image Z = D_xF Q (:func:`dmi.analysis.floquet.ritz`),
and the bordered system with D_xF replaced by Z Q' is solved exactly in b + 1 unknowns, one
evaluation of the map an iteration: a chord Newton step on span Q, a Picard step on its
complement, which contracts at the rate of the largest multiplier left out (Lust, Roose, Spence
and Champneys, SIAM J. Sci. Comput. 19 (1998) 1188).  When that contracts too slowly (by less
than half an iteration) or there is no basis yet (``multipliers=0``), Newton with GMRES on the
bordered matrix-free Jacobian [[D_xF - I, D_pF], [t_x' / dim, t_p]] (D_xF by forward differences
along the Krylov vectors, D_pF by one difference in p per iteration) takes over from the
predictor; ``BranchPoint.corrector`` says which converged.  The inner product weighs
x by 1 / dim (an RMS), so ds is a step in "p or RMS state units".  By default the period M h is
kept: make(p) must keep h.  With ``period=P`` (a function p -> the period, time units, e.g. the
forcing period 2 pi / p of a continuation in the frequency) M is kept and the step follows p:
the map at p is built by ``make(p, h=P(p) / M)`` (libdmi 1.2's ``Solver(n, tau, h=...)``, as for
an autonomous orbit).  A model over tau with a free step h has N = ceil(tau / h) changing with p
(with tau, or with h): the states hold L = max N + 1 over the two ends of the range (+ 2 %) rows,
the older ones filled by M-periodicity (:meth:`StepMap.extend`); the map reads the last
N(p) + 1.  The step grows by 1.5 after an easy corrector (Newton-Picard in <= 6 iterations,
Newton in <= 3),
halves after a failure, and the branch ends at p_end, at ``max_points``, when it leaves the
p-range it started in, or when the step falls below ``min_step`` (``Branch.status`` says which).

Kinks, where the stick pattern changes, are passed: the map is piecewise smooth, its Newton
semismooth, and a failing corrector retries with a halved step.

Events between consecutive points (``Branch.events``):
- ``fold``: dp/ds changes sign (the tangent's p component);
- ``period-doubling``: the number of real multipliers < -1 changes;
- ``torus``: the number of complex multipliers with |mu| > 1 changes;
- ``stick-onset``: a component starts (or stops) sticking somewhere in the period: its number
  of stuck steps goes from 0 to > 0 (or back);
- ``grazing``: a component's number of stick phases changes while it sticks on both sides.
A step is stuck when U_i == 0 for 2 steps or more (:func:`dmi.analysis.shooting.stuck_mask`).
Every point carries ``margin``, a component's least force besides friction at its velocity
reversals, less the friction threshold alpha_i (force units): min |X_i - U_i^p| / h - alpha_i
over the steps p where U_i reaches 0 or changes sign (X the resolvent's argument, from the same
run as the point's states, :meth:`dmi.Solver.run_terms`; alpha_i = |X_i - U_i^(p+1)| / h on the
slip steps).  It is > 0 where every reversal slips through (Den Hartog's net force beyond
friction), <= 0 where the component sticks, and crosses 0 at a stick-onset; it does not depend
on where the steps fall about the reversal (a lone zero step or a sign change), to O(h).
Stick-onset and grazing events are located by bisection along the branch (the chord between the
two points shortened 64 times, each middle corrected across the chord).
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .._solver import Solver
from .branch import Branch, BranchPoint, Event, thinned
from .floquet import fd_step, phase_free, ritz
from .autonomous import AutonomousMaps, phase_row, velocity
from .newton import ShootingError, bordered_newton, bordered_step, fd_eps
from .orbit import Orbit, make_orbit, stuck_mask
from .refine import refine_orbit
from .shooting import periodic_orbit
from .stability import non_real
from .stepmap import Model, StepMap, build, fixed_step, positive_time


def _stick_profile(F: StepMap, U: np.ndarray, X: np.ndarray | None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stuck steps, stick phases and margins (see the module) over one period, from its M + 1
    states U and the resolvent's arguments X of its M steps (:meth:`StepMap.trajectory_terms`);
    X None: the margins are NaN."""
    stuck = stuck_mask(U)
    steps = stuck.sum(axis=0)
    # stick phases on the circle: starts of runs of stuck steps
    phases = np.sum(stuck & ~np.roll(stuck, 1, axis=0), axis=0)
    phases[steps == F.M] = 1
    margin = np.full(F.n, np.nan if X is None else np.inf)
    if X is None:
        return steps, phases, margin
    u0, u1 = U[:-1], U[1:]          # U^p and U^(p+1) of the steps p = 0 .. M - 1
    for i in range(F.n):
        slip = (u1[:, i] != 0.0) & (X[:, i] != u1[:, i])
        if not slip.any():
            continue                    # no friction on this component
        alpha = float(np.median(np.abs(X[slip, i] - u1[slip, i]))) / F.h
        # the steps where the velocity reaches 0 or crosses it (all steps of a component stuck
        # throughout), and the force there besides friction, |X - U^p| / h
        entry = ((u1[:, i] == 0.0) & (u0[:, i] != 0.0)) | (u0[:, i] * u1[:, i] < 0.0)
        if not entry.any():
            entry = stuck[:, i]
        if entry.any():
            margin[i] = float(np.min(np.abs(X[entry, i] - u0[entry, i]))) / F.h - alpha
    return steps, phases, margin


def _point(F: StepMap, x: np.ndarray, multipliers: int, sections: int, dpds: float,
           iterations: int, margins: bool = True, warm: list | None = None,
           corrector: str = "", terms: tuple[np.ndarray, np.ndarray] | None = None,
           autonomous: bool = False) -> BranchPoint:
    """The BranchPoint at the fixed point x of F; ``warm``: a one-element list holding the
    previous point's (Q, Z) of :func:`ritz` (replaced by this point's): the Ritz step starts
    from Z, one block of products instead of two from random vectors.  ``terms``: x's
    :meth:`StepMap.trajectory_terms` when the caller has them (:func:`_correct`).  An
    ``autonomous`` orbit's ``stable`` leaves out its phase multiplier."""
    U, X = F.trajectory_terms(x) if terms is None else terms
    mu = np.empty(0, complex)
    if multipliers > 0:
        prev = warm[0] if warm else None
        eps = fd_step(F, x, U, X)
        if prev is not None and prev[1].shape[0] == x.size:
            mu, Q, Z = ritz(F, x, multipliers, start=prev[1], eps=eps)
        else:
            mu, Q, Z = ritz(F, x, multipliers, eps=eps)
        if warm is not None:
            warm[0] = (Q, Z)
    steps, phases, margin = _stick_profile(F, U, X if margins else None)
    k = F.M // sections
    rest = phase_free(mu) if autonomous else mu
    t, u = thinned(U, F.h)
    return BranchPoint(p=F.p, period=F.M * F.h, amplitude=0.5 * (U.max(axis=0) - U.min(axis=0)),
                       multipliers=mu, stable=bool(rest.size and np.all(np.abs(rest) < 1)),
                       stick_steps=steps, stick_phases=phases, margin=margin,
                       section=U[[j * k for j in range(sections)]], state=np.array(x),
                       dpds=dpds, iterations=iterations, corrector=corrector,
                       t=t, u=u)


#: |dp/ds| (the unit tangent's p component) below which a branch is vertical: a sign change of
#: dp/ds there is noise, not a fold.
VERTICAL = 1e-6


def _test_function(kind: str, mu: np.ndarray) -> float:
    """The test function of a multiplier event, zero at it: 1 + min Re mu for a period doubling
    (the multiplier that crosses -1 may have been half of a complex pair at the previous point,
    a pair that met on the negative axis), max |mu| - 1 over the non-real multipliers for a
    torus (-1 if there is none)."""
    if kind == "period-doubling":
        return 1 + float(np.min(mu.real))
    c = np.abs(non_real(mu))
    return float(np.max(c)) - 1 if c.size else -1.0


def _events(a: BranchPoint, b: BranchPoint, index: int, autonomous: bool = False
            ) -> list[Event]:
    """The events between a and b (see the module); an ``autonomous`` branch's phase multiplier
    is left out of the multipliers' events."""
    ev: list[Event] = []
    mua, mub = (phase_free(q.multipliers) if autonomous else q.multipliers for q in (a, b))

    def at(fa: float, fb: float) -> float:
        w = 0.5 if fa == fb or fa * fb > 0 else fa / (fa - fb)  # no sign change: the middle
        return a.p + (b.p - a.p) * w

    if a.dpds * b.dpds < 0 and min(abs(a.dpds), abs(b.dpds)) > VERTICAL:
        ev.append(Event("fold", at(a.dpds, b.dpds), index, None, "dp/ds changes sign"))

    def real_neg(m: np.ndarray) -> np.ndarray:
        return m[(np.abs(m.imag) <= 1e-8 * np.maximum(np.abs(m), 1)) & (m.real < 0)].real


    na, nb = np.sum(real_neg(mua) < -1), np.sum(real_neg(mub) < -1)
    if na != nb:
        fa, fb = (_test_function("period-doubling", m) for m in (mua, mub))
        ev.append(Event("period-doubling", at(fa, fb), index, None,
                        f"real multipliers < -1: {na} -> {nb}"))
    ca, cb = np.sum(np.abs(non_real(mua)) > 1), np.sum(np.abs(non_real(mub)) > 1)
    if ca != cb:
        fa, fb = (_test_function("torus", m) for m in (mua, mub))
        ev.append(Event("torus", at(fa, fb), index, None,
                        f"complex multipliers with |mu| > 1: {ca} -> {cb}"))
    for i in range(len(a.stick_steps)):
        sa, sb = int(a.stick_steps[i]), int(b.stick_steps[i])
        if (sa == 0) != (sb == 0):
            ma, mb = a.margin[i], b.margin[i]
            ev.append(Event("stick-onset", at(ma, mb) if math.isfinite(ma + mb) else b.p, index,
                            i, f"component {i}: stuck steps {sa} -> {sb}"))
        elif sa and a.stick_phases[i] != b.stick_phases[i]:
            ev.append(Event("grazing", 0.5 * (a.p + b.p), index, i,
                            f"component {i}: stick phases {a.stick_phases[i]} -> "
                            f"{b.stick_phases[i]} (stuck steps {sa} -> {sb})"))
    return ev


def _refine_fold(last: list[BranchPoint], e: Event) -> Event:
    """The fold's p from the parabola p(s) through the last three points (s: arclength in the
    weighted norm), when it has a vertex between them."""
    if len(last) < 3:
        return e
    k = min(q.state.size for q in last)
    s = [0.0]
    for a, b in zip(last, last[1:]):
        d = b.state[-k:] - a.state[-k:]
        s.append(s[-1] + math.sqrt(float(np.dot(d, d)) / k + (b.p - a.p) ** 2))
    c = np.polyfit(s, [q.p for q in last], 2)
    if c[0] != 0:
        sv = -c[1] / (2 * c[0])
        if s[0] <= sv <= s[-1]:
            e.p = float(np.polyval(c, sv))
            e.detail += " (p from a parabola in arclength)"
    return e


def _locate_stick(maps: _Maps, a: BranchPoint, b: BranchPoint, e: Event, tol: float,
                  max_iter: int, bisections: int = 6) -> Event:
    """Bisection between a and b on the stick pattern of component e.component, along the
    branch: the orbit at the middle of the bracket's chord, corrected on the hyperplane through
    it across the chord (a step of the continuation's corrector; also where the branch turns at
    the event, as a vertical branch does at grazing), until the bracket's chord is 2^-bisections
    of the first (a corrected middle off a bent chord shortens it by less than half); the event's
    p becomes the final bracket's midpoint."""
    i = e.component
    key = (lambda q: (q[0] > 0, q[1])) if e.kind == "stick-onset" else (lambda q: (True, q[1]))
    ka = key((a.stick_steps[i], a.stick_phases[i]))
    za, zb = maps.z_of(a), maps.z_of(b)
    if za.size != zb.size:
        return e
    k = maps.k
    w = maps.weights(za.size)
    d = zb - za
    first = math.sqrt(float(np.dot(w * d, d)))
    for _ in range(4 * bisections):
        d = zb - za
        chord = math.sqrt(float(np.dot(w * d, d)))
        if chord <= first * 2.0 ** -bisections:
            break
        t = d / chord
        zm = 0.5 * (za + zb)
        try:
            if k == 2:   # the phase condition through the bracket's first point
                maps.reference(za, maps.of(za[-k:]).trajectory(za[:-k]))
            zm = _corrector(maps, zm, t, tol, max_iter, math.inf)[0]
        except Exception:   # the model's, the map's or the corrector's failure
            return e
        F = maps.of(zm[-k:])
        st, ph, _ = _stick_profile(F, F.trajectory(zm[:-k]), None)
        if key((st[i], ph[i])) == ka:
            za = zm
        else:
            zb = zm
    pa, pb = float(za[-1]), float(zb[-1])
    e.p = 0.5 * (pa + pb)
    e.detail += f" (located by bisection along the branch in [{min(pa, pb)!r}, {max(pa, pb)!r}])"
    return e


class _Maps:
    """The maps of a forced branch: StepMaps by p (the last few), all on states of ``rows``
    rows; a p whose N + 1 exceeds it is refused (ShootingError: the corrector retries with a
    shorter step).  ``period``: None (make(p) must keep the step h) or p -> the period, the map
    at p then built by make(p, h=period(p) / M).  The unknowns are z = (x, p): k = 1 extra
    unknown, no equation besides the arclength."""
    k = 1
    autonomous = False

    def __init__(self, make: Model, M: int, h: float, rows: int,
                 period: Callable[[float], float] | None = None):
        self.make, self.M, self.h, self.rows, self.period = make, M, h, rows, period
        self._cache: dict[float, StepMap] = {}

    def step(self, p: float) -> float:
        """The step h at p: period(p) / M, or the branch's h."""
        if self.period is None:
            return self.h
        try:
            P = self.period(p)
        except Exception as e:  # the period function refuses p: out of range
            raise ValueError(f"period(p = {p!r}) failed: {type(e).__name__}: {e}") from e
        return positive_time(f"period(p = {p!r})", P) / self.M

    def model(self, p: float) -> Model:
        """make as a function of p alone at p's step (the StepMap's and an Orbit's ``make``)."""
        if self.period is None:
            return self.make
        return fixed_step(self.make, self.step(p))

    def build(self, p: float) -> Solver:
        if self.period is None:
            return build(self.make, p)
        h = self.step(p)
        try:
            return build(self.model(p), p)
        except TypeError as e:
            raise ValueError(f"continue_orbit(period=...) needs a model make(p, h=...) that "
                             f"takes the step (h = period(p) / M = {h!r}): {e}") from e

    def __call__(self, p: float) -> StepMap:
        F = self._cache.get(p)
        if F is None:
            s = self.build(p)
            h = self.step(p)
            if abs(s.h - h) > 1e-12 * h:
                what = ("the branch keeps the period M h (make(p) must keep h)"
                        if self.period is None else "expected period(p) / M")
                raise ValueError(f"make(p = {p!r}) has h = {s.h!r}; {what}: h = {h!r}")
            if s.N + 1 > self.rows:
                raise ShootingError(f"make(p = {p!r}) has N = {s.N}: the branch's states hold "
                                    f"{self.rows} rows (N + 1 at the ends of its range, + 2 %)", [])
            F = StepMap(self.model(p), p, self.M, self.rows, solver=s)
            if len(self._cache) > 4:
                self._cache.pop(next(iter(self._cache)))
            self._cache[p] = F
        return F

    def of(self, q: np.ndarray) -> StepMap:
        """The map at the extra unknowns q = (p,)."""
        return self(float(q[-1]))

    def z_of(self, pt: BranchPoint) -> np.ndarray:
        return np.concatenate([pt.state, [pt.p]])

    def col_steps(self, q: np.ndarray) -> np.ndarray:
        return np.array([1e-7 * max(1.0, abs(float(q[-1])))])

    def conditions(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The equations besides the arclength: none."""
        return np.empty(0), np.empty((0, z.size))

    def weights(self, size: int) -> np.ndarray:
        """The arclength's inner product weights: 1 / dim on x (an RMS), 1 on p."""
        w = np.full(size, 1.0 / (size - 1))
        w[-1] = 1.0
        return w

    def reference(self, z: np.ndarray, U: np.ndarray) -> None:
        """A new point on the branch (nothing to update)."""


class _AutoMaps(_Maps):
    """The maps of an autonomous branch: the unknowns are z = (x, h, p) (k = 2), the maps
    StepMaps of make(p, h=h) (:class:`dmi.analysis.autonomous.AutonomousMaps`), and the phase
    condition <xdot, x_0 - x0_ref> = 0 holds besides the arclength, its reference the last
    point's state at t = 0 and velocity there (:meth:`reference`)."""
    k = 2
    autonomous = True

    def __init__(self, make: Model, M: int, h: float, rows: int):
        super().__init__(make, M, h, rows)
        self.auto = AutonomousMaps(make, M, rows, 0.6 * h)
        self.xdot = np.zeros(0)
        self.ref = np.zeros(0)

    def __call__(self, p: float) -> StepMap:
        return self.auto(self.h, p)

    def of(self, q: np.ndarray) -> StepMap:
        return self.auto(float(q[0]), float(q[1]))

    def z_of(self, pt: BranchPoint) -> np.ndarray:
        return np.concatenate([pt.state, [pt.period / self.M, pt.p]])

    def col_steps(self, q: np.ndarray) -> np.ndarray:
        return np.array([1e-7 * float(q[0]), 1e-7 * max(1.0, abs(float(q[1])))])

    def conditions(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g, row = phase_row(z[:-2], self.xdot, self.ref, 2)
        return np.array([g]), row[None, :]

    def weights(self, size: int) -> np.ndarray:
        """1 / dim on x, 1 on p, M^2 on h (the period's change counts as p's)."""
        w = np.full(size, 1.0 / (size - 2))
        w[-2], w[-1] = float(self.M) ** 2, 1.0
        return w

    def reference(self, z: np.ndarray, U: np.ndarray) -> None:
        v = velocity(U, float(z[-2]))
        self.xdot = v / max(float(np.linalg.norm(v)), 1e-300)
        self.ref = z[-2 - v.size:-2].copy()


class _Slow(Exception):
    """The Newton-Picard corrector contracts too slowly; ``z``: its iterate of least residual
    (None if it could not start), ``iterations``: the steps it took."""

    def __init__(self, message: str, z: np.ndarray | None = None, iterations: int = 0):
        super().__init__(message)
        self.z, self.iterations = z, iterations


def _too_slow(rn: float, prev: float, target: float, left: int) -> bool:
    """A linear iteration whose residual went from prev to rn contracts too slowly: by less than
    half, or at a rate that would not bring rn below target in ``left`` more iterations."""
    rate = rn / prev
    if rate > 0.5:
        return True
    return 0 < rate and target < rn and math.log(target / rn) / math.log(rate) > left


def _columns(maps: _Maps, z: np.ndarray, Fx: np.ndarray) -> np.ndarray:
    """dF/dq at z (dim, k) by one forward difference a column."""
    k = maps.k
    x, q = z[:-k], z[-k:]
    d = maps.col_steps(q)
    cols = np.empty((x.size, k))
    for j in range(k):
        qd = q.copy()
        qd[j] += d[j]
        cols[:, j] = (maps.of(qd)(x) - Fx) / d[j]
    return cols


def _borders(maps: _Maps, z: np.ndarray, zp: np.ndarray, t: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """The k equations besides F(x) = x at z: the family's (a phase condition) and the
    arclength <w t, z - zp> = 0; their values and rows (k, dim + k)."""
    g, rows = maps.conditions(z)
    wt = maps.weights(z.size) * t
    return np.concatenate([g, [float(np.dot(wt, z - zp))]]), np.vstack([rows, wt])


def _newton_picard(maps: _Maps, zp: np.ndarray, t: np.ndarray, tol: float, ds: float,
                   Q: np.ndarray, Z: np.ndarray, z0: np.ndarray | None = None,
                   max_iter: int = 16) -> tuple[np.ndarray, int]:
    """The corrector by Newton-Picard (Lust, Roose, Spence & Champneys 1998) from z0 (default the
    predictor zp) on the hyperplane through zp: the Jacobian D_xF is replaced by its rank-b
    approximation Z Q' on the previous point's dominant subspace (Q orthonormal, Z = D_xF Q
    there, from :func:`ritz`), D_qF (the k extra unknowns' columns) by one difference each at
    z0, and the bordered system

        (Z Q' - I) dx + F_q dq = -(F(x) - x),     B_x dx + B_q dq = -g,

    (B, g: the k equations of :func:`_borders`) is solved exactly: dx = Q xi + (I - Q Q')(r +
    F_q dq + Z xi), with (xi, dq) from b + k equations.  On the complement of span Q that is a
    Picard step (x takes F(x)'s component), which contracts at the rate of the largest
    multiplier left out; on span Q a chord Newton step.  One evaluation of F an iteration (k
    more for F_q); S = Q' Z gets Broyden's update from each step (ZC = Z - Q S, the leak off
    span Q, is kept).  Returns (z, iterations); raises _Slow when, after the second iteration,
    the residual falls by less than half in one, or at its rate would not reach tol within
    max_iter; ShootingError as :func:`_corrector`."""
    k = maps.k
    dim = zp.size - k
    z = zp.copy() if z0 is None else z0.copy()
    x = z[:-k]
    F = maps.of(z[-k:])
    if F.dim != dim or Q.shape[0] != dim:
        raise _Slow("the state's size changed")
    Fx = F(x)
    Fq = _columns(maps, z, Fx)
    S = Q.T @ Z
    ZC = Z - Q @ S                   # (I - Q Q') Z
    FqC = Fq - Q @ (Q.T @ Fq)
    b = Q.shape[1]
    _, B = _borders(maps, z, zp, t)  # linear equations: constant rows
    Bx, Bq = B[:, :dim], B[:, dim:]
    K = np.zeros((b + k, b + k))
    K[:b, :b] = S - np.eye(b)
    K[:b, b:] = Q.T @ Fq
    K[b:, :b] = Bx @ Q + Bx @ ZC
    K[b:, b:] = Bx @ FqC + Bq
    w = maps.weights(zp.size)
    prev, best, z_best = math.inf, math.inf, z
    for it in range(max_iter + 1):
        r = Fx - x
        g, _ = _borders(maps, z, zp, t)
        rn = float(np.max(np.abs(r)))
        if not math.isfinite(rn):
            raise ShootingError(f"non-finite residual at p = {float(z[-1])!r}", [rn])
        scale = max(1.0, float(np.max(np.abs(x))))
        if rn <= tol * scale and float(np.max(np.abs(g))) <= 1e-8 * max(1.0, abs(z[-1])):
            return z, it
        if rn < best:
            best, z_best = rn, z
        if it == max_iter or (it >= 2 and _too_slow(rn, prev, tol * scale, max_iter - it)):
            raise _Slow(f"residual {rn:.3g} after {it} iterations (previous {prev:.3g})",
                        z_best, it)
        prev = rn
        Qr = Q.T @ r
        rC = r - Q @ Qr
        try:
            sol = np.linalg.solve(K, np.concatenate([-Qr, -g - Bx @ rC]))
        except np.linalg.LinAlgError:
            raise _Slow("singular reduced system", None, it) from None
        xi, dq = sol[:b], sol[b:]
        z = z + np.concatenate([Q @ xi + rC + FqC @ dq + ZC @ xi, dq])
        d = z - zp
        far = math.sqrt(float(np.dot(w * d, d)))
        if far > ds:
            raise ShootingError(f"corrector strayed {far:.3g} > ds = {ds:.3g} from the predictor "
                                f"at p = {float(z[-1])!r}", [rn])
        x = z[:-k]
        F = maps.of(z[-k:])
        if F.dim != dim:
            raise ShootingError(f"the state grew to {F.dim} values at p = {float(z[-1])!r}", [])
        Fx, Fold = F(x), Fx
        # Broyden's update of the reduced Jacobian S = Q' D_xF Q by the step just taken (Q' dx =
        # xi): S xi := Q' (F(x_new) - F(x_old) - F_q dq); no evaluation, and a multiplier that
        # moved since the previous point (near 1, the chord's rate |dmu| / |1 - mu|) is caught
        nxi = float(np.dot(xi, xi))
        if nxi > 0:
            S = S + np.outer(Q.T @ (Fx - Fold - Fq @ dq) - S @ xi, xi / nxi)
            K[:b, :b] = S - np.eye(b)
    raise AssertionError("unreachable")


def _correct(maps: _Maps, zp: np.ndarray, t: np.ndarray, tol: float, max_iter: int, ds: float,
             dominant: tuple[np.ndarray, np.ndarray] | None, sections: int = 1
             ) -> tuple[np.ndarray, int, str, tuple[np.ndarray, np.ndarray]]:
    """:func:`_solve` and the solution's trajectory terms (:meth:`StepMap.trajectory_terms`, for
    :func:`_point`); refused (ShootingError: the step is halved) when the orbit of a branch of
    ``sections`` > 1 forcing periods is periodic over a part of them: the corrector fell onto
    the branch it was born from (a doubled branch near its doubling, where both cross the first
    step's hyperplane p = p1 close together)."""
    z, its, how = _solve(maps, zp, t, tol, max_iter, ds, dominant)
    k = maps.k
    F = maps.of(z[-k:])
    U, X = F.trajectory_terms(z[:-k])
    for q in range(2, sections + 1):
        m = F.M // q
        if sections % q == 0 and F.M % q == 0 and \
                np.max(np.abs(U[m:] - U[:-m])) <= 1e-6 * max(1.0, float(np.max(np.abs(U)))):
            raise ShootingError(f"the corrector fell onto an orbit of {m} steps (period "
                                f"{sections // q} of the branch's {sections} forcing periods) "
                                f"at p = {float(z[-1])!r}", [])
    return z, its, how, (U, X)


def _solve(maps: _Maps, zp: np.ndarray, t: np.ndarray, tol: float, max_iter: int, ds: float,
           dominant: tuple[np.ndarray, np.ndarray] | None) -> tuple[np.ndarray, int, str]:
    """The corrector from the predictor zp: Newton-Picard on the previous point's ``dominant``
    (Q, Z) when there is one; when it contracts too slowly, once more from its iterate of least
    residual with (Q, Z) renewed there: one block of forward differences of Newton's step
    (:func:`dmi.analysis.newton.fd_eps`) from qr(Z), the dominant subspace of the derivative
    the iteration actually sees (:func:`ritz`); then Newton (GMRES) from zp (not from an
    iterate: near a period doubling, Newton-Picard may have headed for the other branch that
    crosses the first step's hyperplane p = p1).  Returns (z, iterations, which): the iterations
    of all tries, and ``newton-picard`` or ``newton`` (which converged)."""
    done = 0   # Newton-Picard iterations spent, counted in the step's (the step control's)
    k = maps.k
    if dominant is not None:
        z = zp
        Q, Z = dominant
        for renew in (False, True):
            try:
                if renew:
                    F, x = maps.of(z[-k:]), z[:-k]
                    if F.dim != x.size:
                        break
                    _, Q, Z = ritz(F, x, max(1, Q.shape[1] - 2), start=Z, eps=fd_eps(x),
                                   central=False)
                z, its = _newton_picard(maps, zp, t, tol, ds, Q, Z, z)
                return z, done + its, "newton-picard"
            except _Slow as e:
                done += e.iterations
                if e.z is None:
                    break
                z = e.z
    z, its = _corrector(maps, zp, t, tol, max_iter, ds)
    return z, done + its, "newton"


def _corrector(maps: _Maps, zp: np.ndarray, t: np.ndarray, tol: float, max_iter: int,
               ds: float) -> tuple[np.ndarray, int]:
    """Newton (:func:`dmi.analysis.newton.bordered_newton`) on (F_q(x) - x, the family's
    equations, <w t, z - zp>) from the predictor zp; returns (z, iterations).  ShootingError
    when an iterate strays more than ds from the predictor (weighted norm): the step is then
    too long for the predictor, and another branch may lie on the hyperplane."""
    w = maps.weights(zp.size)
    dim = zp.size - maps.k

    def far(z: np.ndarray) -> None:
        d = z - zp
        if math.sqrt(float(np.dot(w * d, d))) > ds:
            raise ShootingError(f"corrector strayed {math.sqrt(float(np.dot(w * d, d))):.3g} > "
                                f"ds = {ds:.3g} from the predictor at p = {float(z[-1])!r}", [])

    def of(q: np.ndarray) -> StepMap:
        F = maps.of(q)
        if F.dim != dim:
            raise ShootingError(f"the state grew to {F.dim} values at p = {float(q[-1])!r}", [])
        return F

    z, res = bordered_newton(of, zp, maps.k, lambda z: _borders(maps, z, zp, t), tol=tol,
                             max_iter=max_iter, what=f"corrector near p = {float(zp[-1])!r}",
                             steps=maps.col_steps(zp[-maps.k:]), check=far)
    return z, len(res) - 1


def _corner(maps: _Maps, z: np.ndarray, t: np.ndarray, ds: float, direction: float,
            tol: float, max_iter: int, dominant: tuple[np.ndarray, np.ndarray] | None,
            sections: int) -> tuple | None:
    """Past a corner of the branch (a stick onset or a grazing, where the map's derivative jumps
    and the secant's hyperplane may miss the branch's new piece): natural steps from z, first in
    p (the orbit at p(z) + s delta, p fixed, towards p_end first), then in the state with p free
    (the orbit on the hyperplane s delta along the tangent's state part: the new piece may be
    vertical, as a branch of orbits born at a nonsmooth Hopf point is), delta = ds and 4 ds; the
    first that converges ahead of z along the branch (<w t, z_new - z> > 0) is taken.  None if
    none does."""
    w = maps.weights(z.size)
    e_p = np.zeros(z.size)
    e_p[-1] = 1.0
    t_x = t.copy()
    t_x[-1] = 0.0
    nx = math.sqrt(float(np.dot(w * t_x, t_x)))
    tries = [(e_p * sign * delta, e_p) for delta in (ds, 4 * ds) for sign in (direction, -direction)]
    if nx > 0:
        t_x /= nx
        tries += [(t_x * sign * delta, t_x) for delta in (ds, 4 * ds) for sign in (1.0, -1.0)]
    for step, normal in tries:
        try:
            got = _correct(maps, z + step, normal, tol, max_iter + 4, math.inf, dominant,
                           sections)
        except Exception:   # the model's, the map's or the corrector's failure
            continue
        if float(np.dot(w * t, got[0] - z)) > 0:
            return got
    return None


def _first_tangent(maps: _Maps, z: np.ndarray, direction: float) -> np.ndarray:
    """The branch's unit tangent (weighted norm) at its first point z: the null vector of the
    bordered Jacobian [[D_xF - I, F_q], [the family's rows]], from one bordered solve with the
    extra row r . dz = 1, r = e_p + the state's deviation from its mean (not orthogonal to a
    tangent that moves p, nor to one that only scales the orbit, as on a branch leaving a Hopf
    point vertically).  Oriented towards p_end, or, where dp/ds is below VERTICAL, to a growing
    deviation."""
    k = maps.k
    x = z[:-k]
    F = maps.of(z[-k:])
    Fx = F(x)
    g, rows = maps.conditions(z)
    dev = x - np.mean(x)
    r = np.zeros(z.size)
    r[:-k] = dev / max(float(np.linalg.norm(dev)), 1e-300)
    r[-1] = 1.0
    t, lin = bordered_step(F, x, Fx, _columns(maps, z, Fx), np.vstack([rows, r]),
                           np.concatenate([np.zeros(len(g)), [-1.0]]), rtol=1e-8)
    if lin > 1e-2:
        raise ShootingError(f"no tangent at the branch's start (GMRES relative residual "
                            f"{lin:.2g}): a singular point", [])
    w = maps.weights(z.size)
    t = t / math.sqrt(float(np.dot(w * t, t)))
    if abs(t[-1]) > VERTICAL:
        return t if t[-1] * direction > 0 else -t
    return t if float(np.dot(t[:-k], dev)) > 0 else -t


def continue_orbit(orbit: Orbit, p_end: float, step: float = 0.05, *, max_points: int = 200,
                   min_step: float | None = None, max_step: float | None = None,
                   multipliers: int = 6, tol: float = 1e-10, max_iter: int = 8,
                   sections: int = 1, margins: bool = True,
                   period: Callable[[float], float] | None = None,
                   refine: bool = False) -> Branch:
    """Continues a periodic orbit in its parameter by pseudo-arclength, with its events.

    The corrector is Newton-Picard on the previous point's dominant subspace, Newton-GMRES when
    that contracts too slowly (see the module); every point gets Floquet multipliers and a stick
    profile; events (fold, period doubling, torus, stick onset, grazing) are detected between
    consecutive points, and stick events located along the branch.  Corners (stick onset,
    grazing) are passed by natural steps when the secant's hyperplane misses the branch's new
    piece.

    Parameters
    ----------
    orbit : Orbit
        The start, from :func:`periodic_orbit` or :func:`hopf_orbit`.  An autonomous orbit
        (``orbit.autonomous``) has its period as an unknown: h = P / M with M = orbit.steps, N =
        ceil(tau / h) changing along the branch (the states hold room for h down to 60 % of the
        start's), a phase condition through the previous point, and its phase multiplier left out
        of ``stable`` and of the events.
    p_end : float
        Where to stop (finite, not orbit.p).
    step : float
        The first point's step in p; then arclengths in the norm sqrt(|dx|^2 / dim + dp^2) (p
        and RMS state units; an autonomous branch weighs the period's change as p's).
    max_points : int
        Points at most.
    min_step, max_step : float, optional
        Step bounds (default step / 1000 and 4 step).
    multipliers : int
        Floquet multipliers a point (they also make the Newton-Picard basis; 0: Newton-GMRES).
    tol : float
        The corrector's tolerance.
    max_iter : int
        Newton iterations a step.
    sections : int
        The orbit spans this many forcing periods (a period-doubled branch: 2), for
        ``BranchPoint.section``.
    margins : bool
        Compute the points' margins (no extra evaluation; False leaves them NaN).
    period : callable, optional
        None keeps the period M h (make(p) keeps h); a function p -> period (time units; a forced
        orbit in its frequency w: ``period=lambda w: 2 * math.pi / w``) keeps M and gives the model
        the step h = period(p) / M through ``make(p, h=...)``.  Must be None for an autonomous
        orbit.
    refine : bool
        Place period-doubling and torus events from the refined multipliers of their two points
        (:func:`dmi.analysis.refine_orbit`: the equation's, O(h^2)); the model must take h.

    Returns
    -------
    Branch
        ``kind`` "orbits" or "autonomous"; ``points``, ``events``, ``status``.  A corrector that
        fails at the smallest step, or the model failing there, ends the branch with that
        ``status``: it does not raise.

    Raises
    ------
    ValueError
        A bad ``step``, ``p_end``, ``max_points`` or ``period``; ``period`` for an autonomous
        orbit; ``period(orbit.p)`` not the orbit's period.
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: must be finite and > 0 (p units)")
    if not math.isfinite(p_end) or p_end == orbit.p:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from the orbit's "
                         f"p = {orbit.p!r}")
    if max_points < 2:
        raise ValueError(f"max_points = {max_points!r}: must be >= 2")
    direction = 1.0 if p_end >= orbit.p else -1.0
    min_step = step / 1000 if min_step is None else min_step
    max_step = 4 * step if max_step is None else max_step
    lo, hi = sorted((orbit.p, float(p_end)))
    n = orbit.u.shape[1]
    x0 = np.array(orbit.state)
    if orbit.autonomous:
        if period is not None:
            raise ValueError("period=...: an autonomous orbit's period is an unknown of the "
                             "branch; continue it with period=None")
        tau = build(orbit.make, orbit.p).tau
        rows = max(orbit.rows or x0.size // n, math.ceil(tau / (0.6 * orbit.h)) + 1)
        maps: _Maps = _AutoMaps(orbit.make, orbit.steps, orbit.h, rows)
        F0 = maps(orbit.p)
        if F0.dim != x0.size:
            x0 = F0.extend(x0)
        maps.reference(np.concatenate([x0, [orbit.h, orbit.p]]), F0.trajectory(x0))
        q0 = np.array([orbit.h, orbit.p])
    else:
        if period is not None:
            if not callable(period):
                raise ValueError(f"period = {period!r}: give a function p -> period (time "
                                 "units)")
            P0 = _Maps(orbit.make, orbit.steps, orbit.h, 0, period).step(orbit.p) * orbit.steps
            if abs(P0 - orbit.period) > 1e-9 * orbit.period:
                raise ValueError(f"period(p = {orbit.p!r}) = {P0!r} but the orbit's period is "
                                 f"{orbit.period!r} (= {orbit.steps} steps h = {orbit.h!r})")
        probe = _Maps(orbit.make, orbit.steps, orbit.h, 0, period)
        # rows for the whole range: N may grow with p (tau with a fixed h, or h with the
        # period); probe both ends
        rows = max(orbit.rows or x0.size // n, probe.build(orbit.p).N + 1)
        try:
            rows = max(rows, probe.build(float(p_end)).N + 1)
        except Exception:
            pass  # make refuses p_end: the branch will stop where make does
        rows += max(2, rows // 50)  # room for a corrector a little beyond the ends
        maps = _Maps(orbit.make, orbit.steps, orbit.h, rows, period)
        F0 = maps(orbit.p)
        if F0.dim != x0.size:
            x0 = F0.extend(x0)
        q0 = np.array([orbit.p])
    k = maps.k
    auto = maps.autonomous
    warm: list = [None]
    pts = [_point(F0, x0, multipliers, sections, direction, orbit.iterations, margins, warm,
                  autonomous=auto)]
    events: list[Event] = []
    status = "max_points reached"
    z = np.concatenate([x0, q0])
    # the first step: natural continuation in p (the hyperplane p = p1)
    ds = step
    z_prev = z
    t_p = np.zeros(z.size)
    t_p[-1] = 1.0
    t0 = _first_tangent(maps, z, direction) if auto else None
    while True:
        if t0 is None:
            zp, tc, far = z.copy(), t_p, math.inf
            zp[-1] = orbit.p + direction * ds
        else:
            zp, tc, far = z + ds * t0, t0, ds
        try:
            z, its, how, terms = _correct(maps, zp, tc, tol, max_iter + 4, far, warm[0],
                                          sections)
            break
        except Exception as e:   # the model's, the map's or the corrector's failure
            ds /= 2
            if ds < min_step:
                return Branch(pts, events, f"first step failed: {e}", orbit.make, orbit.steps,
                              orbit.h, maps.rows, sections, period,
                              "autonomous" if auto else "orbits")
    d = z - z_prev
    dpds = float(d[-1]) / math.sqrt(float(np.dot(maps.weights(z.size) * d, d)))
    pts[0].dpds = dpds if t0 is None else float(t0[-1])
    pts.append(_point(maps.of(z[-k:]), z[:-k], multipliers, sections, dpds, its, margins,
                      warm, how, terms, auto))
    maps.reference(z, terms[0])
    events += _events(pts[-2], pts[-1], 1, auto)
    while len(pts) < max_points:
        if (pts[-1].p - p_end) * direction >= -1e-7 * max(1.0, abs(p_end)):
            status = f"reached p_end = {p_end!r}"
            break
        if pts[-1].p < lo - 1e-7 * max(1, abs(lo)) or pts[-1].p > hi + 1e-7 * max(1, abs(hi)):
            status = f"left the range [{lo!r}, {hi!r}] after a fold"
            break
        w = maps.weights(z.size)
        sec = z - z_prev
        t = sec / math.sqrt(float(np.dot(w * sec, sec)))
        cornered = False
        while True:
            zp, tc = z + ds * t, t
            # do not overshoot p_end: the last step ends on the hyperplane p = p_end (on the
            # secant's, the curvature would leave it short, and one more step repeat the point)
            if (zp[-1] - p_end) * direction > 0 and abs(t[-1]) > 0.5:
                zp, tc = z + ((p_end - z[-1]) / t[-1]) * t, t_p
            try:
                zn, its, how, terms = _correct(maps, zp, tc, tol, max_iter, ds, warm[0],
                                               sections)
                break
            except Exception as e:   # the model's, the map's or the corrector's failure
                if tc is t_p:   # aimed at p_end: halve the step actually taken
                    ds = min(ds, abs((p_end - z[-1]) / t[-1]))
                ds /= 2
                if ds < step / 8 and not cornered:
                    cornered = True
                    got = _corner(maps, z, t, ds, direction, tol, max_iter, warm[0], sections)
                    if got is not None:
                        zn, its, how, terms = got
                        break
                if ds < min_step:
                    status = f"corrector failed at the smallest step {min_step!r} near p = " \
                             f"{float(z[-1])!r}: {e}"
                    zn = None
                    break
        if zn is None:
            break
        z_prev, z = z, zn
        d = z - z_prev
        dpds = float(d[-1]) / math.sqrt(float(np.dot(w * d, d)))
        pts.append(_point(maps.of(z[-k:]), z[:-k], multipliers, sections, dpds, its, margins,
                          warm, how, terms, auto))
        maps.reference(z, terms[0])
        for e in _events(pts[-2], pts[-1], len(pts) - 1, auto):
            if e.kind == "fold":
                e = _refine_fold(pts[-3:], e)
            elif e.kind in ("stick-onset", "grazing"):
                e = _locate_stick(maps, pts[-2], pts[-1], e, tol, max_iter)
                maps.reference(z, terms[0])
            events.append(e)
        easy = its <= (6 if how == "newton-picard" else 3)
        ds = min(max_step, ds * 1.5) if easy else ds
    if refine:
        for e in events:
            if e.kind in ("period-doubling", "torus"):
                _refined_event(maps, pts[e.index - 1], pts[e.index], e, multipliers, tol)
    return Branch(pts, events, status, orbit.make, orbit.steps, orbit.h, maps.rows, sections,
                  period, "autonomous" if auto else "orbits")


def _refined_event(maps: _Maps, a: BranchPoint, b: BranchPoint, e: Event, multipliers: int,
                   tol: float) -> None:
    """e.p from the test function of the refined multipliers at a and b (linear in p through
    them; up to a spacing of the points beyond them), the phase multiplier left out of an
    autonomous branch's."""
    f = []
    for q in (a, b):
        z = maps.z_of(q)
        F = maps.of(z[-maps.k:])
        o = make_orbit(F, q.state, [0.0], multipliers, maps.autonomous)
        mu = refine_orbit(o, tol=tol).multipliers
        f.append(_test_function(e.kind, phase_free(mu) if maps.autonomous else mu))
    w = f[0] / (f[0] - f[1]) if f[0] != f[1] else math.nan
    if 0 <= w <= 1:
        e.p = a.p + (b.p - a.p) * w
        e.detail += " (placed from refined multipliers)"
    elif -1 <= w <= 2:   # the equation's event lies up to a point spacing beyond the scheme's
        e.p = a.p + (b.p - a.p) * w
        e.detail += (" (placed from refined multipliers, extrapolated beyond the points: the "
                     "scheme's event is more than a step of the branch off the equation's)")
    else:
        e.detail += (" (the refined multipliers do not change sign near the points: placed "
                     "from the scheme's)")


def period_doubled_orbit(branch: Branch, event: Event, *, amplitudes: tuple[float, ...] =
                         (0.03, 0.1, 0.3, 1.0), multipliers: int = 6, tol: float = 1e-10
                         ) -> Orbit:
    """The period-2M orbit born at a ``period-doubling`` event of a forced branch.

    At the point of the event's pair where the M-periodic orbit has a multiplier < -1 (its
    unstable side, where a supercritical doubling's orbit lives) the M-periodic state x is
    perturbed along the multiplier's Ritz vector v (|v|_inf = 1), x + a A v, A the orbit's
    amplitude, a from ``amplitudes`` (smallest first: the orbit born at the event is the nearest),
    and shot with period 2 M h; the first solution that is not the M-periodic orbit is returned.
    Continue it with ``continue_orbit(..., sections=2 * branch.sections)``, and
    ``period=lambda p: 2 * P(p)`` for a branch continued with ``period=P``.

    Parameters
    ----------
    branch : Branch
        A forced branch from :func:`continue_orbit`.
    event : Event
        One of its ``period-doubling`` events.
    amplitudes : tuple of float
        The relative kicks tried.
    multipliers : int
        Floquet multipliers of the orbit returned.
    tol : float
        Newton's tolerance.

    Returns
    -------
    Orbit
        The period-doubled orbit.

    Raises
    ------
    ValueError
        The event is not a period doubling.
    ShootingError
        No period-doubled orbit found (what each kick gave is listed).
    """
    if event.kind != "period-doubling":
        raise ValueError(f"event {event.kind!r}: expected a 'period-doubling' event")
    a, b = branch.points[event.index - 1], branch.points[event.index]
    q = a if np.any(a.multipliers.real < -1) else b
    maps = _Maps(branch.make, branch.steps, branch.h, branch.rows, branch.period)
    F = maps(q.p)
    x = F.extend(q.state)
    _, Q, Z = ritz(F, x, 6)
    mu, Y = np.linalg.eig(Q.T @ Z)   # Ritz pairs: the eigenvector Q y
    j = int(np.argmin(np.abs(mu + 1) + 10 * np.abs(mu.imag)))
    v = (Q @ Y[:, j]).real
    v /= np.max(np.abs(v))
    amp = max(float(np.max(q.amplitude)), 0.1 * max(1.0, float(np.max(np.abs(x)))))
    make = branch.make
    if branch.period is not None:   # make(p) at the branch's step period(p) / M unless h is given
        def make(p: float, h: float | None = None) -> Solver:
            return branch.make(p, h=maps.step(p) if h is None else h)  # type: ignore[call-arg]
    tried = []
    for s in amplitudes:
        try:
            o = periodic_orbit(make, q.p, 2 * branch.steps * F.h, x + s * amp * v,
                               rows=F.L, tol=tol, multipliers=multipliers)
        except ShootingError as e:
            tried.append(f"a = {s}: {e}")
            continue
        if np.max(np.abs(F(o.state) - o.state)) > 1e-6 * max(1.0, amp):
            return o
        tried.append(f"a = {s}: converged to the M-periodic orbit")
    raise ShootingError(f"no period-doubled orbit at p = {q.p!r} (multiplier {mu[j]:.4g}): "
                        + "; ".join(tried), [])


__all__ = ["Branch", "BranchPoint", "Event", "continue_orbit", "period_doubled_orbit"]
