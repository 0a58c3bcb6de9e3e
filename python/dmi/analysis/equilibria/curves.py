# Hopf and fold curves of the equation's equilibria in two parameters, by pseudo-arclength, with
# their codimension-two points.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Curves of Hopf points and of folds of the equation's equilibria in the plane (p, q):
:func:`continue_curve` and its records :class:`Curve`, :class:`CurvePoint` and
:class:`CurveEvent`.

What it holds: the two extended systems below as discretisations of the one continuation driver
(:func:`dmi.analysis.continuation.driver.continuation`, its parameter q, p one of the unknowns, so that the
curve passes its turning points in q and lands on q_end and on the user's q exactly), their test
functions of codimension-two points, and the records.  What it may import: numpy, the driver,
the records (:mod:`dmi.analysis.continuation.branch`), the model's linearisation (:mod:`dmi.analysis.core.model`),
the characteristic matrix (:mod:`dmi.analysis.equilibria.equation`), the roots
(:mod:`dmi.analysis.equilibria.stability`), the normal forms
(:mod:`dmi.analysis.equilibria.normal_form`) and the room's tools
(:mod:`dmi.analysis.equilibria.numerics`); the package's ``__init__`` and the stability chart
(:mod:`dmi.analysis.equilibria.chart`, whose traced curves are these systems with the chart's
equilibrium given: :func:`system`, :func:`curve_of`) import it.

The systems (docs/stability.md, "Hopf and fold curves").  G(u; p, q) = R(X(u)) - u is the
equation's equilibrium residual (:func:`dmi.analysis.core.model.equation_step`, divided by h), Delta
(lambda; u, p, q) the characteristic matrix on the free components (those the resolvent does not
hold), built at any u from f_u (the derivative hook ``fu`` where the model sets one, else central
differences), the resolvent's derivative and the kernel's transform.

- Hopf curve: unknowns (u, p, omega, Re v, Im v), equations G = 0, Delta(i omega) v = 0 and
  c v = 1 (complex; c the start's conj(v), so that v stays away from 0).  Each point carries its
  :class:`HopfPoint` with l1, kappa and the crossing speed (in p at fixed q) of
  :func:`dmi.analysis.equilibria.normal_form.criticality`.  Test functions: ``bautin`` l1;
  ``zero-hopf`` the product of the real roots (geometric mean of the moduli, with its sign);
  ``hopf-hopf`` the product of Re lambda over the other non-real pairs (upper half-plane, the
  pair at i omega left out).
- Fold curve: unknowns (u, p, v), equations G = 0, Delta(0) v = 0, c v = 1.  With w the left
  null vector from the bordered system [[Delta(0), b], [c, 0]] (b the start's left null vector,
  c its right one: w continuous along the curve, w b = 1):
  ``cusp`` the fold's quadratic coefficient w D^2 f(u)(v, v) (the model's hook ``d2``, else
  central differences); ``bogdanov-takens`` w Delta'(0) v (a second root at 0: the Hopf curve's
  omega -> 0 ends here); ``zero-hopf`` the product of Re lambda over the non-real pairs.

Every event is located by the driver (Brent's method along the chord of two points, each value a
point of the curve) and checked at the located point (:meth:`_Extended.describe`): a zero-Hopf
or Hopf-Hopf point must have its root on the axis (to 1e-6), a Bautin point a located l1 within
its error, a cusp or Bogdanov-Takens point a test function that vanishes (not a pole).
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..._errors import Error
from ..._solver import Solver
from ..continuation.branch import ON_AXIS, REAL, AlongQ, Curve, CurveEvent, Event, HopfPoint
from ..continuation.driver import ContinuationOptions, continuation, curve_range
from ..core.model import Linearisation, call_make, equation_step
from ..core.newton import ShootingError
from ..scheme.problem import AtQ
from .equation import Characteristic, RefinementWarning
from .normal_form import CriticalityWarning, _check_hooks, _Forms, criticality
from .numerics import forward_jacobian, null_vectors, signed_mean
from .stability import roots as equation_roots

#: Roots computed at each point (the zero-Hopf and Hopf-Hopf test functions read them).
ROOTS = 6


