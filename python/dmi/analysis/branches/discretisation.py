# Continuation of the equation's periodic orbits: the collocation system as a discretisation handed
# to a continuation driver, its signature changed between steps, and the start at a Hopf point.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The collocation discretisation of :mod:`dmi.analysis.collocation.collocate` for a continuation driver.

The driver's contract: ``residual(x, p)`` (len(x) equations), ``jacobian(x, p) -> (J_x, J_p)``
(J_x a scipy.sparse matrix, J_p by a forward difference in p), ``point(x, p)`` (the
:class:`EquationOrbit` the user sees, with its multipliers, their error estimates (the
difference to the solve on the mesh with every pair of intervals merged: an upper estimate), and
its verified stability; None
when the orbit breaks an inequality of its signature), ``event_functions(x, p, point)`` (a sign change is an event) and ``adapt(x, p)``
(between steps: a segment shorter than 1e-7 of the period is removed, a slip or stuck
segment whose inequality breaks is split around the breach, the mesh is equidistributed again and
the phase condition's reference moves to x; x changes its length when the signature changes, and
the driver restarts its tangent).

:func:`equation_hopf_orbit` starts a branch at the equation's Hopf point: the unknowns (x, p) with
the amplitude condition int_0^1 (u_c - u_eq,c)^2 d theta = amplitude^2 / 2 (a sine's mean
square) on the component c where the critical eigenvector v is largest, from u_eq + amplitude
Re(v e^(i omega t)) / |v_c|, v the critical eigenvector of the equation's
characteristic matrix lambda I + f_u + H^(lambda) at lambda = i omega.
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp

from ..core.model import checked_equilibrium
from ..collocation.adapt import Solved, estimate, merged, readapted, transfer
from ..collocation.floquet import multipliers as floquet
from ..collocation.mend import mend
from ..collocation.orbit import equation_orbit
from ..collocation.system import CollocationWarning, check_inequalities, check_jumps, reference
from ..collocation.mesh import periodic_locator, point_matrix
from ..collocation.signature import SLIP_NEG, SLIP_POS, Signature
from ..collocation.system import Layout, Terms, assemble, full_jacobian, node_times, solve
from ..collocation.orbit import EquationOrbit
from ..core.newton import Converge, NewtonOptions, ShootingError, bordered_solve, newton_loop
from ..scheme.problem import Problem
from ..continuation.branch import HopfPoint
from ..scheme.stepmap import Model, build



