# The scheme's step map linearised at a constant history, and its tangent map run by libdmi.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The linearisation shared by the analyses of dmi.analysis; private to the package.

A model is ``make(p) -> dmi.Solver`` (configured, not initialised).  The scheme's step map is

    U^{p+1} = R(X^p),   X^p = U^p - h f(t_p, U^p) - h W^p,   W^p = h sum_{l<N} H(l h) U^{p-l},

R the resolvent (I + hA)^{-1}.  Its state is the window (U^{p-N+1}, ..., U^p), n N numbers.  At a
constant history u_eq with X* = u_eq - h f(u_eq) - h W* the linearisation is

    dU^{p+1} = D (dU^p - h J dU^p - h dW^p),   J = f_u(u_eq),   D = R'(X*),

the same scheme with f(t, u) = J u, resolvent D x and the model's own kernel and convolution
method: the *tangent solver*, a second solver from ``make`` whose rhs and resolvent are replaced by
``dmi_py_linear`` (python/run.c), so that the tangent map runs in C at the speed of a simulation.
"""
from __future__ import annotations

import ctypes
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ... import _lib
from ... import _resolvent as rule
from ..._make import call_make  # noqa: F401  (the equilibria's model calls)
from ..._solver import Solver
from ..._transform import laplace, near_shift

#: Relative step of the central differences of f and of a user resolvent: about eps^(1/3).
FD_STEP = 2.0 ** -17
#: A built-in resolvent's argument closer than this (relative) to a kink is reported as on it.
KINK_TOL = 1e-9
#: Gauss-Legendre nodes per panel of a callback kernel's quadrature (:func:`kernel_panels`).
PANEL_NODES = 16


class KinkError(ValueError):
    """The resolvent is not differentiable at the equilibrium's argument X* (a kink: dry friction
    sticking exactly at its threshold, a box constraint exactly on its face); a ``ValueError``.

    Parameters
    ----------
    message : str
        Which component, and where.
    """


def equilibrium(u_eq: Any, n: int, args: tuple) -> np.ndarray:
    """u_eq as a float array (n,): an array, or a function of the model's parameters."""
    u = u_eq(*args) if callable(u_eq) else u_eq
    a = np.array(u, dtype=float, ndmin=1)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"dmi.analysis: u_eq = {u!r} is not {n} finite numbers (the model's n)")
    return a


class _Matrix:
    """An n x n matrix as the C struct dmi_py_matrix {size_t n; double m[];} of python/run.c."""

    def __init__(self, M: np.ndarray):
        n = M.shape[0]
        cls = type("dmi_py_matrix", (ctypes.Structure,),
                   {"_fields_": [("n", ctypes.c_size_t), ("m", ctypes.c_double * (n * n))]})
        self.c = cls()
        self.c.n = n
        self.c.m[:] = [float(x) for x in np.ravel(M)]


def _checked(values: np.ndarray, what: str, x: Any) -> np.ndarray:
    """values, or ValueError when one is not finite."""
    if not np.all(np.isfinite(values)):
        raise ValueError(f"dmi.analysis: the model's {what} is not finite at {x!r}: {values!r}")
    return values


def _call(solver: Solver, what: str, first: float, x: np.ndarray) -> np.ndarray:
    """The model's rhs f(first, x) or resolvent (first = lam) at x, through the solver's own
    callback: out (n,), finite."""
    try:
        if what == "rhs":
            out = solver.eval_rhs(first, x)
        else:
            out = solver.eval_resolvent(first, x)
    except BaseException as e:
        e.add_note(f"dmi.analysis: raised by the model's {what} at {x!r}")
        raise
    return _checked(out, what, x)


def _call_kernel(solver: Solver, s: float) -> np.ndarray:
    """The model's kernel H(s) (n, n), finite."""
    try:
        out = solver.eval_kernel(s)
    except BaseException as e:
        e.add_note(f"dmi.analysis: raised by the model's kernel at s = {s!r}")
        raise
    return _checked(out, "kernel", s)