@dataclass
class CurvePoint(AlongQ):
    """A point of a :class:`Curve`.

    Attributes
    ----------
    p, q : float
        The parameters.
    u : numpy.ndarray
        Shape (n,): the equation's equilibrium there (state units).
    omega : float
        The crossing frequency (radians / time unit) on a Hopf curve; 0 on a fold curve.
    hopf : HopfPoint or None
        The Hopf point at fixed q (its ``p``, ``omega``, ``root``, ``l1``, ``kappa``,
        ``crossing_speed``); None on a fold curve.
    roots : numpy.ndarray of complex
        The rightmost roots of the equation there, rightmost first.
    dqds : float
        The unit tangent's q component (its sign flips at a turning point in q).
    note : str
        Why l1, kappa or the crossing speed is None (the criticality's warnings), or which roots
        could not be refined (NaN in ``roots``); empty when nothing was left out.
    """
    p: float
    q: float
    u: np.ndarray = field(repr=False)
    omega: float = 0.0
    hopf: HopfPoint | None = field(default=None, repr=False)
    roots: np.ndarray = field(default_factory=lambda: np.empty(0, complex), repr=False)
    dqds: float = 0.0
    note: str = field(default="", repr=False)

    @property
    def l1(self) -> float | None:
        """The Hopf point's first Lyapunov coefficient (None on a fold curve)."""
        return None if self.hopf is None else self.hopf.l1

    @property
    def l1_error(self) -> float | None:
        """Its estimated error (None on a fold curve)."""
        return None if self.hopf is None else self.hopf.l1_error

    @property
    def criticality(self) -> str | None:
        """The Hopf point's criticality (None on a fold curve)."""
        return None if self.hopf is None else self.hopf.criticality

    @property
    def kappa(self) -> np.ndarray | None:
        """The Hopf point's amplitude coefficients (None on a fold curve)."""
        return None if self.hopf is None else self.hopf.kappa