class CollocationDiscretisation:
    """The collocation system of an equation's periodic orbit as a function of (x, p).

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver``.
    layout : Layout
        The unknowns' layout (degree, signature, mesh fractions, autonomous or forced period).
    x : numpy.ndarray
        A solution (or guess) on that layout: the phase condition's reference.
    multipliers : int
        Leading multipliers a point carries.
    estimate : bool
        A point's errors from the solve on the mesh with every pair of intervals merged (False:
        none, ``errors`` empty and ``stable`` None: a verdict needs the multipliers' errors).
    kernel_jumps : sequence of float
        The lags of the kernel's jumps (cuts of the delay integral's pieces at every p).
    """

    def __init__(self, make: Model, layout: Layout, x: np.ndarray, *, multipliers: int = 10,
                 estimate: bool = True, kernel_jumps: tuple[float, ...] = ()):
        self.make, self.lay = make, layout
        self.jumps = tuple(kernel_jumps)
        self.count, self.estimate = int(multipliers), bool(estimate)
        self.problem = Problem(make, keep=5)   # the terms of the last few p
        self.ref = reference(layout, x) if layout.autonomous else None

    @classmethod
    def of(cls, orbit: EquationOrbit, **kw: Any) -> tuple[CollocationDiscretisation, np.ndarray]:
        """The discretisation of a collocated orbit and its unknowns x.

        Parameters
        ----------
        orbit : EquationOrbit
            From :func:`dmi.analysis.collocate` or a point of a branch.
        **kw
            As the constructor's.

        Returns
        -------
        tuple
            (the discretisation, x).

        Raises
        ------
        TypeError
            ``orbit`` is not an EquationOrbit.
        """
        if not isinstance(orbit, EquationOrbit):
            raise TypeError(f"give an EquationOrbit (collocate), not {type(orbit).__name__}")
        n = orbit.nodes.shape[1]
        lay = Layout(orbit.degree, n, orbit.signature, [f.copy() for f in orbit.fractions],
                     orbit.autonomous, orbit.period, tuple(orbit.carried))
        x = np.concatenate([orbit.nodes.ravel(), orbit.switches,
                            [orbit.period] if orbit.autonomous else []])
        disc = cls(orbit.make, lay, x, **kw)
        disc.jumps = tuple(orbit.kernel_jumps)      # the orbit's, before any terms are built
        return disc, x

    def terms(self, p: float) -> Terms:
        """The model's terms at p (the last few cached).

        Parameters
        ----------
        p : float
            The parameter.

        Returns
        -------
        Terms
            f, its derivative, the kernel, A's coefficients of ``make(p)``.
        """
        key = float(p)
        return self.problem.cached(("terms", key),
                                   lambda: Terms(build(self.make, key), self.jumps))

    def residual(self, x: np.ndarray, p: float) -> np.ndarray:
        """The collocation system's residual.

        Parameters
        ----------
        x : numpy.ndarray
            The unknowns (node values, switching times, T if autonomous).
        p : float
            The parameter.

        Returns
        -------
        numpy.ndarray
            len(x) values.
        """
        return assemble(self.lay, self.terms(p), x, self.ref, jacobian=False)[0]

    def jacobian(self, x: np.ndarray, p: float) -> tuple[sp.csc_matrix, np.ndarray]:
        """(J_x, J_p): J_x sparse (exact in the node values, central differences in the
        switching times), J_p by a forward difference (step 1e-7 max(1, |p|): a tangent's
        accuracy, not the orbit's).

        Parameters
        ----------
        x : numpy.ndarray
            The unknowns.
        p : float
            The parameter.

        Returns
        -------
        tuple
            (scipy.sparse.csc_matrix (len(x), len(x)), numpy.ndarray (len(x),)).
        """
        r, J = full_jacobian(self.lay, self.terms(p), x, self.ref)
        d = 1e-7 * max(1.0, abs(p))
        Jp = (self.residual(x, p + d) - r) / d
        return J, Jp

    def point(self, x: np.ndarray, p: float) -> EquationOrbit | None:
        """The orbit at (x, p) with its multipliers and error estimates; None (with a
        CollocationWarning) when it breaks an inequality of its signature or the merged mesh's
        solve fails.

        Parameters
        ----------
        x : numpy.ndarray
            A solution at p.
        p : float
            The parameter.

        Returns
        -------
        EquationOrbit or None
            The point.
        """
        terms = self.terms(p)
        bad = check_inequalities(self.lay, terms, x)
        if bad:
            warnings.warn(f"p = {p!r}: the orbit breaks its signature ({bad[0]}): no point",
                          CollocationWarning, stacklevel=2)
            return None
        here = self._solved(self.lay, terms, x)
        errors: dict[str, Any] = {}
        if self.estimate:
            coarse = self.lay.with_fractions(merged(self.lay.fractions))
            reached: list[float] = []
            try:
                xc, _ = solve(coarse, terms, transfer(self.lay, x, coarse), self.ref,
                              accuracy=reached)
            except (ShootingError, ValueError) as e:
                warnings.warn(f"p = {p!r}: the merged mesh's solve failed ({e}): no point",
                              CollocationWarning, stacklevel=2)
                return None
            # the difference to the mesh of merged pairs is about 2^q - 1 >= 1 times the error;
            # a solve stopped at its rounding floor adds the accuracy it reached
            errors = estimate(self._solved(coarse, terms, xc), here, reached[-1])
        return equation_orbit(here, float(p), self.make, errors, self.jumps)

    def _solved(self, lay: Layout, terms: Terms, x: np.ndarray) -> Solved:
        """x on lay with its leading multipliers (none where the branch carries none)."""
        return Solved(lay, x, floquet(lay, terms, x, self.count) if self.count > 0 else None)

    def event_functions(self, x: np.ndarray, p: float, point: EquationOrbit | None
                        ) -> dict[str, float]:
        """Functions whose sign change is an event: ``fold`` (the largest real multiplier > 0
        but the trivial one, minus 1), ``period_doubling`` (the largest |mu| of the real
        negative ones, minus 1), ``torus`` (the largest |mu| of a complex pair, minus 1) and
        ``segment`` (the shortest segment over the period: 0 where the signature changes; the
        period itself for a smooth orbit), each only where defined.

        Parameters
        ----------
        x : numpy.ndarray
            The unknowns.
        p : float
            The parameter.
        point : EquationOrbit or None
            :meth:`point`'s answer at (x, p).

        Returns
        -------
        dict
            name -> value.
        """
        out: dict[str, float] = {}
        _, b, T = self.lay.split(x)
        e = np.concatenate([[0.0], b, [T]])                 # the segments' ends
        if self.lay.S:
            lengths = np.diff(e)
            out["segment"] = float(min(lengths[0] + lengths[-1], *lengths[1:-1])
                                   if len(lengths) > 2 else lengths[0] + lengths[-1]) / T
        if point is None or point.multipliers.size == 0:
            return out
        mu = np.asarray(point.multipliers)
        if self.lay.autonomous:
            mu = np.delete(mu, int(np.argmin(np.abs(mu - 1))))
        real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
        pos, neg, cx = mu[real & (mu.real > 0)].real, mu[real & (mu.real < 0)].real, mu[~real]
        if pos.size:
            out["fold"] = float(pos.max() - 1)
        if neg.size:
            out["period_doubling"] = float(np.abs(neg).max() - 1)
        if cx.size:
            out["torus"] = float(np.abs(cx).max() - 1)
        return out

    def adapt(self, x: np.ndarray, p: float) -> np.ndarray:
        """Between steps: the signature mended (a vanishing segment removed, a breached
        inequality's stretch made a segment of its own), the mesh equidistributed again, the
        phase condition's reference moved to x.

        Parameters
        ----------
        x : numpy.ndarray
            The unknowns at the last point.
        p : float
            Its parameter.

        Returns
        -------
        numpy.ndarray
            x on the new layout (another length when the signature changed).
        """
        lay, terms = self.lay, self.terms(p)
        mended = mend(lay, terms, x)
        if mended is not None:
            new_lay, x = mended
        else:
            new_lay, x = readapted(lay, x)
        self.lay = new_lay
        if lay.autonomous:
            self.ref = reference(new_lay, x)
        return x