def _central(g: Callable[[np.ndarray], np.ndarray], x: np.ndarray, scale: float,
             kink: str | None) -> np.ndarray:
    """Jacobian of g at x by central differences, step FD_STEP max(|x_j|, scale); with kink (a
    name), one-sided differences that disagree raise KinkError."""
    n = len(x)
    Jac = np.empty((n, n))
    g0 = g(x) if kink else None
    for j in range(n):
        e = np.zeros(n)
        e[j] = FD_STEP * max(abs(x[j]), scale)
        gp, gm = g(x + e), g(x - e)
        Jac[:, j] = (gp - gm) / (2 * e[j])
        if kink:
            fwd, bwd = (gp - g0) / e[j], (g0 - gm) / e[j]
            if np.max(np.abs(fwd - bwd)) > 1e-3 * max(1.0, np.max(np.abs(Jac[:, j]))):
                raise KinkError(f"dmi.analysis: the {kink} is not differentiable at X*[{j}] = "
                                f"{x[j]!r} (one-sided derivatives {fwd!r} and {bwd!r}): a kink "
                                "(sticking exactly at the threshold?)")
    return Jac


#: The Jacobian of a derivative hook may differ from central differences of f by this much,
#: relative to max(1, |J|) (the differences' own error is about 1e-10).
HOOK_TOL = 1e-6


def rhs_jacobian(s: Solver, t: float, u: np.ndarray) -> np.ndarray:
    """f_u(t, u) (n x n): the model's derivative hook ``fu`` (:meth:`dmi.Solver.set_rhs_derivatives`),
    checked against central differences of f (ValueError naming the hook where they disagree),
    or those differences where no hook is set; 0 without a right-hand side."""
    n = s.n
    if not s.has("rhs"):
        return np.zeros((n, n))
    J = _central(lambda x: _call(s, "rhs", t, x), u, np.max(np.abs(u)) or 1.0, None)
    hook = s.rhs_derivatives
    if hook is None:
        return J
    try:
        Jh = np.array(hook[0](float(t), np.array(u, dtype=float)), dtype=float)
    except BaseException as e:
        e.add_note(f"dmi.analysis: raised by the model's derivative fu at t = {t!r}, u = {u!r}")
        raise
    if Jh.shape != (n, n) or not np.all(np.isfinite(Jh)):
        raise ValueError(f"dmi.analysis: the derivative hook fu(t, u) of set_rhs_derivatives "
                         f"returned {Jh!r} at u = {u!r}: give n x n = {n} x {n} finite numbers")
    gap = float(np.max(np.abs(Jh - J)))
    if gap > HOOK_TOL * max(1.0, float(np.max(np.abs(J)))):
        raise ValueError(f"dmi.analysis: the derivative hook fu of set_rhs_derivatives disagrees "
                         f"with central differences of f at u = {u!r} by {gap:.3g} (fu = {Jh!r}, "
                         f"differences {J!r}): correct fu (df_i/du_j in row i, column j)")
    return Jh


def _resolvent_derivative(s: Solver, X: np.ndarray, h: float, scale: float) -> np.ndarray:
    """D = R'(X): exact for the built-in friction and box (:mod:`dmi._resolvent`, libdmi's
    rule), central differences for a callback; KinkError where X is on a kink."""
    n = s.n
    kind = s.resolvent_kind
    if kind == "friction":
        lam = h * s.friction
        for i in range(n):
            if lam[i] != 0 and rule.near(abs(X[i]), lam[i], KINK_TOL):
                raise KinkError(f"dmi.analysis: dry friction component {i} sticks exactly at its "
                                f"threshold (|X*| = {abs(X[i])!r}, h alpha = {lam[i]!r}): a kink "
                                "of the resolvent, no linearisation there")
        return np.diag(rule.friction_slope(X, lam))
    if kind == "box":
        lo, hi = s.box
        for i in range(n):
            for b in (lo[i], hi[i]):
                if np.isfinite(b) and rule.near(X[i], b, KINK_TOL):
                    raise KinkError(f"dmi.analysis: box component {i}: X*[{i}] = {X[i]!r} is on "
                                    f"the face {b!r}: a kink of the projection, no linearisation "
                                    "there")
        return np.diag(rule.box_slope(X, lo, hi))
    if kind != "callback":
        return np.eye(n)
    return _central(lambda x: _call(s, "resolvent", h, x), X, scale, "resolvent")


def resolvent_of(s: Solver) -> Callable[[np.ndarray], np.ndarray]:
    """The model's resolvent (I + h A)^-1 as a function of X: the built-in friction (a soft
    threshold by h alpha) or box (a clip), a callback, or the identity."""
    h = s.h
    if s.resolvent_kind in ("friction", "box", ""):
        return lambda X: s.eval_resolvent(h, X)
    return lambda X: _call(s, "resolvent", h, X)


