# The first Lyapunov coefficient of the equation's Hopf points, the crossing speed, and the
# amplitude coefficients of the orbit born there.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Criticality of a Hopf point of the equation: :func:`criticality`, and the parameter of the
orbit of a given amplitude born there, :func:`predicted_parameter`.

What it holds: the first Lyapunov coefficient l1 of a Hopf point of the continuous equation
u' + A(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0 at an equilibrium u_eq, with its estimated
error and the word ``"supercritical"`` / ``"subcritical"``; the crossing speed Re lambda'(p_H);
the amplitude coefficients kappa of the orbit born there; and the second and third derivatives
of f it needs (the model's derivative hook :meth:`dmi.Solver.set_rhs_derivatives`, or central
differences of f with their error).  What it may import: numpy, the records
(:mod:`dmi.analysis.continuation.branch`), the model's linearisation
(:mod:`dmi.analysis.core.model`), the characteristic matrix
(:mod:`dmi.analysis.equilibria.equation`) and the room's tools
(:mod:`dmi.analysis.equilibria.numerics`); :mod:`dmi.analysis.equilibria.crossing`,
:mod:`dmi.analysis.equilibria.equilibrium` and :mod:`dmi.analysis.equilibria.curves` call it,
so it imports none of them.

The method (docs/stability.md, "Criticality of a Hopf point").  On the free components (those
the resolvent does not hold; A is locally constant on them for dry friction and the box) the
equation reads u' = F(u_t), F(phi) = -f(phi(0)) - int_0^tau H(s) phi(-s) ds, its characteristic
matrix Delta(lambda) = lambda I + f_u + Hhat(lambda) (:class:`dmi.analysis.equilibria.equation.Characteristic`,
near cells included) and its nonlinear terms B = -D^2 f, C = -D^3 f at u_eq (the memory is
linear).  With q, Delta(i omega) q = 0, q^H q = 1, and the row p, p Delta(i omega) = 0,
p Delta'(i omega) q = 1 (Kuznetsov's normalisation, as DDE-BIFTOOL's normal forms):

    h20 = Delta(2 i omega)^-1 B(q, q),   h11 = Delta(0)^-1 B(q, conj q),
    c1  = 1/2 p [B(conj q, h20) + 2 B(q, h11) + C(q, q, conj q)],   l1 = Re c1 / omega.