def _hhat(terms: Terms, lam: complex) -> np.ndarray:
    """int_0^tau H(s) e^(-lam s) ds (n, n) by Gauss-Legendre on 64 panels of 16 nodes."""
    g, w = np.polynomial.legendre.leggauss(16)
    edges = np.linspace(0.0, terms.tau, 65)
    half = 0.5 * np.diff(edges)
    s = (edges[:-1, None] + half[:, None] * (g[None, :] + 1)).ravel()
    ws = (half[:, None] * w[None, :]).ravel()
    if not terms.has_kernel:
        return np.zeros((terms.n, terms.n), complex)
    return np.einsum("p,pij->ij", ws * np.exp(-lam * s), terms.H(s))


def equation_hopf_orbit(make: Model, hopf_point: HopfPoint, u_eq: Any, amplitude: float, *,
                        degree: int = 4, intervals: int = 24, multipliers: int = 10,
                        tol: float = 1e-12, max_iter: int = 30,
                        kernel_jumps: tuple[float, ...] = (), start: float | None = None
                        ) -> EquationOrbit:
    """The equation's periodic orbit born at a Hopf point, of a given amplitude, p free.

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver`` (its step is not used).
    hopf_point : HopfPoint
        The equation's Hopf point (``hopf(..., of="equation")``).
    u_eq : array_like
        Shape (n,): the equilibrium there.
    amplitude : float
        sqrt(2) times the root-mean-square distance from u_eq of the component that moves most
        in the critical mode (a sine's amplitude; state units), > 0.
    degree : int
        m.
    intervals : int
        L (uniform).
    multipliers : int
        Leading multipliers.
    tol : float
        Newton's tolerance on the correction.
    max_iter : int
        Newton iterations at most.
    kernel_jumps : sequence of float
        The lags in (0, tau) where the kernel jumps (as :func:`dmi.analysis.collocate`'s; an
        undeclared jump of a callback kernel found is warned of).
    start : float, optional
        The parameter Newton starts from (default the Hopf point's p; :func:`hopf_orbit` gives
        the amplitude's predicted parameter where the Hopf point has kappa).

    Returns
    -------
    EquationOrbit
        Autonomous, at the p found (errors from the mesh of merged pairs).  Where the orbit is
        not isolated at fixed p (a vertical branch) the merged mesh's solve stops at its
        rounding floor, its accuracy added to the errors, and the amplitude's error is about
        the amplitude itself (not determined at fixed p); ``stable`` is then None (a second
        multiplier at 1).  Where that solve fails, no errors.

    Raises
    ------
    ValueError
        Bad input: not a HopfPoint, omega <= 0, amplitude <= 0, u_eq not n finite numbers or
        not an equilibrium of the equation at p (one equation step moves it by more than
        EQUILIBRIUM_TOL, relative: :func:`dmi.analysis.core.model.checked_equilibrium`), a jump outside (0, tau) or declared where the kernel does not jump.
    ShootingError
        Newton fails.
    """
    if not isinstance(hopf_point, HopfPoint):
        raise ValueError(f"hopf_point = {hopf_point!r}: give a dmi.analysis.HopfPoint")
    if not (hopf_point.omega > 0 and math.isfinite(hopf_point.omega)):
        raise ValueError(f"hopf_point.omega = {hopf_point.omega!r}: a Hopf point has omega > 0")
    a = float(amplitude)
    if not (a > 0 and math.isfinite(a)):
        raise ValueError(f"amplitude = {amplitude!r}: give a finite amplitude > 0")
    p0, om = float(hopf_point.p), float(hopf_point.omega)
    terms = Terms(build(make, p0), kernel_jumps)
    check_jumps(terms, "hopf_orbit")
    n = terms.n
    ue = np.asarray(u_eq, dtype=float).ravel()
    if ue.shape != (n,):
        raise ValueError(f"u_eq = {u_eq!r}: give {n} numbers (the model's n)")
    if not np.all(np.isfinite(ue)):
        raise ValueError(f"u_eq = {u_eq!r}: give {n} finite numbers (the equilibrium)")
    modes = _slipping(terms, ue)
    checked_equilibrium(terms.solver, ue, (p0,), EQUILIBRIUM_TOL, "equation",
                        jumps=terms.H.jumps)
    Jf = terms.fu(np.zeros(1), ue[None, :])[0]
    _, _, Vh = sl.svd(1j * om * np.eye(n) + Jf + _hhat(terms, 1j * om))
    v = Vh[-1].conj()
    c = int(np.argmax(np.abs(v)))
    v = v / v[c]
    T = 2 * math.pi / om
    lay = Layout(int(degree), n, Signature(modes[None, :]),
                 [np.linspace(0.0, 1.0, int(intervals) + 1)], True, T)
    t = node_times(lay, np.empty(0), T)
    V = ue + a * np.real(np.outer(np.exp(1j * om * t), v))
    x = np.concatenate([V.ravel(), [T]])
    disc = CollocationDiscretisation(make, lay, x, multipliers=multipliers,
                                     kernel_jumps=terms.H.jumps)
    p1 = p0 if start is None else float(start)
    gz, gw = lay.basis.gauss()

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, None]:
        g, _ = _amplitude_condition(lay, z[:-1], ue, c, a, gz, gw)
        return np.concatenate([disc.residual(z[:-1], z[-1]), [g]]), None

    def factor(z: np.ndarray, r: np.ndarray, state: None) -> Callable[[np.ndarray], np.ndarray]:
        J, Jp = disc.jacobian(z[:-1], z[-1])
        grow = _amplitude_condition(lay, z[:-1], ue, c, a, gz, gw)[1]
        return lambda r: bordered_solve(J, Jp, grow, -r)

    z, _ = newton_loop(evaluate, factor, np.concatenate([x, [p1]]),
                       NewtonOptions(tol=tol, max_iter=max_iter, converge=Converge.CORRECTION,
                                     stall=False),
                       what=f"the orbit from the Hopf point at p = {p0!r}")
    pt = disc.point(z[:-1], z[-1])
    if pt is None:            # the merged mesh's solve failed: no estimate
        disc.estimate = False
        pt = disc.point(z[:-1], z[-1])
    if pt is None:
        raise ShootingError("the orbit from the Hopf point breaks its signature", [])
    return pt