def rhs_of(s: Solver, t: float = 0.0) -> Callable[[np.ndarray], np.ndarray]:
    """The model's f(t, u) as a function of u (0 without a right-hand side)."""
    if not s.has("rhs"):
        return lambda u: np.zeros(s.n)
    return lambda u: _call(s, "rhs", t, u)


def kernel_of(s: Solver) -> tuple[tuple | None, Callable[[float], np.ndarray] | None]:
    """The model's kernel: (the exponential-sum terms (a, b, C, D) of ``set_kernel_exp``, None)
    or (None, H(s) -> (n, n) of a callback), (None, None) without a kernel."""
    kind = s.kernel_kind
    if kind == "exp":
        return s.kernel_terms, None
    if kind == "callback":
        return None, (lambda x: _call_kernel(s, x))
    return None, None


def _panels(length: float, tau: float, reach: float) -> int:
    """Panels of width at most min(tau / 8, 1 / reach) on a piece of [0, tau] of that length."""
    return max(1, math.ceil(8 * length / tau), math.ceil(length * reach))


def kernel_panels(call: Callable[[float], np.ndarray], tau: float, reach: float,
                  jumps: Sequence[float] = ()) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes s, weights w and kernel samples H(s) (k, n, n) on panels of [0, tau]
    of width at most min(tau / 8, 1 / reach), PANEL_NODES nodes each; the lags ``jumps`` inside
    (0, tau) where H jumps are panel edges (each piece between them is integrated on its own, so
    that a jump costs no accuracy)."""
    x, wx = np.polynomial.legendre.leggauss(PANEL_NODES)
    cuts = sorted({0.0, float(tau)} | {float(j) for j in jumps if 0.0 < j < tau})
    edges = np.concatenate([np.linspace(a, b, _panels(b - a, tau, reach) + 1)[:-1]
                            for a, b in zip(cuts[:-1], cuts[1:])] + [[float(tau)]])
    half = 0.5 * np.diff(edges)
    s = (edges[:-1, None] + half[:, None] * (x[None, :] + 1)).ravel()
    w = (half[:, None] * wx[None, :]).ravel()
    H = np.array([call(float(si)) for si in s])
    return s, w, H


def kernel_integral(s: Solver, jumps: Sequence[float] = ()) -> np.ndarray:
    """int_0^tau H(s) ds (n x n) of the model's kernel: Hhat(0) in closed form for an
    exponential sum (with a fitted singular kernel's exact near part), by the panels'
    quadrature for a callback (piecewise between its declared ``jumps``, lags in (0, tau)), 0
    without a kernel."""
    terms, kernel = kernel_of(s)
    if terms is not None:
        near = near_shift(s)      # a fitted singular kernel: exact on [0, delta]
        return np.real(laplace(0.0, *terms, tau=s.tau) + (near(0.0) if near else 0.0))
    if kernel is not None:
        _, w, H = kernel_panels(kernel, s.tau, 1.0, jumps)
        return np.tensordot(w, H, axes=(0, 0))
    return np.zeros((s.n, s.n))


def equation_terms(s: Solver, jumps: Sequence[float] = ()
                   ) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """u -> (X, G): the resolvent's argument X = u - h f(0, u) - h K u with the continuous
    integral K = int_0^tau H (the scheme's has h sum_l H(l h) for K; a callback kernel's declared
    ``jumps`` cut its quadrature), and G(u) = R(X) - u, zero at the equation's equilibria."""
    h, f, R, K = s.h, rhs_of(s), resolvent_of(s), kernel_integral(s, jumps)

    def terms(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        X = u - h * f(u) - h * (K @ u)
        return X, R(X) - u
    return terms


def equation_step(s: Solver) -> Callable[[np.ndarray], np.ndarray]:
    """G(u) of :func:`equation_terms`."""
    terms = equation_terms(s)
    return lambda u: terms(u)[1]


def checked_equilibrium(s: Solver, u: np.ndarray, args: tuple, tol: float, of: str,
                        jumps: Sequence[float] = ()) -> tuple[np.ndarray, float]:
    """(X*, t0): the resolvent's argument at the equilibrium u and the step's time, after
    checking that one step of the scheme from the constant history u (or, ``of="equation"``,
    of the equation's step with the continuous integral, cut at a callback kernel's declared
    ``jumps``) moves it by at most tol times max(1, |u|, |u - X*|); ValueError naming the move
    otherwise.  The scheme's check initialises s."""
    t0 = 0.0
    if of == "equation":
        X, moved = equation_terms(s, jumps)(u)
    else:
        s.init()
        s.set_window(np.tile(u, (s.N + 1, 1)))
        t0 = s.time
        s.step()
        _, X = s.step_terms()
        moved = s.state - u
    scale = max(1.0, np.max(np.abs(u)), np.max(np.abs(u - X)))
    res = np.max(np.abs(moved))
    if not res <= tol * scale:
        raise ValueError(f"dmi.analysis: u_eq = {u!r} is not an equilibrium of the "
                         f"{'equation' if of == 'equation' else 'step map'} "
                         f"at {args!r}: one step moves it by {moved!r} (max {res:.3g}, "
                         f"{res / scale:.3g} relative to max(1, |u_eq|, |u_eq - X*|) = "
                         f"{scale:.3g}; tolerance {tol:g}): correct it with "
                         "dmi.analysis.equilibrium")
    return X, t0


class Linearisation:
    """The step map of the model's solver linearised at the constant history u_eq, and the
    tangent solver that applies it (:meth:`apply`).  Use as a context manager (frees both)."""

    def __init__(self, factory: Callable[[], Solver], u_eq: Any, args: tuple = (),
                 tol: float = 1e-9, of: str = "scheme"):
        s = factory()
        try:
            self._linearise(s, u_eq, args, tol, of)
        finally:
            s.close()
        t = factory()
        try:
            self._rhs, self._res = _Matrix(self.J), _Matrix(self.D)
            t.set_rhs(_lib.pylib.dmi_py_linear, self._rhs.c)
            t.set_resolvent(_lib.pylib.dmi_py_linear, self._res.c)
            t.init()
        except BaseException:
            t.close()
            raise
        self.tangent = t
        self._window = np.zeros((self.N + 1, self.n))
        # what the equation's characteristic matrix needs (dmi.analysis.equilibria.equation)
        self.resolvent_kind = s.resolvent_kind if s.resolvent_kind != "callback" else ""
        self.kernel_terms, self.kernel = kernel_of(t)

    def _linearise(self, s: Solver, u_eq: Any, args: tuple, tol: float, of: str) -> None:
        """J, D and the equilibrium's check: one step of the scheme from the constant history
        u_eq, or (``of="equation"``) of the equation's step with the continuous integral."""
        n, N = s.n, s.N
        u = equilibrium(u_eq, n, args)
        h = s.h
        X, t0 = checked_equilibrium(s, u, args, tol, of)
        scale_u = max(np.max(np.abs(u)), np.max(np.abs(X))) or 1.0
        J = rhs_jacobian(s, t0, u)
        self.D = _resolvent_derivative(s, X, h, scale_u)
        self.J, self.u_eq, self.X = J, u, X
        self.n, self.N, self.h, self.tau = n, N, h, s.tau

    @property
    def dim(self) -> int:
        """Dimension n N of the step map's state."""
        return self.n * self.N

    def apply(self, v: np.ndarray, steps: int) -> np.ndarray:
        """M^steps v for a state v (n N,) (the window's last N rows, oldest first), real."""
        w = self._window
        w[0] = 0.0           # U^{p-N}: not read by the step map
        w[1:] = np.reshape(v, (self.N, self.n))
        self.tangent.set_window(w)
        self.tangent.advance(steps)
        return self.tangent.get_window()[1:].reshape(-1)

    def characteristic(self, z: complex) -> np.ndarray:
        """The scheme's characteristic matrix at the multiplier z (n x n, complex): column j is
        one tangent step of the mode U^(p-k) = z^(-k) e_j (k = 0 .. N) less z e_j, so that a
        root lambda = log(z) / h has a null vector, the mode's last row."""
        n, N = self.n, self.N
        powers = complex(z) ** -np.arange(N, -1, -1.0)   # z^-N .. z^0, oldest row first
        R = np.empty((n, n), dtype=complex)
        t = self.tangent
        for j in range(n):
            col = np.zeros(n, dtype=complex)
            for part, unit in ((np.real, 1.0), (np.imag, 1j)):
                w = np.zeros((N + 1, n))
                w[:, j] = part(powers)
                t.set_window(w)
                t.advance(1)
                col += unit * t.get_window()[-1]
            col[j] -= z
            R[:, j] = col
        return R

    def apply_complex(self, V: np.ndarray, steps: int) -> np.ndarray:
        """M^steps on the columns of a complex array V (n N, k)."""
        out = np.empty(V.shape, dtype=complex)
        for j in range(V.shape[1]):
            out[:, j] = self.apply(V[:, j].real, steps) + 1j * self.apply(V[:, j].imag, steps)
        return out

    def close(self) -> None:
        self.tangent.close()

    def __enter__(self) -> Linearisation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


#: A stacked evaluation of f (:class:`ManyRhs`) agrees with the per-point calls to this, relative
#: to max(1, |f|) (the same operations on arrays: rounding only).
STACKED_TOL = 1e-12


def python_rhs(s: Solver) -> Callable[..., Any] | None:
    """The model's rhs as the Python function the user gave (set_rhs of a function, or of one
    with jit=True: its source function), None for a C function or none."""
    bound = s._keep.get("rhs")          # the solver's record of the callback it hands libdmi
    if bound is None or bound.address is None:
        return None
    if getattr(bound, "jit", False):
        return getattr(bound, "f", None)
    return bound.keep[1] if bound.python else None


class ManyRhs:
    """f(t_c, U_c) (P, n) at many points (t (P,), U (P, n)): one call of the model's Python
    function on the stacked states, f(t, U.T) with t (P,) and u (n, P) -> (n, P), where the
    function takes them (NumPy operations on u[i] and t broadcast), else the solver's per-point
    loop (:meth:`dmi.Solver.eval_rhs_many`, the function the scheme calls).

    The stacked call is checked against the per-point calls: at every point of its first use,
    at six points of each later one (first, middle, last and three that move from call to call;
    agreement to STACKED_TOL relative, or the same inf or NaN); a stacked call that raises,
    returns another shape or disagrees is not tried again (``why`` says which; the per-point
    loop raises a model's own error with its point).  A model's function must treat each point
    on its own (no reduction over the points, e.g. np.max(u[0]) or a norm of u)."""

    def __init__(self, s: Solver):
        self.solver = s
        self.f = python_rhs(s) if s.has("rhs") else None
        self.checked = False
        self.calls = 0
        self.why = ""           # why the stacked call was given up, for a debugging user

    def __call__(self, t: np.ndarray, U: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float).ravel()
        U = np.asarray(U, dtype=float)
        if self.f is not None and U.ndim == 2 and U.shape[0] == t.size and t.size > 1:
            out = self._stacked(t, U)
            if out is not None:
                return out
        return self.solver.eval_rhs_many(t, U)

    def _stacked(self, t: np.ndarray, U: np.ndarray) -> np.ndarray | None:
        """The stacked call, checked; None (and no stacked call again) where it fails."""
        P = t.size
        try:
            with np.errstate(all="ignore"):
                got = self.f(t.copy(), np.array(U.T, order="C"))  # type: ignore[misc]
                out = np.asarray(got, dtype=float)
        except Exception as e:
            self.why = f"the stacked call raised {type(e).__name__}: {e}"
            out = None
        if out is None or out.shape != (U.shape[1], P):
            if out is not None:
                self.why = f"the stacked call returned shape {out.shape}, not {(U.shape[1], P)}"
            self.f = None
            return None
        out = np.ascontiguousarray(out.T)
        # every point at the first use; later three fixed points and three that move each call
        self.calls += 1
        at = (np.arange(P) if not self.checked else
              np.unique([0, P // 2, P - 1] + [(self.calls * k * 7919) % P for k in (1, 2, 3)]))
        ref = self.solver.eval_rhs_many(t[at], U[at])
        with np.errstate(invalid="ignore"):
            ok = (out[at] == ref) | (np.abs(out[at] - ref) <= STACKED_TOL
                                     * np.maximum(1.0, np.abs(ref)))
        ok |= np.isnan(out[at]) & np.isnan(ref)
        if not np.all(ok):
            self.why = "the stacked call disagrees with the per-point calls"
            self.f = None
            return None
        self.checked = True
        return out