class _Extended:
    """The extended system of a Hopf curve (``kind="hopf"``) or a fold curve (``"fold"``) for
    the driver: the unknowns x = (u, p, omega, Re v, Im v) or (u, p, v), the driver's parameter
    q (see the module).

    ``given``: the equilibrium is known, u = given(p, q) (a stability chart's), and not an
    unknown: x = (p, omega, Re v, Im v) or (p, v), no equation G = 0.  ``of="scheme"`` (only
    with ``given``): the scheme's characteristic matrix at the multiplier e^(i omega h)
    (:meth:`dmi.analysis.core.model.Linearisation.characteristic`, every component) in place
    of Delta(i omega), its derivative in omega by a central difference.  ``tests=False``: the
    points carry no roots nor criticality, and there are no test functions (a chart's
    curves)."""

    def __init__(self, make2: Callable[[float, float], Solver], kind: str, n: int,
                 free: np.ndarray, c: np.ndarray, tol: float, count: int, *,
                 given: Callable[[float, float], np.ndarray] | None = None,
                 of: str = "equation", lin_tol: float = 1e-9, tests: bool = True):
        self.make2, self.kind, self.n, self.free, self.m = make2, kind, n, free, free.size
        self.c, self.tol, self.count = c, tol, count
        self.given, self.of, self.lin_tol, self.tests = given, of, lin_tol, tests
        self.k = 0 if given is not None else n    # the unknowns of u
        self.why = ""
        self.hooks_checked = False   # the model's d2 checked against differences of f
        self.cusp_warned = False     # no cusp test (a resolvent callback) said once
        self.b = c   # a fold curve's border column: the start's left null vector (set below)
        self.reach = 1.0   # a callback kernel's panels reach |lambda| <= reach
        m = self.m
        # the arclength: u and p as the equilibria's branch (Euclidean), omega too, v little
        self.weight = np.concatenate([np.ones(self.k + 1), np.ones(1 if kind == "hopf" else 0),
                                      np.full(2 * m if kind == "hopf" else m, 1e-2)])

    # ---- the unknowns --------------------------------------------------------------------
    def split(self, x: np.ndarray, q: float) -> tuple[np.ndarray, float, float, np.ndarray]:
        """(u, p, omega, v): v complex on a Hopf curve, real on a fold curve (omega 0)."""
        k, m = self.k, self.m
        p = float(x[k])
        u = x[:k] if self.given is None else self.given(p, float(q))
        if self.kind == "hopf":
            return u, p, float(x[k + 1]), x[k + 2:k + 2 + m] + 1j * x[k + 2 + m:]
        return u, p, 0.0, x[k + 1:]

    def _at(self, u: np.ndarray, p: float, q: float) -> tuple[np.ndarray, Characteristic,
                                                               Solver]:
        """(G(u) / h (empty with ``given``), Delta, the open solver) at (p, q); the caller
        closes the solver."""
        s = call_make(self.make2, p, q)
        try:
            G = equation_step(s)(u) / s.h if self.given is None else np.empty(0)
            ch = Characteristic.at(s, u, self.reach)
        except BaseException:
            s.close()
            raise
        if not np.array_equal(ch.free, self.free):
            s.close()
            raise ShootingError(f"the components the resolvent holds change at (p, q) = "
                                f"({p!r}, {q!r}) (free {ch.free.tolist()}, at the start "
                                f"{self.free.tolist()}): the curve meets a switch", [])
        return G, ch, s

    def matrices(self, u: np.ndarray, p: float, q: float, omega: float, slope: bool
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """(G / h, the characteristic matrix at i omega, its derivative in omega if ``slope``)
        at (p, q): the equation's Delta(i omega) and i Delta'(i omega), or the scheme's."""
        if self.of == "scheme":
            with Linearisation(lambda: call_make(self.make2, p, q), u, (p, q), self.lin_tol,
                               "scheme") as lin:
                def at(w: float) -> np.ndarray:
                    return lin.characteristic(complex(np.exp(1j * w * lin.h)))
                M, dM = at(omega), None
                if slope:
                    d = 1e-6 * max(1.0, abs(omega))
                    dM = (at(omega + d) - at(omega - d)) / (2 * d)
            return np.empty(0), M, dM
        G, ch, s = self._at(u, p, q)
        try:
            return G, ch(1j * omega), 1j * ch.prime(1j * omega, order=4) if slope else None
        finally:
            s.close()

    def _stack(self, G: np.ndarray, r: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The residual (G / h, M v, c v - 1), real."""
        norm = complex(self.c @ v) - 1.0
        if self.kind == "hopf":
            return np.concatenate([G, r.real, r.imag, [norm.real, norm.imag]])
        return np.concatenate([G, r.real, [norm.real]])

    # ---- the driver's contract -----------------------------------------------------------
    def residual(self, x: np.ndarray, q: float) -> np.ndarray:
        """(G / h, Delta v, c v - 1) at (x, q), real."""
        u, p, omega, v = self.split(x, q)
        G, M, _ = self.matrices(u, p, q, omega, False)
        return self._stack(G, M @ v, v)

    def jacobian(self, x: np.ndarray, q: float) -> tuple[np.ndarray, np.ndarray]:
        """(d/dx, d/dq): the columns of u, p and q by forward differences of step 1e-7 max(1,
        |y_j|); those of v (Delta, and c in the normalisation) and omega (i Delta'(i omega) v)
        in closed form."""
        k, m = self.k, self.m
        u, p, omega, v = self.split(x, q)
        G, M, dM = self.matrices(u, p, q, omega, self.kind == "hopf")
        y = np.concatenate([x, [q]])
        J = forward_jacobian(lambda e: self.residual(e[:-1], float(e[-1])), y,
                             self._stack(G, M @ v, v), list(range(k + 1)) + [y.size - 1])
        if self.kind == "hopf":
            # rows (Re, Im) of Delta v and of c v over the columns omega, Re v, Im v
            dMv = dM @ v
            re, im = slice(k + 2, k + 2 + m), slice(k + 2 + m, k + 2 + 2 * m)
            top, low, c = slice(k, k + m), slice(k + m, k + 2 * m), k + 2 * m
            J[top, k + 1], J[low, k + 1] = dMv.real, dMv.imag
            J[top, re], J[top, im], J[low, re], J[low, im] = M.real, -M.imag, M.imag, M.real
            J[c, re], J[c, im] = self.c.real, -self.c.imag
            J[c + 1, re], J[c + 1, im] = self.c.imag, self.c.real
        else:
            J[k:k + m, k + 1:k + 1 + m] = M.real
            J[k + m, k + 1:k + 1 + m] = self.c
        return J[:, :-1], J[:, -1]

    def point(self, x: np.ndarray, q: float) -> CurvePoint:
        """The curve's point: the equation's rightmost roots, and on a Hopf curve the Hopf
        point's criticality (its warnings kept: they say why a value is None)."""
        u, p, omega, _ = self.split(x, q)
        if not self.tests:
            return CurvePoint(p=p, q=float(q), u=np.array(u, dtype=float), omega=omega)
        make1 = AtQ(self.make2, q)
        # a root that cannot be refined (near a double root: Bogdanov-Takens) is NaN, which the
        # test functions leave out; its warning goes into the point's note
        with warnings.catch_warnings(record=True) as unrefined:
            warnings.simplefilter("always", RefinementWarning)
            try:
                lam = equation_roots(make1, p, u, self.count, tol=max(self.tol * 1e3, 1e-9),
                                     of="equation")
            except (ValueError, ArithmeticError, RuntimeError, np.linalg.LinAlgError,
                    Error) as e:   # the roots' failure: the test functions read NaN
                lam = np.empty(0, complex)
                warnings.warn(f"no roots: {e}", RefinementWarning, stacklevel=1)
        pt = CurvePoint(p=p, q=float(q), u=u.copy(), omega=omega, roots=lam,
                        note="; ".join(str(w.message) for w in unrefined))
        if self.kind == "hopf":
            hp = HopfPoint(p=p, omega=omega, root=complex(0.0, omega))
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", CriticalityWarning)
                hp = criticality(make1, hp, u, tol=max(self.tol * 1e3, 1e-9))
            pt.hopf = hp
            pt.note = "; ".join([pt.note] * bool(pt.note) + [str(w.message) for w in caught])
        return pt

    def _others(self, lam: np.ndarray, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """(the real roots, the non-real roots of the upper half-plane but the one at i omega)."""
        lam = lam[np.isfinite(lam)]
        real = np.abs(lam.imag) <= REAL * np.maximum(1.0, np.abs(lam))
        upper = lam[~real & (lam.imag > 0)]
        if self.kind == "hopf" and upper.size:
            upper = np.delete(upper, np.argmin(np.abs(upper - 1j * omega)))
        return lam[real].real, upper

    def _null(self, x: np.ndarray, q: float) -> tuple[float, float]:
        """A fold curve's (w D^2 f(u)(v, v), w Delta'(0) v), w the bordered left null vector."""
        u, p, _, v = self.split(x, q)
        _, ch, s = self._at(u, p, q)
        try:
            M = ch(0.0).real
            m = self.m
            A = np.zeros((m + 1, m + 1))
            A[:m, :m], A[:m, m], A[m, :m] = M, self.b, self.c
            rhs = np.zeros(m + 1)
            rhs[m] = 1.0
            w = np.linalg.solve(A.T, rhs)[:m]
            vf = np.zeros(self.n)
            vf[self.free] = v
            forms = _Forms(s, u)
            if not self.hooks_checked and forms.d2 is not None:   # the model's d2, once
                _check_hooks(forms, vf / float(np.max(np.abs(vf))))
                self.hooks_checked = True
            if s.resolvent_kind == "callback":   # D^2 G holds R'', which is not computed
                if not self.cusp_warned:
                    warnings.warn("dmi.analysis: no cusp test on this fold curve: the model's A "
                                  "is a resolvent callback, whose second derivative the test "
                                  "needs (put the nonlinear terms in f, or use the built-in "
                                  "friction or box)", CriticalityWarning, stacklevel=2)
                    self.cusp_warned = True
                a = math.nan
            else:
                a = float(w @ forms.b_real(vf, vf, same=True)[self.free])
            bt = float(w @ ch.prime(0.0, order=4).real @ v)
        finally:
            s.close()
        return a, bt

    def event_functions(self, x: np.ndarray, q: float, point: CurvePoint) -> dict[str, float]:
        """The test functions (see the module); NaN where not computable; none without
        ``tests``."""
        if not self.tests:
            return {}
        real, upper = self._others(point.roots, point.omega) if point.roots.size else (
            np.empty(0), np.empty(0, complex))
        if self.kind == "hopf":
            f = {"bautin": math.nan if point.l1 is None else float(point.l1)}
            if point.roots.size:
                f["zero-hopf"] = signed_mean(real)
                f["hopf-hopf"] = signed_mean(upper.real)
            return f
        try:
            a, bt = self._null(x, q)
        except (ShootingError, np.linalg.LinAlgError):
            a = bt = math.nan
        f = {"cusp": a, "bogdanov-takens": bt}
        if point.roots.size:
            f["zero-hopf"] = signed_mean(upper.real)
        return f

    def describe(self, kind: str, x: np.ndarray, q: float, point: CurvePoint
                 ) -> dict[str, Any] | None:
        """The located event checked (see the module); None, with ``why``, when refuted."""
        u, p, omega, _ = self.split(x, q)
        self.why = ""
        if kind in ("zero-hopf", "hopf-hopf"):
            real, upper = self._others(point.roots, omega)
            on = (real if kind == "zero-hopf" and self.kind == "hopf" else upper)
            near = [complex(r) for r in on if abs(complex(r).real) <= ON_AXIS * max(1.0, abs(r))]
            if not near:
                self.why = (f"no {'real root at 0' if on is real else 'other pair on the axis'} "
                            f"there (the rightmost roots {np.round(point.roots[:6], 6)!r}): the "
                            "set of roots computed changed")
                return None
            root = min(near, key=lambda r: abs(r.real))
            what = ("a real root crosses 0" if on is real else
                    f"a pair of roots crosses the imaginary axis at omega = {root.imag:.8g}")
            return {"detail": f"{what} (the root {root:.3g})"}
        if kind == "bautin":
            if point.l1 is None or point.l1_error is None or not abs(point.l1) <= max(
                    10 * point.l1_error, 1e-8):
                self.why = f"l1 = {point.l1!r} is not 0 within its error {point.l1_error!r}"
                return None
            return {"hopf": point.hopf,
                    "detail": f"l1 changes sign (l1 = {point.l1:.3g}, its error "
                              f"{point.l1_error:.3g}) at omega = {omega:.8g}"}
        if kind in ("cusp", "bogdanov-takens"):
            a, bt = self._null(x, q)
            val = a if kind == "cusp" else bt
            # a zero, not a pole: the value at the located point is small at the curve's scale
            if not abs(val) <= 1e-6:
                self.why = f"the test function is {val:.3g} there: a pole, not a zero"
                return None
            what = ("the fold's quadratic coefficient w D^2 f(v, v) changes sign" if kind == "cusp"
                    else "w Delta'(0) v changes sign: a second root at 0 (the Hopf curve "
                         "ends here as omega -> 0)")
            return {"detail": f"{what} ({val:.3g} at the located point)"}
        return {}


def _start(start: Any, u_eq: Any) -> tuple[str, float, np.ndarray, float]:
    """(kind, p, u, omega) of the start: a HopfPoint (with u_eq), or an equilibrium branch's
    ``hopf`` or ``fold`` event."""
    if isinstance(start, HopfPoint):
        if u_eq is None:
            raise ValueError("continue_curve: a HopfPoint start needs u_eq, the equation's "
                             "equilibrium at it (shape (n,))")
        if not (start.omega > 0 and math.isfinite(start.omega)):
            raise ValueError(f"continue_curve: the HopfPoint's omega = {start.omega!r} is not > 0: "
                             "a real root crosses there (start a fold curve from the branch's "
                             "fold event)")
        return "hopf", float(start.p), np.array(u_eq, dtype=float, ndmin=1).ravel(), \
            float(start.omega)
    if isinstance(start, Event) and start.kind == "hopf" and start.hopf is not None \
            and start.u is not None:
        return "hopf", float(start.hopf.p), np.array(start.u, dtype=float), \
            float(start.hopf.omega)
    if isinstance(start, Event) and start.kind == "fold":
        if start.u is None:
            raise ValueError("continue_curve: the fold event has no equilibrium (u None: it was "
                             "not located on the branch); continue the branch with a smaller "
                             "step so that it is")
        return "fold", float(start.p), np.array(start.u, dtype=float), 0.0
    raise ValueError(f"continue_curve: start = {start!r}: give a HopfPoint of the equation (with "
                     "u_eq), or a 'hopf' or 'fold' event of a branch of the equation's "
                     "equilibria (continue_equilibrium from equilibrium(..., of='equation'))")


def continue_curve(start: Any, make2: Callable[[float, float], Solver], q0: float, q_end: float,
                   *, u_eq: Any = None, step: float | None = None, at: Iterable[float] = (),
                   max_points: int = 200, min_step: float | None = None,
                   max_step: float | None = None, tol: float = 1e-10, count: int = ROOTS
                   ) -> Curve:
    """Continues a Hopf point or a fold of the equation's equilibria in the plane (p, q).

    The curve of (p, q) where the equilibrium u of ``make2(p, q)`` has a pair of roots
    +- i omega (a Hopf curve) or a root 0 (a fold curve), followed by pseudo-arclength in
    (u, p, q, omega) from the start at q0 (see :mod:`dmi.analysis.equilibria.curves` for the extended
    systems), through turning points in q, until q_end; with its codimension-two points
    located and checked.  Only the equation's (``of="equation"``) points: the scheme's are
    O(h) off.

    Parameters
    ----------
    start : HopfPoint or Event
        A Hopf point of the equation at q = q0 (``hopf(lambda p: make2(p, q0), ...,
        of="equation")``; then ``u_eq`` is required), or a ``hopf`` or ``fold`` event of a
        branch of the equation's equilibria of ``make2(., q0)`` (its ``u`` the equilibrium).
    make2 : callable
        The model ``make2(p, q) -> dmi.Solver``, configured, not initialised.
    q0 : float
        The start's q.
    q_end : float
        Where to stop (finite, not q0); the last point lies on it exactly when the curve gets
        there.
    u_eq : array_like, optional
        The equation's equilibrium at a HopfPoint start, shape (n,).
    step : float, optional
        The first step (arclength in (u, p, q, omega): p or q units; default |q_end - q0| / 20).
    at : iterable of float
        Values of q where a point is wanted (a ``user`` event each, the point on it exactly).
    max_points : int
        Points at most.
    min_step, max_step : float, optional
        Step bounds (default step / 1000 and 4 step).
    tol : float
        The corrector's tolerance (on G / h and Delta v, relative to max(1, |x|_inf)).
    count : int
        Rightmost roots computed a point (the zero-Hopf and Hopf-Hopf tests read them).

    Returns
    -------
    Curve
        ``kind`` ``"hopf"`` or ``"fold"``, ``points`` (:class:`CurvePoint`: ``p``, ``q``,
        ``u``, ``omega``, ``l1``, ``kappa``, ``hopf``, ``roots``), ``events``
        (:class:`CurveEvent`: ``bautin``, ``zero-hopf``, ``hopf-hopf``, ``cusp``,
        ``bogdanov-takens``, ``user``), ``status`` (it does not raise when the corrector fails
        on the way: the curve ends there, the status says why).

    Raises
    ------
    ValueError
        A start of another kind, a HopfPoint without u_eq, bad q0, q_end, step or at; a start
        that is not a Hopf point or fold of the equation (the corrector does not converge at
        q0: a ShootingError, a ValueError).
    """
    kind, p0, u0, omega0 = _start(start, u_eq)
    q0, q_end, step = curve_range("continue_curve", q0, q_end, step)
    disc, x0 = system(kind, p0, u0, omega0, make2, q0, tol=tol, count=count)
    try:
        options = ContinuationOptions(step=float(step), min_step=min_step, max_step=max_step,
                                      max_points=max_points, at=tuple(at), tol=tol, max_iter=10,
                                      easy=4)
        b = continuation(disc, x0, q0, q_end, options, make=make2, kind=kind)
    except ShootingError as e:
        raise not_a_start(disc, x0, q0, tol, e) from None
    return curve_of(b, disc, omega0)


def _start_matrix(make2: Callable[[float, float], Solver], kind: str, p0: float, q0: float,
                  u0: np.ndarray, omega0: float, of: str, lin_tol: float
                  ) -> tuple[int, np.ndarray, np.ndarray]:
    """(n, the free components, the characteristic matrix at the start: real on a fold)."""
    if of == "scheme":
        with Linearisation(lambda: call_make(make2, p0, q0), u0, (p0, q0), lin_tol,
                           "scheme") as lin:
            M = lin.characteristic(complex(np.exp(1j * omega0 * lin.h)))
            return lin.n, np.arange(lin.n), M if kind == "hopf" else M.real
    s = call_make(make2, p0, q0)
    try:
        n = s.n
        if u0.shape != (n,) or not np.all(np.isfinite(u0)):
            raise ValueError(f"continue_curve: the equilibrium {u0!r} is not n = {n} finite "
                             "numbers")
        ch = Characteristic.at(s, u0, 2.5 * omega0 + 1.0)
    finally:
        s.close()
    return n, ch.free, ch(1j * omega0) if kind == "hopf" else ch(0.0).real


def system(kind: str, p0: float, u0: np.ndarray, omega0: float,
           make2: Callable[[float, float], Solver], q0: float, *, tol: float = 1e-10,
           count: int = ROOTS, given: Callable[[float, float], np.ndarray] | None = None,
           of: str = "equation", lin_tol: float = 1e-9, tests: bool = True
           ) -> tuple[_Extended, np.ndarray]:
    """The extended system of the Hopf (``kind="hopf"``) or fold curve through (p0, q0), u0 the
    equilibrium there and omega0 the crossing frequency, and its start x0, for the driver
    (``given``, ``of``, ``lin_tol`` and ``tests`` as :class:`_Extended`'s)."""
    n, free, M0 = _start_matrix(make2, kind, p0, q0, u0, omega0, of, lin_tol)
    v0 = null_vectors(M0)[0]
    disc = _Extended(make2, kind, n, free, v0.conj() if kind == "hopf" else v0.real, tol,
                     int(count), given=given, of=of, lin_tol=lin_tol, tests=tests)
    disc.reach = 2.5 * omega0 + 1.0
    if kind == "fold":
        disc.b = null_vectors(M0.T)[0].real
    head = [p0] if given is not None else [*u0, p0]
    if kind == "hopf":
        return disc, np.concatenate([head, [omega0], v0.real, v0.imag])
    return disc, np.concatenate([head, v0.real])


def not_a_start(disc: _Extended, x0: np.ndarray, q0: float, tol: float, e: Exception
                ) -> ValueError:
    """The error of a start where the corrector fails."""
    _, p0, _, _ = disc.split(x0, q0)
    return ValueError(f"continue_curve: the start (p, q) = ({p0!r}, {q0!r}) is not a "
                      f"{'Hopf point' if disc.kind == 'hopf' else 'fold'} of the {disc.of}'s "
                      f"equilibria of make2 to the tolerance {tol!r}: the corrector failed "
                      f"there: {e}")


def curve_of(b: Any, disc: _Extended, omega0: float) -> Curve:
    """The :class:`Curve` of the driver's branch b on ``disc``: its points, its events (the
    codimension-two points and the user points), its status in q's words."""
    kind = disc.kind
    points: list[CurvePoint] = list(b.points)
    events: list[CurveEvent] = []
    for e in b.events:
        if e.kind == "user":
            # the driver's index is the landed point's; else the nearest point on that q
            on = [j for j, pt in enumerate(points) if pt.q == e.p]
            i = e.index if e.index in on or not on else min(on, key=lambda j: abs(j - e.index))
            events.append(CurveEvent("user", points[i].p, float(e.p), i, e.detail,
                                     points[i].u))
        elif e.kind in ("bautin", "zero-hopf", "hopf-hopf", "cusp", "bogdanov-takens") \
                and e.u is not None:
            events.append(CurveEvent(e.kind, float(e.u[disc.k]), float(e.p), e.index, e.detail,
                                     np.array(disc.split(e.u, e.p)[0], dtype=float), e.hopf))
        # the driver's "fold" (a turning point in q) and "branch-point" are not the curve's
    # the driver's words for its parameter are p's: here it is q
    status = b.status.replace("p_end", "q_end").replace(" near p = ", " near q = ")
    if kind == "hopf" and not status.startswith(("reached", "left", "max_points")) \
            and points and points[-1].omega < 0.05 * omega0:
        status += (f"; omega fell from {omega0:.6g} to {points[-1].omega:.3g}: a "
                   "Bogdanov-Takens point is near (p, q) = "
                   f"({points[-1].p:.8g}, {points[-1].q:.8g}) (locate it on the fold curve)")
    return Curve(kind=kind, points=points, events=events, status=status, make2=disc.make2)


__all__ = ["Curve", "CurveEvent", "CurvePoint", "continue_curve"]
