# The collocation equations of a periodic orbit of the equation: the model's terms, the layout of
# the unknowns, the residual with its sparse Jacobian, Newton's method on them, and a solution's
# inequalities checked on a fine grid.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The collocation system of :mod:`dmi.analysis.collocation.collocate`; private to the package.

The equation is u' + A(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0.  The unknowns are the node
values of the periodic piecewise polynomial (:mod:`dmi.analysis.collocation.mesh`), the switching
times b_1 < ... < b_S of the signature (:mod:`dmi.analysis.collocation.signature`) and, for an
autonomous orbit, the period T.  The period is cut into pieces at 0, the b's, the points (b_k + c)
mod T the memory carries them to, and T; the mesh of each piece is a fixed set of fractions of it,
so the mesh moves with the b's and T.  The equations: at the m Gauss points of each interval
u' + f + int H u + (alpha_i sign on slip components) = 0, a held component (stuck, on a face) held
at its value instead; one switching condition at each b_k; for an autonomous orbit the integral
phase condition int_0^1 <u(theta T), r'(theta)> d theta = 0 against a reference orbit r.

The Jacobian's columns of the node values are exact (f_u by central differences of the model's
rhs), T's exact for a smooth autonomous orbit, the b's exact along the mesh's motion
(:func:`switch_columns`, T's with switches too; f's t derivative of a forced orbit and the
phase condition's row by differences).
"""
from __future__ import annotations

import functools
import warnings
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ..._solver import Solver
from ..core.model import FD_STEP, ManyRhs
from .fold import Fold, exp_sum, fold_of, folding
from .mesh import (STEEP, Basis, DelayPlan, Kernel, Locator, Near,
                   delay_matrix, delay_matrix_separable, folded_matrix, history_locator,
                   history_rows, interval_of, periodic_locator, point_matrix)
from .signature import HI, LO, SLIP_NEG, SLIP_POS, STUCK, Signature, violations
from ..core.newton import Converge, NewtonOptions, Search, ShootingError, newton_loop

#: Quadrature nodes a piece of the delay integral: m + QUAD_EXTRA (exact for H u with u of
#: degree m and H of degree m + 2 QUAD_EXTRA - 1 on the piece; the error h^(2m + 2 QUAD_EXTRA + 1)
#: a piece stays below the collocation's h^(2m) at the mesh points).
QUAD_EXTRA = 1
#: Iterations at the residual's rounding floor without a halving correction after which a
#: solve that reports its accuracy stops (:func:`solve`).
FLOOR_ITERATIONS = 3
#: Delay matrices a Terms keeps (the most recently used): a Newton loop at a fixed mesh (a forced
#: orbit without switches) builds its matrix once, and the monodromy operator's once for its
#: multipliers and eigenfunction.
DELAY_CACHE = 6
#: Quadrature nodes of the delay plans a Terms keeps, in all (10 bytes each with one kernel
#: entry, 28 with four: at most 112 MB at n = 2 with a full kernel; measured, m = 4); a larger
#: plan is used once and not kept.
PLAN_NODES = 4e6
#: A mesh whose intervals within one piece are this factor apart or more is graded
#: (:meth:`Layout.interval_ratio`: the relaxation oscillation's equidistributed meshes 2 to 3 on
#: 16 to 24 intervals, 5 to 136 from 48 on; van der Pol's at eps = 1 1.2 to 3.9, a stick-slip
#: belt's 1.03): its Jacobian is factored in COLAMD's column order (:func:`factored`), and its
#: collocation checked (adapt.checked).
GRADED = 6.0
#: The step of f's t derivative in the switching times' columns of a forced orbit (five-point
#: differences), relative to the period: truncation and rounding both near 1e-13 relative for a
#: forcing of the orbit's own frequency.
FT_STEP = 2e-4
#: Points a mesh interval of the grid on which a solution's inequalities are checked
#: (:func:`check_inequalities`).
CHECK_POINTS = 8


class CollocationWarning(RuntimeWarning):
    """A collocated orbit's verdict that could not be verified (its stability), or an order
    the method cannot reach (a kernel's jump at a lag not declared)."""


class Terms:
    """The equation's terms of a model at p, read through the Solver's public accessors.

    Parameters
    ----------
    solver : dmi.Solver
        The model at p (configured; its step is not used).
    jumps : sequence of float
        Lags in (0, tau) where the kernel jumps (cuts of the delay integral's pieces).

    Raises
    ------
    ValueError
        A user resolvent (``set_resolvent``): no A to collocate (use ``refine_orbit``); near
        cells whose kernel is not s^-beta C with a known beta (``set_kernel_near`` alone, or a
        ``near=`` kernel of ``set_kernel_fit`` other than the fit's PowerKernel); a jump outside
        (0, tau).
    """

    def __init__(self, solver: Solver, jumps: tuple[float, ...] = ()):
        if solver.resolvent_kind == "callback":
            raise ValueError("collocate: the model sets its own resolvent (set_resolvent): "
                             "collocation needs the operator A itself (set_friction, set_box or "
                             "none); use dmi.analysis.refine_orbit for this model")
        self.solver = solver
        self.n, self.tau = solver.n, float(solver.tau)
        alpha = solver.friction
        self.alpha = np.zeros(self.n) if alpha is None else np.asarray(alpha, dtype=float)
        box = solver.box
        self.lo = np.full(self.n, -np.inf) if box is None else np.asarray(box[0], dtype=float)
        self.hi = np.full(self.n, np.inf) if box is None else np.asarray(box[1], dtype=float)
        self.terms = solver.kernel_terms
        self.kind = solver.kernel_kind
        self.has_rhs = solver.has("rhs")
        self._many = ManyRhs(solver)
        rate = float(np.max(-self.terms[0], initial=0.0)) if self.kind == "exp" else 0.0
        self.H = Kernel(self._far, near_part(solver), kernel_jumps(jumps, self.tau),
                        rate if rate * self.tau > STEEP else 0.0)
        self._delays: OrderedDict[tuple, tuple] = OrderedDict()
        self._plans: OrderedDict[tuple, DelayPlan] = OrderedDict()
        self._kept: dict[str, tuple[tuple, np.ndarray]] = {}
        #: Whether a periodic orbit's delay integral is folded onto one period (an exponential
        #: sum; :mod:`dmi.analysis.collocation.fold`).
        self.fold = bool(folding()) and self.kind == "exp"
        self._folds: tuple[float, Fold | None] | None = None
        #: Whether an exponential sum's far cells go by separated factors (the folded kernel's
        #: and a history's memory; False: every piece by its own quadrature, delay_matrix's).
        self.separable = True

    def folded(self, T: float) -> Fold | None:
        """The kernel folded onto the period T (:func:`~.fold.fold_of`; the last one kept), None
        when it does not fold (folding off, a callback kernel, tau <= T, near cells reaching T)."""
        if not self.fold:
            return None
        if self._folds is None or self._folds[0] != float(T):
            self._folds = (float(T), fold_of(self.H, self.terms, self.tau, T))
        return self._folds[1]

    def periodic_delay(self, times: np.ndarray, mesh: np.ndarray, T: float, basis: Basis,
                       rows: int, slope_of: np.ndarray | None = None,
                       loc: Locator | None = None) -> tuple[sp.csr_matrix, np.ndarray | None]:
        """delay_matrix's (G, T derivative) at ``times`` on the periodic orbit of ``mesh``
        (period T, ``rows`` node rows, ``slope_of`` its node values for the T derivative; ``loc``
        a periodic locator of other node rows, default the continuous one): when the kernel
        folds (:meth:`folded`), the folded kernel H_T over [0, T] (near part included), its later
        periods' tail over [0, delta] with a near part, and with ``slope_of`` the moment's period
        derivative; else over the whole memory."""
        f = self.folded(T)
        if loc is None and f is None:
            got = self._planned(np.asarray(times, dtype=float), np.asarray(mesh, dtype=float), T,
                                basis, rows, slope_of)
            if got is not None:
                return got
        if loc is None:
            loc = periodic_locator(mesh, basis.m)
        if f is None:
            return delay_matrix(times, self.tau, mesh, T, self.H, loc, basis, self.n, rows,
                                pattern=self.pattern, slope_of=slope_of)
        n, pattern = self.n, self.pattern
        if slope_of is None and self.separable:     # the far cells by products
            G, dT = folded_matrix(times, f, mesh, T, loc, basis, n, rows, pattern), None
        else:
            G, dT = delay_matrix(times, T, mesh, T, f.kernel, loc, basis, n, rows,
                                 pattern=pattern, slope_of=slope_of)
        near = f.kernel.near
        if f.tail is not None and near is not None:
            cuts = np.array([j for j in f.jumps if j < near.delta])
            Gt, dt = delay_matrix(times, near.delta, mesh, T, f.tail, loc, basis, n, rows,
                                  breaks=cuts, pattern=pattern, slope_of=slope_of)
            G = G + Gt
            if dT is not None:
                dT = dT + dt
        if slope_of is not None:
            dT = dT + delay_matrix(times, T, mesh, T, f.moment, loc, basis, n, rows,
                                   breaks=np.asarray(f.jumps), pattern=pattern,
                                   slope_of=slope_of)[1]
        return G, dT

    def _planned(self, times: np.ndarray, mesh: np.ndarray, T: float, basis: Basis, rows: int,
                 slope_of: np.ndarray | None) -> tuple[sp.csr_matrix, np.ndarray | None] | None:
        """delay_matrix's (G, T derivative) by a :class:`~.mesh.DelayPlan` (one kept for each
        count of times, mesh size, basis and rows: the last DELAY_CACHE, PLAN_NODES quadrature
        nodes in all at most; made anew where its crossings no longer fit); None for a kernel
        with a near part, jumps or grading."""
        H = self.H
        if H.near is not None or H.jumps or H.grading > 0:
            return None
        key = (times.size, mesh.size, type(basis), basis.m, basis.q, rows)
        plan = self._plans.get(key)
        got = plan.matrix(times, mesh, T, slope_of) if plan is not None else None
        if got is None:
            plan = DelayPlan(times, mesh, self.tau, T, self._entries, basis, self.n, rows,
                             self.pattern)
            got = plan.matrix(times, mesh, T, slope_of)
            self._plans.pop(key, None)
            if plan.nodes <= PLAN_NODES:
                self._plans[key] = plan
                while (len(self._plans) > DELAY_CACHE
                       or sum(q.nodes for q in self._plans.values()) > PLAN_NODES):
                    self._plans.popitem(last=False)
        else:
            self._plans.move_to_end(key)
        return got

    def memory_delay(self, times: np.ndarray, mesh: np.ndarray, T: float, loc: Locator,
                     basis: Basis, rows: int) -> sp.csr_matrix:
        """delay_matrix's G over the whole memory (a history's locator ``loc``): an exponential
        sum's far cells by products (:func:`~.mesh.delay_matrix_separable`; every piece by its
        own quadrature with ``separable`` off)."""
        if self.separable and self.kind == "exp":
            return delay_matrix_separable(times, self.tau, mesh, T, self.H, self.terms, loc,
                                          basis, self.n, rows, pattern=self.pattern)
        return delay_matrix(times, self.tau, mesh, T, self.H, loc, basis, self.n, rows,
                            pattern=self.pattern)[0]

    def delay(self, times: np.ndarray, mesh: np.ndarray, T: float, loc: Locator, basis: Basis,
              rows: int, history: History | None = None, extra: np.ndarray | None = None,
              periodic: bool = False) -> tuple[sp.csr_matrix, sp.csr_matrix | None]:
        """The delay integral's matrix (:meth:`memory_delay`) at the collocation times of
        ``mesh`` and at the ``extra`` times (the switching conditions' that need the memory) in
        one, kept for the last DELAY_CACHE meshes (it depends on the mesh, T, the basis, the
        extra times and the history's mesh only, not on the node values).  With ``periodic``
        (``loc`` the periodic locator of ``mesh``), folded onto one period
        (:meth:`periodic_delay`).

        Parameters
        ----------
        times : numpy.ndarray
            The collocation times of ``mesh``.
        mesh : numpy.ndarray
            The mesh of one period.
        T : float
            The period.
        loc : callable
            The locator of the node rows (periodic, or of ``history``).
        basis : Basis
            The basis.
        rows : int
            The node rows.
        history : History, optional
            The past of the monodromy operator's system (its mesh and periods enter the key).
        extra : numpy.ndarray, optional
            More times, after the collocation times.
        periodic : bool
            u is the periodic orbit of ``mesh`` (``loc`` its periodic locator, no history).

        Returns
        -------
        tuple
            G (len(times) n, rows n) and the rows of the extra times (len(extra) n, rows n;
            None without them).
        """
        more = np.empty(0) if extra is None else np.asarray(extra, dtype=float)
        key = (np.asarray(mesh, dtype=float).tobytes(), float(T), basis.m, basis.q, rows,
               None if history is None else (history.hist.tobytes(), history.periods),
               more.tobytes(), periodic and self.fold, self.separable)
        got = self._delays.get(key)
        if got is None:
            every = np.concatenate([times, more])
            if periodic and history is None:
                G = self.periodic_delay(every, mesh, T, basis, rows)[0]
            else:
                G = self.memory_delay(every, mesh, T, loc, basis, rows)
            cut = len(times) * self.n
            got = (G, None) if not more.size else (G[:cut], G[cut:])
            self._delays[key] = got
            if len(self._delays) > DELAY_CACHE:
                self._delays.popitem(last=False)
        else:
            self._delays.move_to_end(key)
        return got

    def _last(self, slot: str, t: np.ndarray, U: np.ndarray,
              compute: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
        """compute(t, U), kept (read-only) in ``slot`` for the next call with the same t and U
        (Newton's residual and Jacobian at one iterate, the monodromy's Jacobian at the orbit)."""
        t = np.asarray(t, dtype=float)
        U = np.asarray(U, dtype=float)
        key = (t.tobytes(), U.tobytes(), U.shape)
        kept = self._kept.get(slot)
        if kept is not None and kept[0] == key:
            return kept[1]
        out = compute(t, U)
        out.setflags(write=False)
        self._kept[slot] = (key, out)
        return out

    def f(self, t: np.ndarray, U: np.ndarray) -> np.ndarray:
        """f(t_c, U_c) (P, n) at the times t (P,) and states U (P, n) (read-only)."""
        return self._last("f", t, U, self._rhs)

    def f_anew(self, t: np.ndarray, U: np.ndarray) -> np.ndarray:
        """f(t_c, U_c) (P, n) computed anew, not kept (f at moved states, without displacing
        the kept f at the orbit)."""
        return self._rhs(np.asarray(t, dtype=float), np.asarray(U, dtype=float))

    def _rhs(self, t: np.ndarray, U: np.ndarray) -> np.ndarray:
        """f(t_c, U_c) (P, n) from the model's rhs (zero without one)."""
        if not self.has_rhs:
            return np.zeros_like(U)
        out = self._many(t, U)
        if not np.all(np.isfinite(out)):
            c = int(np.flatnonzero(~np.all(np.isfinite(out), axis=1))[0])
            raise ValueError(f"collocate: the model's rhs is not finite at t = {t[c]!r}, "
                             f"u = {U[c]!r}: {out[c]!r}")
        return out

    def fu(self, t: np.ndarray, U: np.ndarray) -> np.ndarray:
        """df/du (P, n, n) by central differences (step FD_STEP max(|u_j|, 1); read-only)."""
        return self._last("fu", t, U, self._jacobian)

    def _jacobian(self, t: np.ndarray, U: np.ndarray) -> np.ndarray:
        """df/du (P, n, n) by central differences of the model's rhs."""
        P, n = U.shape
        J = np.zeros((P, n, n))
        if not self.has_rhs:
            return J
        e = FD_STEP * np.maximum(np.abs(U), 1.0)                  # (P, n)
        shift = np.einsum("pj,jk->jpk", e, np.eye(n))              # (n, P, n): column j moved
        both = np.concatenate([U[None] + shift, U[None] - shift]).reshape(-1, n)
        F = self._rhs(np.tile(t, 2 * n), both).reshape(2, n, P, n)
        J[:] = np.transpose((F[0] - F[1]) / (2 * e.T[:, :, None]), (1, 2, 0))
        return J

    @property
    def pattern(self) -> np.ndarray:
        """(n, n) booleans: the kernel's entries that may be nonzero (an exponential sum's
        nonzero C or D entries; all for a callback)."""
        if self.kind == "exp":
            _, _, C, D = self.terms  # type: ignore[misc]
            near = self.H.near
            return (np.any(C != 0, axis=0) | np.any(D != 0, axis=0)
                    | (near.C != 0 if near is not None else False))
        return np.ones((self.n, self.n), bool)

    def same_memory(self, other: Terms) -> bool:
        """Whether other's delay integral is this one's: no kernel in both, or the same
        exponential sum, near part, jumps and tau (a callback kernel is never known to be)."""
        if self.kind != other.kind or self.tau != other.tau:
            return False
        if self.kind == "":
            return True
        a, b = self.H.near, other.H.near
        if self.kind != "exp" or (a is None) != (b is None) or self.H.jumps != other.H.jumps:
            return False
        if a is not None and not (a.delta == b.delta and a.beta == b.beta  # type: ignore[union-attr]
                                  and np.array_equal(a.C, b.C)):         # type: ignore[union-attr]
            return False
        return all(np.array_equal(x, y) for x, y in zip(self.terms, other.terms))

    @property
    def has_kernel(self) -> bool:
        """Whether the model has a kernel."""
        return self.kind != ""

    def _entries(self, s: np.ndarray) -> np.ndarray:
        """The entries of H(s) in :attr:`pattern` (P, entries), row by row, at the lags s (P,)
        (past a near part's delta)."""
        ia, ib = np.nonzero(self.pattern)
        if self.kind == "exp":
            a, b, C, D = self.terms  # type: ignore[misc]
            return exp_sum(s, a, b, C[:, ia, ib], D[:, ia, ib])
        return self._far(s)[:, ia, ib]

    def _far(self, s: np.ndarray) -> np.ndarray:
        """H(s) (P, n, n) at the lags s (P,) (past a near part's delta): an exponential sum in
        closed form, a callback one lag at a time."""
        s = np.asarray(s, dtype=float)
        if self.kind == "exp":
            return exp_sum(s, *self.terms)  # type: ignore[misc]
        out = np.array([self.solver.eval_kernel(float(x)) for x in s]).reshape(-1, self.n, self.n)
        if not np.all(np.isfinite(out)):
            raise ValueError("collocate: the model's kernel is not finite on (0, tau)")
        return out


def near_part(solver: Solver) -> Near | None:
    """The near part s^-beta C on (0, delta] of a model's kernel (None without near cells): beta
    is the exponent of the fit's PowerKernel (``Solver.kernel_fit``), C read from the near kernel
    at delta and checked to be the same at delta / 2, delta / 7 and delta / 50 (relative 1e-12).

    Raises
    ------
    ValueError
        Near cells without a fit whose kernel has an exponent, or a near kernel not of the form
        s^-beta C.
    """
    if not solver.has("kernel_near"):
        return None
    delta = float(solver.kernel_near_delta)
    fit = solver.kernel_fit
    beta = getattr(getattr(fit[0], "kernel", None), "beta", None) if fit is not None else None
    if beta is None:
        raise ValueError("collocate: the model's kernel has exact near cells (delta = "
                         f"{delta!r}) whose form s^-beta g(s) is not known: product integration "
                         "needs the exponent; set the kernel with Solver.set_kernel_fit of a fit "
                         "of a dmi.kernels.PowerKernel (fit.kernel keeps its beta), or use "
                         "refine_orbit")
    lags = delta / np.array([1.0, 2.0, 7.0, 50.0])
    K = np.array([solver.eval_kernel_near(float(x)) * x ** beta for x in lags])
    if not (np.all(np.isfinite(K)) and np.max(np.abs(K - K[0])) <= 1e-12 * max(
            float(np.max(np.abs(K[0]))), 1e-300)):
        raise ValueError("collocate: the near kernel (set_kernel_fit's near=, or "
                         f"set_kernel_near) is not s^-beta C with the fit's beta = {beta!r} on "
                         f"(0, {delta!r}]: product integration needs that form; give the fit's "
                         "own PowerKernel as the near kernel, or use refine_orbit")
    return Near(delta, float(beta), K[0])


def kernel_jumps(jumps: Any, tau: float) -> tuple[float, ...]:
    """The declared jumps, checked and sorted.

    Raises
    ------
    ValueError
        A lag not finite or outside (0, tau).
    """
    out = sorted(float(j) for j in np.atleast_1d(np.asarray(jumps, dtype=float)))
    bad = [j for j in out if not (0.0 < j < tau)]
    if bad:
        raise ValueError(f"collocate: kernel_jumps = {jumps!r}: {bad[0]!r} is not inside (0, "
                         f"tau = {tau!r}); give the lags in (0, tau) where H jumps")
    return tuple(out)


#: Lags at which a callback kernel is sampled for its jumps (:func:`undeclared_jumps`).
JUMP_SAMPLES = 1024
#: Halvings of a cell that brackets a jump (:func:`_bisect_jump`).
JUMP_HALVINGS = 50


def _bisect_jump(K: Kernel, lo: float, hi: float) -> tuple[float, float]:
    """(the lag where H's difference concentrates in [lo, hi], the difference left there): the
    cell bisected JUMP_HALVINGS times towards the half with the larger difference (3 kernel
    calls a halving); a jump keeps its size, a smooth H loses 2^-JUMP_HALVINGS of it."""
    for _ in range(JUMP_HALVINGS):
        mid = 0.5 * (lo + hi)
        v = K(np.array([lo, mid, hi])).reshape(3, -1)
        if np.max(np.abs(v[1] - v[0])) >= np.max(np.abs(v[2] - v[1])):
            hi = mid
        else:
            lo = mid
    left = float(np.max(np.abs(np.diff(K(np.array([lo, hi])).reshape(2, -1), axis=0))))
    return 0.5 * (lo + hi), left


def misdeclared_jumps(terms: Terms) -> list[tuple[float, float | None]]:
    """The declared lags where a callback kernel does not jump: (the lag, the jump found
    within a sampling cell of it, or None), each checked by :func:`_bisect_jump` on
    [lag - tau / JUMP_SAMPLES, lag + tau / JUMP_SAMPLES] (about 150 kernel calls a lag): no
    jump there (the difference falls below 1e-3 of the cell's), or a jump more than 1e-9 tau
    away.  Empty for an exponential sum (smooth: a declared lag is only a cut)."""
    if terms.kind != "callback":
        return []
    K, tau = terms.H, terms.tau
    w = tau / JUMP_SAMPLES
    big = float(np.max(np.abs(K(np.linspace(0.0, tau, 65)[1:]))))
    out: list[tuple[float, float | None]] = []
    for j in K.jumps:
        lo, hi = max(j - w, 0.5 * j), min(j + w, 0.5 * (j + tau))
        D = float(np.max(np.abs(np.diff(K(np.array([lo, hi])).reshape(2, -1), axis=0))))
        at, left = _bisect_jump(K, lo, hi)
        if D > 1e-12 * big and left > 1e-3 * D:
            if abs(at - j) > 1e-9 * tau:
                out.append((j, at))
        else:
            out.append((j, None))
    return out


def undeclared_jumps(terms: Terms, samples: int = JUMP_SAMPLES) -> list[float]:
    """Lags in (0, tau) where a callback kernel jumps and that are not declared (within 1e-9
    tau): H sampled at ``samples`` lags, a cell whose difference is 4 times both its
    neighbours' bisected (:func:`_bisect_jump`); a jump keeps 1e-3 of its first difference, a
    smooth H loses 2^-50 of it.  Kernel calls: ``samples`` and about 150 a suspect cell.  Empty
    for an exponential sum (smooth past its near part)."""
    if terms.kind != "callback":
        return []
    K = terms.H
    s = np.linspace(0.0, terms.tau, samples + 1)[1:]
    V = K(s).reshape(s.size, -1)
    D = np.max(np.abs(np.diff(V, axis=0)), axis=1)
    big = float(np.max(np.abs(V)))
    Dn = np.maximum(np.r_[0.0, D[:-1]], np.r_[D[1:], 0.0])
    found = []
    for c in np.flatnonzero((D > 4 * Dn) & (D > 1e-12 * big)):
        lo, hi = float(s[c]), float(s[c + 1])
        if any(lo - 1e-12 * terms.tau <= j <= hi + 1e-12 * terms.tau for j in K.jumps):
            continue   # a declared lag's cell: misdeclared_jumps bisects around it
        at, left = _bisect_jump(K, lo, hi)
        if left > 1e-3 * D[c] and not any(abs(at - j) <= 1e-9 * terms.tau for j in K.jumps):
            found.append(at)
    return found


@dataclass
class Layout:
    """The unknowns x = (node values (L m, n) row-major, b_1..b_S, T if autonomous) and the mesh.

    Attributes
    ----------
    m : int
        The degree.
    n : int
        The state's dimension.
    signature : Signature
        The modes of the pieces.
    fractions : list of numpy.ndarray
        Each piece's mesh as fractions 0 = f_0 < ... < f_k = 1 of the piece.
    autonomous : bool
        The period is an unknown.
    period : float
        The period of a forced orbit (unused when autonomous).
    carried : tuple of float
        Lags c at which the memory carries each switch forward: the pieces are also cut at
        (b_k + c) mod T (c = tau where H(tau) != 0: the delay integral's derivative jumps there),
        so that no interval holds a jump of a derivative of u.
    """
    m: int
    n: int
    signature: Signature
    fractions: list[np.ndarray]
    autonomous: bool
    period: float
    carried: tuple[float, ...] = ()
    basis: Basis = field(init=False)

    def __post_init__(self) -> None:
        self.basis = Basis(self.m, self.m + QUAD_EXTRA)

    @property
    def L(self) -> int:
        """The intervals."""
        return sum(len(f) - 1 for f in self.fractions)

    @property
    def rows(self) -> int:
        """The node rows, L m."""
        return self.L * self.m

    @property
    def S(self) -> int:
        """The switching times."""
        return self.signature.switches

    @property
    def size(self) -> int:
        """len(x)."""
        return self.rows * self.n + self.S + int(self.autonomous)

    def interval_ratio(self) -> float:
        """The largest ratio of two interval lengths within one piece of the mesh."""
        return max((float(np.max(np.diff(f)) / np.min(np.diff(f))) for f in self.fractions
                    if len(f) > 1), default=1.0)

    def split(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """(node values (L m, n), b (S,), T)."""
        k = self.rows * self.n
        T = float(x[-1]) if self.autonomous else self.period
        return x[:k].reshape(self.rows, self.n), x[k:k + self.S], T

    def ends(self, b: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:
        """The pieces' ends in order (0, the b_k, the carried (b_k + c) mod T, T) and the switch
        each moves with (k - 1 for b_k and its carried points, -1 for 0 and T)."""
        t, who, _ = self.ends_in_T(b, T)
        return t, who

    def ends_in_T(self, b: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`ends` and each end's motion with T at fixed b (1 for T, minus the wraps of a
        carried point (b_k + c) mod T, 0 for the others)."""
        S = self.S
        t = [0.0, T] + list(b) + [float((b[k] + c) % T) for k in range(S) for c in self.carried]
        who = [-1, -1] + list(range(S)) + [k for k in range(S) for _ in self.carried]
        dT = [0.0, 1.0] + [0.0] * S + [-float((b[k] + c) // T) for k in range(S)
                                       for c in self.carried]
        order = np.argsort(t, kind="stable")
        t, who, dT = np.asarray(t)[order], np.asarray(who)[order], np.asarray(dT)[order]
        if t[0] != 0.0 or t[-1] != T:          # a carried point at 0 or T: keep 0 and T outside
            inner = (t > 0) & (t < T)
            t = np.concatenate([[0.0], t[inner], [T]])
            who = np.concatenate([[-1], who[inner], [-1]])
            dT = np.concatenate([[0.0], dT[inner], [1.0]])
        return t, who, dT

    def bounds(self, b: np.ndarray, T: float) -> np.ndarray:
        """The pieces' ends (:meth:`ends`)."""
        return self.ends(b, T)[0]

    def mesh(self, b: np.ndarray, T: float) -> np.ndarray:
        """The L + 1 mesh points."""
        e = self.bounds(b, T)
        if e.size != len(self.fractions) + 1:
            raise Degenerate(f"a carried breakpoint left (0, T): {e.size - 1} pieces for "
                             f"{len(self.fractions)} meshes")
        parts = [e[j] + (e[j + 1] - e[j]) * f[:-1] for j, f in enumerate(self.fractions)]
        return np.concatenate(parts + [[T]])

    def piece_modes(self, b: np.ndarray, T: float) -> list[np.ndarray]:
        """The modes of the pieces: those of the segment holding each piece."""
        e = self.bounds(b, T)
        seg = np.searchsorted(b, 0.5 * (e[:-1] + e[1:]))
        pieces = self.signature.pieces()
        return [pieces[int(k)] for k in seg]

    def piece_of_interval(self) -> np.ndarray:
        """(L,): the piece of each interval."""
        return np.concatenate([np.full(len(f) - 1, j) for j, f in enumerate(self.fractions)])

    def node_motion(self) -> tuple[np.ndarray, np.ndarray]:
        """For each interval's m + 1 nodes (L, m + 1): d t / d (left end of its piece) and d t /
        d (right end) (the nodes move with their piece's ends)."""
        z = self.basis.nodes
        left, right = [], []
        for f in self.fractions:
            fr = f[:-1, None] + np.diff(f)[:, None] * z[None, :]
            left.append(1.0 - fr)
            right.append(fr)
        return np.concatenate(left), np.concatenate(right)

    def with_fractions(self, fractions: list[np.ndarray]) -> Layout:
        """The same layout on other meshes of its pieces."""
        return Layout(self.m, self.n, self.signature, fractions, self.autonomous, self.period,
                      self.carried)


class Degenerate(ValueError):
    """A piece's length went to zero or below (a segment vanishes)."""


@dataclass
class History:
    """A fixed past for the monodromy operator: ``periods`` copies of the mesh ``hist`` behind
    t = 0, with the node values ``phi`` (periods L (m + 1), n), each interval its own m + 1."""
    hist: np.ndarray
    periods: int
    phi: np.ndarray


def _held(mode: np.ndarray, terms: Terms) -> tuple[np.ndarray, np.ndarray]:
    """(P, n) masks of held components and their values, for modes (P, n)."""
    held = (mode == STUCK) | (mode == LO) | (mode == HI)
    value = np.where(mode == LO, terms.lo, np.where(mode == HI, terms.hi, 0.0))
    return held, np.nan_to_num(value)


def assemble(lay: Layout, terms: Terms, x: np.ndarray, ref: Callable[[np.ndarray], np.ndarray]
             | None, *, jacobian: bool = True, history: History | None = None
             ) -> tuple[np.ndarray, sp.csr_matrix | None, np.ndarray | None]:
    """The residual, its Jacobian's columns of the node values (sparse) and, for a smooth
    autonomous orbit, its column of T (exact; else None), at x.

    With ``history``, the system of one period forward from that past (the monodromy operator):
    node rows L m + 1 (u(T) too), then the past's rows; equations u(0) = phi(0-), the
    collocation and the switching conditions (no phase condition, T fixed).
    """
    m, n, basis = lay.m, lay.n, lay.basis
    V, b, T = lay.split(x)
    e = lay.bounds(b, T)
    if np.any(np.diff(e) <= 0) or not np.isfinite(T) or e.size != len(lay.fractions) + 1:
        raise Degenerate(f"a piece's length went to {np.min(np.diff(e)):.3g}: the switching "
                         f"times {b!r} (and their carried points) are out of order in (0, {T!r})")
    mesh = lay.mesh(b, T)
    h = np.diff(mesh)
    gz, gw = basis.gauss()
    tc = (mesh[:-1, None] + h[:, None] * gz[None, :]).ravel()
    if history is None:
        rows = lay.rows
        loc: Locator = periodic_locator(mesh, m)
        u = V.ravel()
    else:
        rows = history_rows(lay.L, m, history.periods)
        loc = history_locator(mesh, history.hist, m, history.periods)
        u = np.concatenate([V.ravel(), V[0], history.phi.ravel()])
    E, D = collocation_matrices(basis, h, n, rows, periodic=history is None)
    scaled = jacobian and lay.autonomous and history is None and lay.S == 0
    G, dI, Gb = None, None, None
    if terms.has_kernel and scaled:         # the T column's integral needs the node values
        G, dI = terms.periodic_delay(tc, mesh, T, basis, rows, slope_of=V)
    elif terms.has_kernel:                  # with the memory at the stick endings' b's
        G, Gb = terms.delay(tc, mesh, T, loc, basis, rows, history, b[force_switches(lay)],
                            periodic=history is None)
    Uc = (E @ u).reshape(-1, n)
    du = (D @ u).reshape(-1, n)
    r = du + terms.f(tc, Uc)
    if G is not None:
        r += (G @ u).reshape(-1, n)
    mode = np.repeat(np.array(lay.piece_modes(b, T))[lay.piece_of_interval()], m, axis=0)
    r += terms.alpha * ((mode == SLIP_POS).astype(float) - (mode == SLIP_NEG))
    held, value = _held(mode, terms)
    r = np.where(held, Uc - value, r)
    J = None
    if jacobian:
        J = D + fu_points(terms.fu(tc, Uc), tc, loc, basis, rows)
        if G is not None:
            J = J + G
        if np.any(held):
            hv = held.ravel().astype(float)
            J = sp.diags(1.0 - hv) @ J + sp.diags(hv) @ E
    dT = None
    if scaled:        # d r / d T with the nodes fixed in theta = t / T (an autonomous rhs)
        dT = np.where(held, 0.0, -du / T + (dI if dI is not None else 0.0)).ravel()
    extra_r, extra_J = [], []
    if history is not None:                        # u(0) = phi(0-): the last past node
        last = history_rows(lay.L, m, history.periods) - 1
        extra_r.append(V[0] - history.phi[-1])
        if jacobian:
            extra_J.append(sp.csr_matrix((np.r_[np.ones(n), -np.ones(n)],
                                          (np.r_[np.arange(n), np.arange(n)],
                                           np.r_[np.arange(n), last * n + np.arange(n)])),
                                         shape=(n, rows * n)))
    if lay.S:
        g, sw = _switch_conditions(lay, terms, b, mesh, T, loc, rows, u, jacobian, Gb)
        extra_r.append(g)
        if jacobian:
            extra_J.append(sw)
    if lay.autonomous and history is None and ref is not None:
        w = (h[:, None] * gw[None, :]).ravel() / T
        R = ref(tc / T)                                     # r'(theta_c) (P, n)
        extra_r.append(np.array([np.sum(w[:, None] * R * Uc)]))
        if jacobian:
            extra_J.append(sp.csr_matrix((w[:, None] * R).reshape(1, -1)) @ E)
    res = np.concatenate([r.ravel()] + extra_r)
    if jacobian:
        J = sp.vstack([J] + extra_J, format="csr")
        if history is None:
            J = J[:, :lay.rows * n]
    if dT is not None:                  # the phase condition does not move with T
        dT = np.concatenate([dT, np.zeros(res.size - dT.size)])
    return res, J, dT


def collocation_matrices(basis: Basis, h: np.ndarray, n: int, rows: int, periodic: bool
                         ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """(E, D): u and u' (d/dt) at the m Gauss points of each of the L intervals of lengths h
    (P = L m points, (P n, rows n) each) from the node rows (interval i's nodes i m .. i m + m,
    wrapped mod L m when ``periodic``): the basis at the Gauss points, the same for every
    interval, with the derivative's over h_i; each row's m + 1 entries written in place (E and
    D's pattern kept for each layout, D's values divided by h anew)."""
    E, D, per = _collocation_pattern(basis, h.size, n, rows, periodic)
    D = D.copy()
    D.data /= np.repeat(h, per)
    return E, D


@functools.lru_cache(maxsize=16)
def _collocation_pattern(basis: Basis, L: int, n: int, rows: int, periodic: bool
                         ) -> tuple[sp.csr_matrix, sp.csr_matrix, int]:
    """(E, D for intervals of length 1, the stored entries an interval) of
    :func:`collocation_matrices` (E read-only: shared by every caller)."""
    m = basis.m
    gz = basis.gauss()[0]
    P = L * m
    g = np.tile(np.arange(m), L)
    cols = np.repeat(np.arange(L), m)[:, None] * m + np.arange(m + 1)[None, :]
    if periodic:
        cols %= L * m
    index = np.broadcast_to(cols[:, None, :] * n + np.arange(n)[None, :, None],
                            (P, n, m + 1)).ravel()
    ptr = np.arange(0, P * n * (m + 1) + 1, m + 1)
    shape = (P * n, rows * n)
    ev = np.broadcast_to(basis.values(gz)[g][:, None, :], (P, n, m + 1)).ravel()
    dv = np.broadcast_to(basis.derivatives(gz)[g][:, None, :], (P, n, m + 1)).ravel()
    E = sp.csr_matrix((ev, index, ptr.copy()), shape=shape)
    D = sp.csr_matrix((dv, index.copy(), ptr), shape=shape)
    if periodic and L < 2:               # one interval: its first and last node are one row
        E.sum_duplicates()
        D.sum_duplicates()
    for a in (E.data, E.indices, E.indptr):
        a.setflags(write=False)
    return E, D, D.nnz // L


def fu_points(fu: np.ndarray, tc: np.ndarray, loc: Locator, basis: Basis, rows: int
              ) -> sp.csr_matrix:
    """The sparse matrix (P n, rows n) of f_u(t_c, u(t_c)) u(t_c) in the node values: the
    block-diagonal f_u (P, n, n) times the point values' matrix, its entries f_u[c, a, b] B_k(z_c)
    at row c n + a, column cols[c, k] n + b, built in one go."""
    P, n, _ = fu.shape
    _, z, cols = loc(tc)
    B = basis.values(z)                                              # (P, m + 1)
    val = fu[:, :, :, None] * B[:, None, None, :]                     # (P, a, b, k)
    r = np.broadcast_to((np.arange(P) * n)[:, None, None, None]
                        + np.arange(n)[None, :, None, None], val.shape)
    c = np.broadcast_to(cols[:, None, None, :] * n + np.arange(n)[None, None, :, None],
                        val.shape)
    return sp.csr_matrix((val.ravel(), (r.ravel(), c.ravel())), shape=(P * n, rows * n))


def force_switches(lay: Layout) -> list[int]:
    """The indices k - 1 of the switches b_k whose condition is a net force (a stick ending, a
    contact ending): those that need the memory at b_k."""
    out = []
    for k in range(1, lay.S + 1):
        _, before, after = lay.signature.switch(k)
        if not (before in (SLIP_POS, SLIP_NEG) or after in (LO, HI)):
            out.append(k - 1)
    return out


def _switch_conditions(lay: Layout, terms: Terms, b: np.ndarray, mesh: np.ndarray, T: float,
                       loc: Locator, rows: int, u: np.ndarray, jacobian: bool,
                       Gb: sp.csr_matrix | None = None
                       ) -> tuple[np.ndarray, sp.csr_matrix | None]:
    """The switching conditions at b_1..b_S (S,) and their rows in the node values (S, rows n),
    the values at all the b's and the memory at those that need it each in one call (``Gb``:
    the memory's rows at the :func:`force_switches`' b's, built with the collocation's): the
    component reaching 0 or a face (a slip ending, a contact starting), or its net force
    -f_i - (int H u)_i reaching +-alpha_i (a stick ending) or 0 (a contact ending)."""
    n, S = lay.n, lay.S
    t = np.asarray(b, dtype=float)
    Eb = point_matrix(t, loc, lay.basis, mesh, n, rows)
    ub = (Eb @ u).reshape(S, n)
    switch = [lay.signature.switch(k) for k in range(1, S + 1)]
    g = np.empty(S)
    out: list = [None] * S
    force = []
    for k, (i, before, after) in enumerate(switch):
        if before in (SLIP_POS, SLIP_NEG) or after in (LO, HI):
            target = terms.lo[i] if after == LO else terms.hi[i] if after == HI else 0.0
            g[k] = ub[k, i] - target
            out[k] = Eb[k * n + i]
        else:
            force.append(k)
    if force:
        tf = t[force]
        if Gb is None and terms.has_kernel:
            Gb = delay_matrix(tf, terms.tau, mesh, T, terms.H, loc, lay.basis, n, rows,
                              pattern=terms.pattern)[0]
        F = -terms.f(tf, ub[force]) - ((Gb @ u).reshape(-1, n) if Gb is not None else 0.0)
        fu = terms.fu(tf, ub[force]) if jacobian else None
        for j, k in enumerate(force):
            i, _, after = switch[k]
            target = terms.alpha[i] * (after == SLIP_POS) - terms.alpha[i] * (after == SLIP_NEG)
            g[k] = F[j, i] - target
            if jacobian:
                row = -(sp.csr_matrix(fu[j, i:i + 1]) @ Eb[k * n:(k + 1) * n])
                out[k] = row - Gb[j * n + i] if Gb is not None else row
    if not jacobian:
        return g, None
    return g, sp.vstack(out, format="csr")


def broken_locator(mesh: np.ndarray, m: int, history: History | None = None
                   ) -> tuple[Locator, int]:
    """The locator of a discontinuous piecewise polynomial on ``mesh`` (each interval its own
    m + 1 node rows, L (m + 1) of them), periodic, or with ``history``'s past behind t = 0 (its
    rows after, as :func:`history_locator` has them), and its node rows."""
    L = mesh.size - 1
    k = np.arange(m + 1)
    if history is None:
        T = float(mesh[-1])

        def periodic(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            i, z = interval_of(mesh, np.mod(t, T))
            return i, z, i[:, None] * (m + 1) + k[None, :]
        return periodic, L * (m + 1)
    inner = history_locator(mesh, history.hist, m, history.periods)
    shift = L * (m + 1) - (L * m + 1)

    def forward(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        i, z, cols = inner(t)
        front = np.asarray(t, dtype=float) >= 0
        cols = np.where(front[:, None], i[:, None] * (m + 1) + k[None, :], cols + shift)
        return i, z, cols
    return forward, L * (m + 1) + history.periods * L * (m + 1)


def f_t(terms: Terms, t: np.ndarray, U: np.ndarray, T: float) -> np.ndarray:
    """df/dt (len(t), n) at (t, U): five-point central differences of step FT_STEP T (one call
    of the model for the four shifts)."""
    e = FT_STEP * T
    P = len(t)
    F = terms.f_anew(np.concatenate([t + e, t - e, t + 2 * e, t - 2 * e]),
                     np.tile(U, (4, 1))).reshape(4, P, -1)
    return (8.0 * (F[0] - F[1]) - (F[2] - F[3])) / (12.0 * e)


def mesh_motion(lay: Layout, ends: np.ndarray) -> np.ndarray:
    """(K, L, m + 1): each interval node's motion when the pieces' ends move by ``ends`` (K,
    ends) (a node moves with its piece's two ends, linearly)."""
    left, right = lay.node_motion()
    piece = lay.piece_of_interval()
    return left[None] * ends[:, piece, None] + right[None] * ends[:, piece + 1, None]


def switch_columns(lay: Layout, terms: Terms, x: np.ndarray, ref: Callable | None,
                   history: History | None = None, period: bool = False) -> np.ndarray:
    """The residual's columns of the switching times (residual size, S), and with ``period``
    (a periodic autonomous orbit) T's after them: exact but for f's t derivative (:func:`f_t`, a
    forced orbit) and the phase condition's row (differences).  Each b_k's column is
    :func:`motion_columns` of its motion (it and the points the memory carries it to); T's is
    its derivative with every time scaled (theta = t / T fixed: u' by -1 / T, the delay integral
    by (1 / T) int_0^tau s H(s) u'(t - s) ds, the phase condition not at all) plus the ends'
    motion with T at fixed b less their scaling's (one :func:`motion_columns` for all).  A
    history must continue the period (no jump in the past, nor between it and u(0)): its jumps'
    own motion terms are not in the columns."""
    V, b, T = lay.split(x)
    e, who, dT = lay.ends_in_T(b, T)
    S = lay.S
    force = np.asarray(force_switches(lay), dtype=int)
    ends = (who[None, :] == np.arange(S)[:, None]).astype(float)
    own = (np.arange(S)[:, None] == force[None, :]).astype(float)
    if period:
        ends = np.vstack([ends, (dT - e / T)[None, :]])
        own = np.vstack([own, -(b[force] / T)[None, :]])
    cols = motion_columns(lay, terms, x, ref, history, ends, own)
    if period:
        cols[:, -1] += _scaled_column(lay, terms, x, cols.shape[0])
    return cols


def _scaled_column(lay: Layout, terms: Terms, x: np.ndarray, size: int) -> np.ndarray:
    """The residual's derivative in T with every time scaled (theta = t / T fixed; the nodes
    held; the phase condition's row 0), of a periodic autonomous orbit with switches."""
    m, n, L = lay.m, lay.n, lay.L
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    h = np.diff(mesh)
    gz = lay.basis.gauss()[0]
    P = L * m
    force = force_switches(lay)
    times = np.concatenate([(mesh[:-1, None] + h[:, None] * gz[None, :]).ravel(), b[force]])
    dI = np.zeros((times.size, n))
    if terms.has_kernel:
        dI = terms.periodic_delay(times, mesh, T, lay.basis, lay.rows, slope_of=V)[1]
    one = V[(np.arange(L)[:, None] * m + np.arange(m + 1)[None, :]) % lay.rows]
    du = np.einsum("gk,lkn->lgn", lay.basis.derivatives(gz), one).reshape(P, n)
    du /= np.repeat(h, m)[:, None]
    dr = -du / T + dI[:P]
    mode = np.repeat(np.array(lay.piece_modes(b, T))[lay.piece_of_interval()], m, axis=0)
    dr[_held(mode, terms)[0]] = 0.0
    col = np.zeros(size)
    col[:P * n] = dr.ravel()
    for q, k in enumerate(force):
        col[P * n + k] = -dI[P + q, lay.signature.switch(k + 1)[0]]
    return col


def motion_columns(lay: Layout, terms: Terms, x: np.ndarray, ref: Callable | None,
                   history: History | None, ends: np.ndarray, own: np.ndarray) -> np.ndarray:
    """The residual's derivatives (residual size, K) along K motions of the pieces' ends
    (``ends`` (K, ends), the nodes keeping their values; ``own`` (K, the :func:`force_switches`'
    b's: stick and contact endings) their motion), exact but for f's t derivative (:func:`f_t`, a forced
    orbit) and the phase condition's (differences).

    At a fixed time the orbit changes by -nu u' (nu the time's motion, piecewise linear) and a
    collocation time t_c by nu(t_c); so the collocation row's u' scales by -nu'(t_c), f moves
    with t_c, and the delay integral by int_0^tau H(s) (nu(t_c) - nu(t_c - s)) u'(t_c - s) ds
    (the delay matrix of the discontinuous node values of u' and nu u', exact in the basis; a
    history's past does not move).  The stick endings' net force likewise at b_k."""
    m, n, L, K = lay.m, lay.n, lay.L, ends.shape[0]
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    h = np.diff(mesh)
    basis = lay.basis
    gz = basis.gauss()[0]
    one = V[(np.arange(L)[:, None] * m + np.arange(m + 1)[None, :]) % lay.rows]  # (L, m + 1, n)
    slope = np.einsum("ij,ljn->lin", basis.derivatives(basis.nodes), one) / h[:, None, None]
    nu = mesh_motion(lay, ends)                                        # (K, L, m + 1)
    ic = np.repeat(np.arange(L), m)
    nu_c = nu[:, ic, 0] + np.tile(gz, L) * (nu[:, ic, m] - nu[:, ic, 0])   # (K, P)
    force = force_switches(lay)
    times = np.concatenate([(mesh[:-1, None] + h[:, None] * gz[None, :]).ravel(), b[force]])
    P = L * m
    Uc = np.einsum("gk,lkn->lgn", basis.values(gz), one).reshape(P, n)
    du = np.einsum("gk,lkn->lgn", basis.derivatives(gz), one).reshape(P, n) / h[ic, None]
    dW = _moved_delay(lay, terms, times, mesh, T, slope, nu, own, history)  # (K, times, n)
    first = P * n + (n if history is not None else 0)
    cols = np.zeros((K, first + lay.S + int(lay.autonomous and history is None
                                             and ref is not None)))
    dr = -((nu[:, ic, m] - nu[:, ic, 0]) / h[ic])[:, :, None] * du[None] + dW[:, :P]
    if not lay.autonomous:
        dr += nu_c[:, :, None] * f_t(terms, times[:P], Uc, T)[None]
    mode = np.repeat(np.array(lay.piece_modes(b, T))[lay.piece_of_interval()], m, axis=0)
    dr[:, _held(mode, terms)[0]] = 0.0
    cols[:, :P * n] = dr.reshape(K, -1)
    ft = (f_t(terms, b[force], evaluate(lay, x, b[force]), T)
          if force and not lay.autonomous else None)
    for q, k in enumerate(force):
        i = lay.signature.switch(k + 1)[0]
        cols[:, first + k] = -dW[:, P + q, i] - (own[:, q] * ft[q, i] if ft is not None else 0)
    if cols.shape[1] > first + lay.S:
        cols[:, -1] = _phase_columns(lay, mesh, nu, T, Uc, ref)
    return cols.T


def _moved_delay(lay: Layout, terms: Terms, times: np.ndarray, mesh: np.ndarray, T: float,
                 slope: np.ndarray, nu: np.ndarray, own: np.ndarray, history: History | None
                 ) -> np.ndarray:
    """(K, len(times), n): the delay integral's change at ``times`` (the collocation times,
    then stick endings' b's, which move by ``own`` (K, b's)) along each motion nu (K, L, m + 1)
    of the nodes (:func:`motion_columns`)."""
    m, n, L, K = lay.m, lay.n, lay.L, nu.shape[0]
    out = np.zeros((K, times.size, n))
    if not terms.has_kernel:
        return out
    loc, rows = broken_locator(mesh, m, history)
    if history is None:
        G = terms.periodic_delay(times, mesh, T, lay.basis, rows, loc=loc)[0]
        past = np.empty((0, n))
    else:
        G = terms.memory_delay(times, mesh, T, loc, lay.basis, rows)
        dz = lay.basis.derivatives(lay.basis.nodes)
        hh = np.tile(np.diff(history.hist), history.periods)
        ph = history.phi.reshape(-1, m + 1, n)
        past = (np.einsum("ij,ljn->lin", dz, ph) / hh[:, None, None]).reshape(-1, n)
    cur = slope.reshape(-1, n)
    vec = np.column_stack([np.concatenate([cur, past]).ravel()]
                          + [np.concatenate([(nu[j].reshape(-1)[:, None] * cur),
                                             np.zeros_like(past)]).ravel() for j in range(K)])
    W = (G @ vec).reshape(times.size, n, K + 1)
    i, z, _ = loc(times)
    nu_t = nu[:, i, 0] + z * (nu[:, i, m] - nu[:, i, 0])              # (K, len(times))
    nu_t[:, L * m:] = own
    for j in range(K):
        out[j] = nu_t[j][:, None] * W[:, :, 0] - W[:, :, j + 1]
    return out


def _phase_columns(lay: Layout, mesh: np.ndarray, nu: np.ndarray, T: float, Uc: np.ndarray,
                   ref: Callable) -> np.ndarray:
    """(K,): the phase condition's derivatives along the nodes' motions nu (K, L, m + 1) (its
    weights and reference move with the mesh, u at the collocation points does not), central
    differences of step 1e-6 T."""
    gz, gw = lay.basis.gauss()
    moves = np.concatenate([nu[:, :, 0], nu[:, -1:, -1]], axis=1)      # (K, L + 1): the mesh

    def phase(moved: np.ndarray) -> float:
        h = np.diff(moved)
        tc = (moved[:-1, None] + h[:, None] * gz[None, :]).ravel()
        w = (h[:, None] * gw[None, :]).ravel() / T
        return float(np.sum(w[:, None] * ref(tc / T) * Uc))
    d = 1e-6 * T
    return np.array([(phase(mesh + d * v) - phase(mesh - d * v)) / (2 * d) for v in moves])


def full_jacobian(lay: Layout, terms: Terms, x: np.ndarray, ref: Callable | None,
                  history: History | None = None) -> tuple[np.ndarray, sp.csc_matrix]:
    """The residual and the whole Jacobian: the node columns of :func:`assemble`, the
    switching times' and with them T's (:func:`switch_columns`), or T's of a smooth autonomous
    orbit (:func:`assemble`'s)."""
    r, J, dT = assemble(lay, terms, x, ref, history=history)
    both = lay.autonomous and history is None
    cols = [] if not lay.S else list(switch_columns(lay, terms, x, ref, history, both).T)
    if both and dT is not None:
        cols.append(dT)
    if cols:
        J = sp.hstack([J, sp.csr_matrix(np.column_stack(cols))])
    return r, sp.csc_matrix(J)


def solve(lay: Layout, terms: Terms, x0: np.ndarray, ref: Callable | None, *,
          tol: float = 1e-12, max_iter: int = 25, what: str = "collocation",
          accuracy: list[float] | None = None) -> tuple[np.ndarray, list[float]]:
    """Newton's method on the collocation system with sparse LU (:func:`newton_loop`): the
    factored Jacobian is kept while the residual falls by 10 or more a step (chord steps cost a
    residual), refreshed otherwise, and a fresh step is halved until the residual falls;
    converged when the correction is below tol max(1, |x|_inf) (that correction applied).

    With ``accuracy`` (a list the caller adds to its error estimates), also converged when the
    residual stays at its floor (<= tol max(1, |x|_inf)) while the corrections stop falling
    (FLOOR_ITERATIONS iterations without halving: rounding amplified by a nearly singular
    Jacobian, as at a fixed p on a vertical branch); the achieved accuracy (the largest of those
    corrections, else the last one) is appended to it.

    Raises
    ------
    ShootingError
        No convergence in max_iter, no progress, a singular Jacobian, a non-finite residual, a
        fresh step rejected at every length (:func:`reject_why`).
    """
    res: list[float] = []

    def evaluate(x: np.ndarray) -> tuple[np.ndarray, None]:
        return assemble(lay, terms, x, ref, jacobian=False)[0], None

    def factor(x: np.ndarray, r: np.ndarray, state: None) -> Callable[[np.ndarray], np.ndarray]:
        lu = factored(lay, terms, x, ref, what, res)
        return lambda r: lu.solve(-r)

    options = NewtonOptions(tol=tol, max_iter=max_iter, converge=Converge.CORRECTION, chord=0.1,
                            search=Search.DESCENT, reject=(Degenerate,),
                            reject_why=reject_why(lay), stall=False,
                            floor=FLOOR_ITERATIONS if accuracy is not None else 0)
    return newton_loop(evaluate, factor, x0, options, what=what, history=res, accuracy=accuracy)


def reject_why(lay: Layout) -> str:
    """What a Newton step that :func:`assemble` rejects (:class:`Degenerate`) on every length
    tried means: with switches, a segment that vanishes (the signature read from the start no
    longer holds); without, a period that leaves (0, inf) (Newton diverges)."""
    if lay.S > 0:
        return ("a segment of the signature vanishes on every step length tried (the start's "
                "signature " + ", ".join(lay.signature.describe()) + " does not hold near it)")
    return ("the period leaves (0, inf) on every step length tried (Newton diverges from the "
            "start)")


def factored(lay: Layout, terms: Terms, x: np.ndarray, ref: Callable | None, what: str,
             res: list[float]) -> Any:
    """The sparse LU of the Jacobian at x (ShootingError when singular), its columns in their
    own order (the node values in time: a band with the memory's reach and the wrap-around;
    measured faster to factor and solve than COLAMD's order on van der Pol's Jacobians up to
    1281 columns), or on a graded mesh (GRADED) in COLAMD's: there the memory's reach spans
    many fine intervals and the band fills (the relaxation oscillation at degree 4 on 840
    intervals: 1.9 s and 1.5e7 nonzeros of the factors in the own order, 0.28 s and 2.6e6 in
    COLAMD's)."""
    _, J = full_jacobian(lay, terms, x, ref)
    try:
        return sla.splu(J, permc_spec="COLAMD" if lay.interval_ratio() >= GRADED else "NATURAL")
    except RuntimeError as err:
        raise ShootingError(f"{what}: singular Jacobian ({err})", res) from None


def interval_counts(lengths: np.ndarray, L: int) -> np.ndarray:
    """L intervals shared by pieces of these lengths (or weights), at least 1 each."""
    w = np.asarray(lengths, dtype=float)
    c = np.maximum(1, np.round(L * w / w.sum()).astype(int))
    return c


def uniform_fractions(bounds: np.ndarray, L: int) -> list[np.ndarray]:
    """Each piece of [0, T] (ends ``bounds``) cut into equal intervals, L in all (about)."""
    return [np.linspace(0.0, 1.0, c + 1) for c in interval_counts(np.diff(bounds), L)]


def evaluate(lay: Layout, x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """u(t) (len(t), n) of the collocated orbit x (t any reals)."""
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    _, z, cols = periodic_locator(mesh, lay.m)(np.asarray(t, dtype=float))
    return np.einsum("pk,pkn->pn", lay.basis.values(z), V[cols])


def check_inequalities(lay: Layout, terms: Terms, x: np.ndarray, rel: float = 1e-9
                       ) -> list[str]:
    """The inequalities of its signature (:func:`~.signature.violations`) the solution x breaks
    on a fine grid (CHECK_POINTS a mesh interval) by more than rel times its scale (its largest
    entry, at least 1)."""
    tol = rel * max(1.0, float(np.max(np.abs(x))))
    if lay.signature.switches == 0 and not (np.any(terms.alpha > 0)
                                            or np.any(np.isfinite(terms.lo))
                                            or np.any(np.isfinite(terms.hi))):
        return []
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    e = lay.bounds(b, T)
    grid, us, forces = [], [], []
    for j in range(len(e) - 1):
        count = (len(lay.fractions[j]) - 1) * CHECK_POINTS + 1
        t = np.linspace(e[j], e[j + 1], count)
        u = evaluate(lay, x, t)
        F = -terms.f(t, u)
        if terms.has_kernel:
            G = terms.periodic_delay(t, mesh, T, lay.basis, lay.rows)[0]
            F = F - (G @ V.ravel()).reshape(-1, lay.n)
        grid.append(t)
        us.append(u)
        forces.append(F)
    return violations(lay.piece_modes(b, T), grid, us, forces, terms.alpha, terms.lo, terms.hi,
                      tol)


def node_times(lay: Layout, b: np.ndarray, T: float) -> np.ndarray:
    """The times of the L m node rows."""
    mesh = lay.mesh(b, T)
    z = lay.basis.nodes[:-1]
    return (mesh[:-1, None] + np.diff(mesh)[:, None] * z[None, :]).ravel()


def carried(terms: Terms, sig: Any) -> tuple[float, ...]:
    """The lags at which the memory carries a switch forward on an orbit with switches: the
    declared jumps of H and tau where H(tau) != 0 (the delay integral's derivative jumps at
    b_k + s_j), else ()."""
    if sig.switches == 0 or not terms.has_kernel:
        return ()
    end = (terms.tau,) if np.any(terms.H(np.array([terms.tau])) != 0) else ()
    return terms.H.jumps + end


def reference(lay: Layout, x: np.ndarray) -> Any:
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