def _slipping(terms: Terms, ue: np.ndarray) -> np.ndarray:
    """The modes (n,) at an equilibrium: a friction component slips with the sign of u_eq, the
    others are free.

    Raises
    ------
    ValueError
        A friction component at 0 (stuck) or a box component on a face: no Hopf point there.
    """
    modes = np.zeros(terms.n, dtype=int)
    for i in range(terms.n):
        if terms.alpha[i] > 0:
            if ue[i] == 0:
                raise ValueError(f"u_eq[{i}] = 0 sticks (friction): no Hopf orbit there")
            modes[i] = SLIP_POS if ue[i] > 0 else SLIP_NEG
        elif ue[i] <= terms.lo[i] or ue[i] >= terms.hi[i]:
            raise ValueError(f"u_eq[{i}] = {ue[i]!r} is on the box's face: no Hopf orbit there")
    return modes


#: The equilibrium check's tolerance (:func:`dmi.analysis.core.model.checked_equilibrium`): that of
#: :func:`dmi.analysis.roots`, which the equation's Hopf point was found with.
EQUILIBRIUM_TOL = 1e-9


def _amplitude_condition(lay: Layout, x: np.ndarray, ue: np.ndarray, c: int, a: float,
                         gz: np.ndarray, gw: np.ndarray) -> tuple[float, np.ndarray]:
    """int_0^1 (u_c - u_eq,c)^2 d theta - a^2 / 2 and its row in (x, p) (Gauss points)."""
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    h = np.diff(mesh)
    tc = (mesh[:-1, None] + h[:, None] * gz[None, :]).ravel()
    w = (h[:, None] * gw[None, :]).ravel() / T
    E = point_matrix(tc, periodic_locator(mesh, lay.m), lay.basis, mesh, lay.n, lay.rows)
    d = (E @ V.ravel()).reshape(-1, lay.n) - ue
    d[:, np.arange(lay.n) != c] = 0.0
    g = float(np.sum(w[:, None] * d * d) - 0.5 * a * a)
    row = np.concatenate([(2 * w[:, None] * d).ravel() @ E, np.zeros(x.size - lay.rows * lay.n
                                                                     + 1)])
    return g, row


__all__ = ["CollocationDiscretisation", "equation_hopf_orbit"]