The crossing speed is Re lambda'(p_H) = -Re p (dDelta/dp)(i omega) q, dDelta/dp by fourth-order
central differences in p (the equilibrium corrected at each p).  On the centre manifold
u = u_eq + 2 Re(w q) + O(|w|^2), |w|^2 = -Re lambda' (p - p_H) / (omega l1), so the orbit's
half range (max - min) / 2 of component j is kappa_j sqrt|p - p_H| with
kappa_j = 2 |q_j| sqrt(|Re lambda'| / (omega |l1|)), on the side where
l1 Re lambda' (p - p_H) < 0.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from ..._errors import Error
from ..continuation.branch import ON_AXIS, HopfPoint
from ..core.model import Linearisation, _call, call_make, equation_step, equilibrium
from .equation import SLOPE, Characteristic, refine
from .numerics import forward_jacobian, null_vectors

EPS = float(np.finfo(float).eps)

#: Fourth-order central stencils of the k-th derivative: offsets (times the step) and weights.
STENCILS = {1: SLOPE[4][:2],
            2: (np.array([-2.0, -1.0, 0.0, 1.0, 2.0]),
                np.array([-1.0, 16.0, -30.0, 16.0, -1.0]) / 12),
            3: (np.array([-3.0, -2.0, -1.0, 1.0, 2.0, 3.0]),
                np.array([1.0, -8.0, 13.0, -13.0, 8.0, -1.0]) / 8)}

#: A derivative hook's d2 or d3 may differ from central differences of f by this much, relative
#: to max(1, |value|) (the differences' own error is about 1e-9 at the unit scale).
HOOK_TOL = 1e-5


class CriticalityWarning(RuntimeWarning):
    """The criticality of a Hopf point, its l1, kappa or crossing speed not reported (None),
    with the reason."""


class _Unavailable(Exception):
    """Why a quantity of the Hopf point is not computed (said in a CriticalityWarning)."""


class _Forms:
    """The second and third derivatives of f(t, .) at u (all n components, complex directions),
    from the model's hook where given, else by the fourth-order central differences of
    :data:`STENCILS` at step level ``level`` (0: twice the step of level 1, which is about
    eps^(1 / (k + 4)) max(1, |u|) for the k-th derivative).  ``rounding`` accumulates a bound on
    the differences' rounding errors since it was last reset."""

    def __init__(self, solver: Any, u: np.ndarray, t: float = 0.0):
        self.s, self.u, self.t, self.n = solver, u, t, u.size
        hook = solver.rhs_derivatives
        self.fu, self.d2, self.d3 = hook if hook is not None else (None, None, None)
        self.scale = max(1.0, float(np.max(np.abs(u))))
        self.level = 1
        self.rounding = 0.0

    @property
    def exact(self) -> bool:
        """Both forms from the hook (no differences)."""
        return self.d2 is not None and self.d3 is not None

    def _hook(self, g: Callable[..., Any], name: str, x: np.ndarray, *dirs: np.ndarray
              ) -> np.ndarray:
        """The hook g(t, x, *dirs), checked: n finite numbers (a Jacobian for fu: n x n)."""
        try:
            out = np.array(g(float(self.t), np.array(x, dtype=float),
                             *[np.array(d, dtype=float) for d in dirs]), dtype=float)
        except BaseException as e:
            e.add_note(f"dmi.analysis: raised by the model's derivative {name} at u = {x!r}")
            raise
        shape = (self.n, self.n) if name == "fu" else (self.n,)
        if out.shape != shape or not np.all(np.isfinite(out)):
            raise ValueError(f"dmi.analysis: the derivative hook {name} of set_rhs_derivatives "
                             f"returned {out!r} at u = {x!r}: give {shape} finite numbers")
        return out

    def f(self, x: np.ndarray) -> np.ndarray:
        return _call(self.s, "rhs", self.t, x)

    def diff(self, g: Callable[[np.ndarray], np.ndarray], k: int, v: np.ndarray) -> np.ndarray:
        """d^k/dt^k g(u + t v) at t = 0 by the stencil of order k at this level."""
        nv = float(np.max(np.abs(v)))
        if nv == 0:
            return np.zeros(self.n)
        d = v / nv
        h = 2.0 ** (1 - self.level) * EPS ** (1.0 / (k + 4)) * self.scale
        offsets, w = STENCILS[k]
        vals = np.array([g(self.u + o * h * d) for o in offsets])
        self.rounding += (8 * EPS * float(np.sum(np.abs(w))) * float(np.max(np.abs(vals)))
                          / h ** k * nv ** k)
        return (w @ vals) / h ** k * nv ** k

    def b_real(self, v: np.ndarray, w: np.ndarray, same: bool = False) -> np.ndarray:
        """D^2 f(u)(v, w), v and w real."""
        if self.d2 is not None:
            return self._hook(self.d2, "d2", self.u, v, w)
        if self.fu is not None:
            return self.diff(lambda x: self._hook(self.fu, "fu", x) @ v, 1, w)
        if same:
            return self.diff(self.f, 2, v)
        return (self.diff(self.f, 2, v + w) - self.diff(self.f, 2, v - w)) / 4

    def c_real(self, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
        """D^3 f(u)(a, b, c), real directions, from d3 or differences of d2 (the path without
        them is :meth:`c_qqq`'s)."""
        if self.d3 is not None:
            return self._hook(self.d3, "d3", self.u, a, b, c)
        return self.diff(lambda x: self._hook(self.d2, "d2", x, a, b), 1, c)

    def b(self, a: np.ndarray, c: np.ndarray) -> np.ndarray:
        """D^2 f(u)(a, c), a and c complex (the bilinear extension; a is c: B(q, q) =
        B(x, x) - B(y, y) + 2 i B(x, y))."""
        ar, ai, cr, ci = a.real, a.imag, c.real, c.imag
        out = np.zeros(self.n, dtype=complex)
        if a is c:
            pairs = ((ar, ar, 1.0), (ai, ai, -1.0), (ar, ai, 2j))
        else:
            pairs = ((ar, cr, 1.0), (ai, ci, -1.0), (ar, ci, 1j), (ai, cr, 1j))
        for v, w, unit in pairs:
            if np.any(v) and np.any(w):
                out += unit * self.b_real(v, w, same=np.array_equal(v, w))
        return out

    def c_qqq(self, q: np.ndarray) -> np.ndarray:
        """D^3 f(u)(q, q, conj q) = C(x,x,x) + C(x,y,y) + i (C(x,x,y) + C(y,y,y)), q = x + i y;
        without d2 and d3 from the four cubes T(v) = d^3/dt^3 f(u + t v) at x, y, x + y, x - y."""
        x, y = q.real.copy(), q.imag.copy()
        if self.d3 is None and self.d2 is None:
            T = {k: self.diff(self.f, 3, v) for k, v in
                 (("x", x), ("y", y), ("+", x + y), ("-", x - y))}
            cxxy = ((T["+"] - T["-"]) / 2 - T["y"]) / 3
            cxyy = ((T["+"] + T["-"]) / 2 - T["x"]) / 3
            return T["x"] + cxyy + 1j * (cxxy + T["y"])
        return (self.c_real(x, x, x) + self.c_real(x, y, y)
                + 1j * (self.c_real(x, x, y) + self.c_real(y, y, y)))


def _corrected(s: Any, u0: np.ndarray) -> np.ndarray:
    """The equation's equilibrium near u0 by Newton on G(u) = R(X(u)) - u (the Jacobian by
    forward differences), to rounding."""
    G = equation_step(s)
    u = np.array(u0, dtype=float)
    last = math.inf
    for _ in range(30):
        g = G(u)
        du = np.linalg.solve(forward_jacobian(G, u, g), -g)
        u = u + du
        size = float(np.max(np.abs(du)))
        if size <= 4 * EPS * max(1.0, float(np.max(np.abs(u)))):
            return u
        if size >= 0.5 * last:     # stalled at rounding: accepted only with a small residual
            if float(np.max(np.abs(G(u)))) <= 1e-9 * max(1.0, float(np.max(np.abs(u)))):
                return u
            raise _Unavailable(f"the equilibrium near u = {u0!r} could not be corrected (Newton "
                               f"stalled with the residual {float(np.max(np.abs(G(u)))):.3g})")
        last = size
    raise _Unavailable(f"the equilibrium near u = {u0!r} could not be corrected (Newton did not "
                       "settle in 30 iterations)")


def _characteristic(make: Any, p: float, u: np.ndarray, tol: float, reach: float
                    ) -> Characteristic:
    """Delta of the equation of make(p) at its equilibrium u."""
    with Linearisation(lambda: call_make(make, p), u, (p,), tol, "equation") as lin:
        return Characteristic(lin, reach)


def _crossing_speed(make: Any, p: float, u_eq: Any, u: np.ndarray, omega: float,
                    q: np.ndarray, prow: np.ndarray, free: np.ndarray, tol: float,
                    reach: float) -> tuple[float, float]:
    """(Re lambda'(p), its estimated error): -Re p dDelta/dp(i omega) q, dDelta/dp by the
    fourth-order central difference of step delta = 1e-3 max(1, |p|), the error its difference
    from the same with step 2 delta."""
    delta = 1e-3 * max(1.0, abs(p))
    D = {}
    for j in (-4, -2, -1, 1, 2, 4):
        pj = p + j * delta
        try:
            s = call_make(make, pj)
            try:
                u0 = equilibrium(u_eq, s.n, (pj,)) if callable(u_eq) else u
                uj = _corrected(s, u0)
            finally:
                s.close()
            ch = _characteristic(make, pj, uj, tol, reach)
        except (np.linalg.LinAlgError, ArithmeticError, ValueError, RuntimeError, Error) as e:
            raise _Unavailable(f"the equilibrium or its characteristic matrix at p = {pj!r} "
                               f"(for the difference in p): {type(e).__name__}: {e}") from e
        if not np.array_equal(ch.free, free):
            raise _Unavailable(f"the components the resolvent holds change between p = {p!r} "
                               f"and {pj!r}: no crossing speed (the Hopf point is at a switch)")
        D[j] = ch(1j * omega)
    speed = []
    for k in (1, 2):
        dD = (D[-2 * k] - 8 * D[-k] + 8 * D[k] - D[2 * k]) / (12 * k * delta)
        speed.append(float((-(prow @ dD @ q)).real))
    return speed[0], abs(speed[0] - speed[1])


def _c1(forms: _Forms, ch: Characteristic, q: np.ndarray, prow: np.ndarray,
        inv2: np.ndarray, inv0: np.ndarray) -> tuple[complex, float, float]:
    """(c1, a bound on its rounding from the differences, the magnitude of its terms)."""
    free, n = ch.free, forms.n

    def full(v: np.ndarray) -> np.ndarray:
        out = np.zeros(n, dtype=complex)
        out[free] = v
        return out

    forms.rounding = 0.0
    qf = full(q)
    Bqq = forms.b(qf, qf)[free]
    Bqqb = forms.b(qf, full(q.conj()))[free].real
    r_bqq = forms.rounding
    # B = -D^2 f, C = -D^3 f: h20, h11 change sign with B, the quadratic terms of c1 do not
    h20 = -(inv2 @ Bqq)
    h11 = -(inv0 @ Bqqb)
    forms.rounding = 0.0
    t1 = -forms.b(full(q.conj()), full(h20))[free]
    t2 = -2 * forms.b(qf, full(h11))[free]
    r_b = forms.rounding
    forms.rounding = 0.0
    t3 = -forms.c_qqq(qf)[free]
    r_c = forms.rounding
    pn = float(np.linalg.norm(prow))
    norm_b = max(float(np.linalg.norm(Bqq)), float(np.linalg.norm(Bqqb)))
    rounding = 0.5 * pn * (r_c + r_b + 3 * norm_b * (np.linalg.norm(inv2, 2)
                                                     + np.linalg.norm(inv0, 2)) * r_bqq)
    size = 0.5 * pn * float(np.linalg.norm(t1) + np.linalg.norm(t2) + np.linalg.norm(t3))
    return complex(0.5 * prow @ (t1 + t2 + t3)), rounding, size


def _check_hooks(forms: _Forms, x: np.ndarray) -> None:
    """d2 and d3 of the hook against central differences of f along x (ValueError naming the
    hook where they disagree)."""
    plain = _Forms(forms.s, forms.u, forms.t)
    plain.fu = plain.d2 = plain.d3 = None
    for name, hook, k, dirs in (("d2", forms.d2, 2, (x, x)), ("d3", forms.d3, 3, (x, x, x))):
        if hook is None:
            continue
        got = forms._hook(hook, name, forms.u, *dirs)
        want = plain.diff(plain.f, k, x)
        gap = float(np.max(np.abs(got - want)))
        if gap > HOOK_TOL * max(1.0, float(np.max(np.abs(want)))):
            raise ValueError(f"dmi.analysis: the derivative hook {name} of set_rhs_derivatives "
                             f"disagrees with central differences of f at u = {forms.u!r} in the "
                             f"direction {x!r} by {gap:.3g} ({name} = {got!r}, differences "
                             f"{want!r}): correct {name}")


def criticality(make: Callable[[float], Any], hopf_point: HopfPoint, u_eq: Any, *,
                tol: float = 1e-9) -> HopfPoint:
    """The Hopf point with its first Lyapunov coefficient, criticality, amplitude coefficients
    and crossing speed (the equation's; see the module for the method).

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver``.
    hopf_point : HopfPoint
        A Hopf point of the equation (``hopf(..., of="equation")``, or a ``hopf`` event of a
        branch of the equation's equilibria), omega > 0.
    u_eq : array_like or callable
        The equation's equilibrium at ``hopf_point.p``, shape (n,), or a function ``u_eq(p)``
        (then also used near p for the crossing speed; an array is corrected by Newton there).
    tol : float
        The equilibrium-residual tolerance (as :func:`dmi.analysis.roots`').

    Returns
    -------
    HopfPoint
        ``hopf_point`` with ``l1``, ``l1_error``, ``criticality``, ``kappa`` and
        ``crossing_speed`` set; each that cannot be computed or verified stays None, with a
        :class:`CriticalityWarning` saying why.

    Raises
    ------
    ValueError
        A derivative hook (:meth:`dmi.Solver.set_rhs_derivatives`) that returns values of the
        wrong shape, or disagrees with central differences of f; the errors of
        :func:`dmi.analysis.roots` (u_eq not an equilibrium).
    """
    omega0 = float(hopf_point.omega)
    p = float(hopf_point.p)
    if not (omega0 > 0 and math.isfinite(omega0)):
        return hopf_point
    try:
        return _criticality(make, hopf_point, u_eq, tol)
    except _Unavailable as why:
        warnings.warn(f"dmi.analysis: no first Lyapunov coefficient at the Hopf point p = {p!r}: "
                      f"{why}", CriticalityWarning, stacklevel=3)
        return hopf_point


def _vectors(ch: Characteristic, lam: complex) -> tuple[np.ndarray, np.ndarray, float]:
    """(q, p, the condition of q): Delta(lambda) q = 0 with |q| = 1, p Delta(lambda) = 0 with
    p Delta'(lambda) q = 1 (Delta' of order 4)."""
    q, prow, sv = null_vectors(ch(lam))
    if ch.m > 1 and sv[-2] <= 1e-8 * sv[0]:
        raise _Unavailable("the null space of Delta(i omega) is not one-dimensional (singular "
                           f"values {sv!r}): a double root")
    norm = complex(prow @ ch.prime(lam, order=4) @ q)
    if abs(norm) <= 1e-10 * np.linalg.norm(prow):
        raise _Unavailable("p Delta'(i omega) q = 0: the root is not simple")
    return q, prow / norm, (sv[0] / sv[-2] if ch.m > 1 else 1.0)


def _inverses(ch: Characteristic, omega: float) -> tuple[np.ndarray, np.ndarray, float]:
    """(Delta(2 i omega)^-1, Delta(0)^-1, the sum of their condition numbers)."""
    M2, M0 = ch(2j * omega), ch(0.0)
    conds = 0.0
    for name, M in (("Delta(2 i omega)", M2), ("Delta(0)", M0)):
        c = np.linalg.cond(M)
        if not c <= 1e10:
            raise _Unavailable(f"{name} is singular (condition {c:.3g}): "
                               + ("a root at 2 i omega (a 1:2 resonance)" if M is M2 else
                                  "a root at 0 as well (a zero-Hopf point)"))
        conds += c
    return np.linalg.inv(M2), np.linalg.inv(M0), conds


def _first_coefficient(s: Any, u: np.ndarray, ch: Characteristic, q: np.ndarray,
                       prow: np.ndarray, cond_q: float, omega: float) -> tuple[complex, float]:
    """(c1, its estimated error): the differences' rounding, their truncation (c1 again at
    twice the steps, without the hook's d2 and d3) and the linear algebra's rounding."""
    inv2, inv0, conds = _inverses(ch, omega)
    forms = _Forms(s, u)
    if forms.d2 is not None or forms.d3 is not None:
        x = np.zeros(s.n)
        x[ch.free] = q.real if np.any(q.real) else q.imag
        _check_hooks(forms, x / np.max(np.abs(x)))
    forms.level = 1
    c1, rounding, size = _c1(forms, ch, q, prow, inv2, inv0)
    err = rounding
    if not forms.exact:
        forms.level = 0
        c1_coarse, _, _ = _c1(forms, ch, q, prow, inv2, inv0)
        err += abs(c1.real - c1_coarse.real)
    # the linear algebra's rounding, and (without fu) the Jacobian's differences, ~1e-10
    err += size * (1e3 * EPS * (cond_q + conds) + (1e-9 * cond_q if forms.fu is None else 0.0))
    return c1, err


def _criticality(make: Any, hp: HopfPoint, u_eq: Any, tol: float) -> HopfPoint:
    p, omega0 = float(hp.p), float(hp.omega)
    reach = 2.5 * omega0 + 1.0
    s = call_make(make, p)
    try:
        if s.resolvent_kind == "callback":
            raise _Unavailable("the model's A is a resolvent callback: the second and third "
                               "derivatives of A that l1 needs are not computed (put the "
                               "nonlinear terms in f, or use the built-in friction or box)")
        u = _corrected(s, equilibrium(u_eq, s.n, (p,)))
        ch = _characteristic(make, p, u, tol, reach)
        lam, why = refine(ch, complex(0.0, omega0))
        if why or not abs(lam.imag - omega0) <= 1e-6 * omega0:
            raise _Unavailable(f"the root i omega = {1j * omega0!r} of the equation could not be "
                               f"refined ({why or f'it converged to {lam!r}'})")
        if not abs(lam.real) <= ON_AXIS * max(1.0, abs(lam)):
            raise _Unavailable(f"not a Hopf point: the root refined from i omega = "
                               f"{1j * omega0!r} is {lam!r}, off the imaginary axis")
        omega = lam.imag
        q, prow, cond_q = _vectors(ch, lam)
        c1, err = _first_coefficient(s, u, ch, q, prow, cond_q, omega)
    finally:
        s.close()
    l1 = c1.real / omega
    l1_error = err / omega
    word = None
    if abs(l1) > l1_error:
        word = "supercritical" if l1 < 0 else "subcritical"
    out = dataclasses.replace(hp, l1=float(l1), l1_error=float(l1_error), criticality=word)
    try:
        speed, speed_err = _crossing_speed(make, p, u_eq, u, omega, q, prow, ch.free, tol, reach)
    except _Unavailable as why:
        warnings.warn(f"dmi.analysis: no crossing speed (nor kappa) at the Hopf point p = {p!r}: "
                      f"{why}", CriticalityWarning, stacklevel=4)
        return out
    if not abs(speed) > 10 * speed_err:
        warnings.warn(f"dmi.analysis: the Hopf point p = {p!r} has a crossing speed {speed:.6g} "
                      f"not distinct from 0 (its error {speed_err:.3g}): no crossing speed, no "
                      "kappa and no side (the orbit does not grow as sqrt|p - p_H|)",
                      CriticalityWarning, stacklevel=4)
        return out
    out = dataclasses.replace(out, crossing_speed=speed)
    if word is None:
        warnings.warn(f"dmi.analysis: the Hopf point p = {p!r} has l1 = {l1:.6g} within its "
                      f"estimated error {l1_error:.3g}: its criticality is not decided (a "
                      "degenerate Hopf point, or differences of f too inaccurate: give "
                      "Solver.set_rhs_derivatives), and no kappa", CriticalityWarning,
                      stacklevel=4)
        return out
    kappa = np.zeros(len(u))
    kappa[ch.free] = 2 * np.abs(q) * math.sqrt(abs(speed) / (omega * abs(l1)))
    return dataclasses.replace(out, kappa=kappa)


def predicted_parameter(hopf_point: HopfPoint, amplitude: float,
                        component: int | None = None) -> float:
    """The parameter where the orbit born at a Hopf point has a given amplitude, to leading
    order: p = p_H + side (A / kappa_j)^2.

    The orbit's half range (max - min) / 2 of component j grows as kappa_j sqrt|p - p_H| on the
    side where it exists (``hopf_point.side``: the sign of -l1 Re lambda'(p_H)), so a wanted
    amplitude A of that component is met near p_H + side (A / kappa_j)^2, off by O(A^4): the
    predictor of an orbit of amplitude A.

    Parameters
    ----------
    hopf_point : HopfPoint
        A Hopf point of the equation with its ``kappa`` and ``side``
        (:func:`criticality`: ``hopf(..., of="equation")``, a ``hopf`` event of a branch of
        the equation's equilibria).
    amplitude : float
        A, the wanted (max - min) / 2 of component j (state units), finite and > 0.
    component : int, optional
        j; default the component that moves most (the largest kappa_j).

    Returns
    -------
    float
        The predicted parameter.

    Raises
    ------
    ValueError
        A hopf_point without kappa or side (the scheme's, or one whose criticality or crossing
        speed is not decided: its CriticalityWarning said why), an amplitude that is not finite
        and > 0, a component out of range or whose kappa is 0 (a held component).
    """
    if not isinstance(hopf_point, HopfPoint):
        raise ValueError(f"predicted_parameter: hopf_point = {hopf_point!r}: give a "
                         "dmi.analysis.HopfPoint")
    kappa, side = hopf_point.kappa, hopf_point.side
    if kappa is None or side is None:
        raise ValueError(f"predicted_parameter: the Hopf point at p = {hopf_point.p!r} has no "
                         "kappa (the scheme's, or its criticality or crossing speed not "
                         "decided): compute it with hopf(..., of='equation')")
    a = float(amplitude)
    if not (a > 0 and math.isfinite(a)):
        raise ValueError(f"predicted_parameter: amplitude = {amplitude!r}: give a finite "
                         "amplitude > 0 (state units)")
    kappa = np.asarray(kappa, dtype=float)
    j = int(np.argmax(kappa)) if component is None else component
    if not (isinstance(j, (int, np.integer)) and 0 <= j < kappa.size and kappa[j] > 0):
        raise ValueError(f"predicted_parameter: component = {component!r}: give an index in "
                         f"[0, {kappa.size}) whose kappa is > 0 (kappa = {kappa!r})")
    return float(hopf_point.p) + side * (a / float(kappa[j])) ** 2


__all__ = ["CriticalityWarning", "criticality", "predicted_parameter"]
