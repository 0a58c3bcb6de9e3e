# Exponential-sum fits of memory kernels, with their error and the bound they put on the solution.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Fitting a kernel by a sum of exponentials, the form ``Solver.set_kernel_exp`` runs in O(1) per step.

:func:`fit` returns a :class:`KernelFit`: the arrays ``a, b, C, D`` of

    H~(s) = sum_k exp(a_k s) (C_k cos(b_k s) + D_k sin(b_k s)),   a_k <= 0, b_k >= 0,

its measured error on a grid ten times finer than the fit's, and :meth:`KernelFit.solution_bound`, what
the error does to the solution.  Two methods (docs/kernels.md says why these):

- **ESPRIT** (a matrix pencil of the Hankel matrix of uniform samples on ``[delta, tau]``): for smooth and
  oscillating kernels and for tabulated (also noisy) data.  A kernel that is an exponential sum is found
  with its own number of terms; a matrix kernel's entries are stacked side by side, so they share the
  exponents.  The rank grows until the error meets ``tol``; for noisy data it stops at the singular
  values' noise floor.
- **Laplace quadrature and compression** for completely monotone kernels ``H(s) = int e^{-t s} dmu(t)``,
  ``mu >= 0`` (power laws ``s^{-beta}``, ``1/(1+s)``, relaxation moduli) over many scales: the
  Bernstein integral discretised (for :class:`PowerKernel` by the trapezoidal rule in ``x = log t``, an
  a priori accurate quadrature; for any other positive decreasing kernel by non-negative least squares
  over a geometric dictionary of rates), then compressed by a Galerkin projection of the symmetric
  state-space realisation onto its dominant singular directions on ``[delta, tau]`` and a
  non-negative refit.  Every weight is positive: no cancelling terms, ``sum C = H~(0)``.

Both run when both apply; the fit with fewer terms that meets ``tol`` is returned.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import sys
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from . import _transform

__all__ = ["KernelFit", "PowerKernel", "fit", "main"]


@dataclass(frozen=True)
class PowerKernel:
    """The power kernel ``c s^{-beta}``, ``0 < beta < 1``, singular at 0 and integrable (with
    ``c = 1 / Gamma(beta)`` it is the kernel of the Caputo derivative of order ``1 - beta``).

    A callable ``s -> c s^{-beta}`` that also carries its Laplace measure, ``s^{-beta} = 1/Gamma(beta)
    int exp(-s e^x + beta x) dx``, so :func:`fit` discretises that integral instead of fitting samples,
    and the error between grid points is bounded with the derivative (the fit is then ``certified``).

    Attributes
    ----------
    beta : float
        The exponent, 0 < beta < 1 (for beta >= 1 the kernel is not integrable at 0: no memory
        kernel).
    c : float
        The factor, finite and nonzero.

    Raises
    ------
    ValueError
        beta or c out of range (at construction).
    """
    beta: float
    c: float = 1.0

    def __post_init__(self) -> None:
        if not 0 < self.beta < 1:
            raise ValueError(f"PowerKernel: beta = {self.beta}; expected 0 < beta < 1 (s^-beta is "
                             "integrable at 0 only for beta < 1)")
        if not math.isfinite(self.c) or self.c == 0:
            raise ValueError(f"PowerKernel: c = {self.c}; expected a finite nonzero c")

    def __call__(self, s: Any) -> Any:
        return self.c * np.asarray(s, dtype=np.float64) ** -self.beta

    def derivative_bound(self, s: np.ndarray) -> np.ndarray:
        """The derivative's modulus, decreasing in s.

        Parameters
        ----------
        s : numpy.ndarray
            Points s > 0 (time units).

        Returns
        -------
        numpy.ndarray
            ``|H'(s)| = |c| beta s^{-beta-1}``, the shape of s.
        """
        return abs(self.c) * self.beta * s ** (-self.beta - 1)


@dataclass(frozen=True, eq=False)
class KernelFit:
    """An exponential-sum fit of a kernel on ``[delta, tau]``.

    ``a, b, C, D`` are what ``Solver.set_kernel_exp`` (``dmi_set_kernel_exp``) takes;
    :attr:`terms` = K counts (a, b) pairs (a cosine is one term).  The norms are Frobenius norms,
    the integrals by the trapezoidal rule on the check grid (for tabulated data: on the samples).
    Picklable.

    Attributes
    ----------
    a, b : numpy.ndarray, shape (K,)
        Rates (a_k <= 0) and angular frequencies (b_k >= 0), 1 / time unit.
    C, D : numpy.ndarray
        The cosines' and sines' coefficients: (K,) for a scalar kernel, (K, n, n) for a matrix one
        (units of H).
    tau : float
        The right end of the fit (time units).
    delta : float
        Its left end (time units); > 0 for a kernel singular at 0.
    max_error : float
        The largest error (relative if ``relative``) measured on the check grid.
    relative : bool
        Whether ``max_error`` is relative to max |H(s)| at each s.
    certified : bool
        ``max_error`` bounds the error everywhere on ``[delta, tau]``, between the check grid's
        points too (a derivative bound, docs/kernels.md; only for a :class:`PowerKernel`).  It
        covers the fit on ``[delta, tau]`` and nothing else: not the near cells below ``delta``,
        whose weights libdmi computes by its own quadrature of the exact kernel
        (``Solver.set_kernel_near``), nor the scheme's error.
    l1_error : float
        int_delta^tau ||H - H~|| ds.
    kernel_l1 : float
        int_0^tau ||H|| ds, >= 0 (the kernel must be integrable: :func:`fit` refuses one that
        is not).
    method : str
        The method of the fit returned: ``"esprit"`` or ``"laplace"`` (:func:`fit`: the rates
        chosen for the kernel), or ``"fixed"`` (:meth:`refit`: the rates of another fit).
    grid_points : int
        Points of the check grid.
    kernel : PowerKernel or None
        The fitted :class:`PowerKernel`, if it was one (``Solver.set_kernel_fit`` takes the near
        cells from it).
    """
    a: np.ndarray
    b: np.ndarray
    C: np.ndarray
    D: np.ndarray
    tau: float
    delta: float
    max_error: float
    relative: bool
    certified: bool
    l1_error: float
    kernel_l1: float
    method: str
    grid_points: int = field(default=0)
    kernel: PowerKernel | None = field(default=None)

    @property
    def terms(self) -> int:
        """K, the number of (a, b) pairs (a cosine is one term)."""
        return int(len(self.a))

    @property
    def n(self) -> int:
        """1 for a scalar kernel, else the matrices' size."""
        return 1 if self.C.ndim == 1 else int(self.C.shape[1])

    def __call__(self, s: Any) -> np.ndarray:
        """The fit's value.

        Parameters
        ----------
        s : array_like
            Points (time units).

        Returns
        -------
        numpy.ndarray
            ``H~(s)``: shape ``s.shape`` (+ (n, n)).
        """
        return _transform.evaluate(s, self.a, self.b, self.C, self.D)

    def refit(self, H: Callable[[float], Any], *, tol: float | None = None,
              certify: bool = False) -> KernelFit:
        """A fit of another kernel on the same ``[delta, tau]`` with this fit's rates and
        frequencies ``a, b``: only ``C, D`` change.

        They are the weighted least-squares fit of H's values at points fixed by this fit, with
        row weights fixed by this fit's values: a fixed linear map of H's values.  So the fit of
        a kernel with parameters (a :class:`PowerKernel`'s ``c`` and ``beta``) keeps its
        structure (term count, rates) and is smooth in them, which :func:`dmi.identify.sensitivities`
        needs to differentiate a model through it; :func:`fit` chooses its rates anew for each
        kernel, a choice that is not differentiable.  Fit once at a typical kernel, then refit
        inside ``make(p)``.

        Parameters
        ----------
        H : callable or PowerKernel
            The kernel, of this fit's shape (scalar, or n x n), finite on ``[delta, tau]``.
        tol : float, optional
            The error accepted (relative if this fit is), > 0; default: ten times this fit's
            ``max_error``.  A refit whose measured error exceeds it warns (the rates do not suit
            H: fit H anew, at a kernel nearer the ones refitted).
        certify : bool, optional
            For a PowerKernel: whether to bound the error between the check grid's points as
            :func:`fit` does (``certified``; about a second for a tight tol, so off by default:
            a refit inside ``make(p)`` runs several times per fit iteration).

        Returns
        -------
        KernelFit
            ``method = "fixed"``, its ``max_error`` measured on a grid ten times finer than the
            least-squares points (``certified`` only with ``certify``), ``kernel`` H when it is a
            PowerKernel.

        Raises
        ------
        ValueError
            tol not > 0; H of another shape, or not finite on ``[delta, tau]``; a PowerKernel
            refitted from a fit with ``delta = 0``.
        """
        if tol is None:
            tol = 10 * self.max_error
        if not tol > 0:
            raise ValueError(f"refit: tol = {tol}; expected > 0")
        lo, tau = self.delta, self.tau
        if lo == 0 and isinstance(H, PowerKernel):
            raise ValueError("refit: a PowerKernel is singular at 0: refit a fit with delta > 0")
        K = len(self.a)
        s, pinv = self._refit_map()
        V = _values(H, s)
        shape = self.C.shape[1:]
        if V.shape[1:] != shape or not np.all(np.isfinite(V)):
            raise ValueError(f"refit: H gives values of shape {V.shape[1:]} on [delta, tau] "
                             f"({'finite' if np.all(np.isfinite(V)) else 'not all finite'}); this "
                             f"fit's kernel has shape {shape} and must be finite there")
        C, D = _split(pinv @ V.reshape(len(s), -1), self.b)
        # the error on a grid ten times finer than the least-squares points
        check_s = np.unique(np.concatenate([_log_grid(lo, tau, 10 * len(s) // 2),
                                            np.linspace(lo, tau, 10 * len(s) // 2)]))
        check_v = _values(H, check_s)
        certified_fn = (_certifier(H, lo, tau, tol, self.relative)
                        if certify and isinstance(H, PowerKernel) else None)
        out = _build(self.a.copy(), self.b.copy(), C, D, shape, tau, lo, self.relative, "fixed",
                     check_s, check_v, certified_fn, check_s, check_v)
        if out.max_error > tol:
            warnings.warn(f"refit: the error of the refit is {out.max_error:.3g}, above tol = "
                          f"{tol:.3g}: this fit's {K} rates do not suit H; fit it anew (fit), at a "
                          "kernel nearer the ones refitted", stacklevel=2)
        done = _with_l1(out, H, None)
        object.__setattr__(done, "_source", (s, pinv))
        return done

    def refit_derivative(self, dH: Callable[[np.ndarray], Any]) -> tuple[np.ndarray, np.ndarray]:
        """The derivative of this refit's coefficients along a derivative of its kernel: a refit
        is linear in the kernel's values, so the derivative of ``C, D`` in a parameter of the
        kernel is the same linear map applied to the kernel's derivative in it (computed from a
        closed form of the derivative, not from differences of coefficients, in which the
        least-squares map's conditioning would amplify rounding).

        Parameters
        ----------
        dH : callable
            The kernel's derivative in the parameter, vectorised over s (an array of points),
            of the kernel's shape.

        Returns
        -------
        (numpy.ndarray, numpy.ndarray)
            dC and dD, the shapes of ``C`` and ``D``.

        Raises
        ------
        ValueError
            This fit is not one of :meth:`refit`, or dH gives values of another shape.
        """
        source = self.__dict__.get("_source")
        if source is None:
            raise ValueError(f"refit_derivative: this fit's method is {self.method!r}, not a "
                             "refit's ('fixed'): its rates were chosen for its kernel")
        s, pinv = source
        V = np.asarray(dH(s), dtype=np.float64)
        if V.shape != (len(s),) + self.C.shape[1:]:
            raise ValueError(f"refit_derivative: dH gives values of shape {V.shape[1:]}; the "
                             f"kernel's shape is {self.C.shape[1:]}")
        dC, dD = _split(pinv @ V.reshape(len(s), -1), self.b)
        return dC.reshape(self.C.shape), dD.reshape(self.C.shape)

    def _refit_map(self) -> tuple[np.ndarray, np.ndarray]:
        """The points s of :meth:`refit` and the linear map from H's values there to (C; D of the
        oscillating terms): the weighted least-squares pseudo-inverse, computed once per fit."""
        cached = self.__dict__.get("_refit_cache")
        if cached is not None:
            return cached
        lo, tau = self.delta, self.tau
        m = max(400, 16 * len(self.a))
        s = np.unique(np.concatenate([_log_grid(lo, tau, m), np.linspace(lo, tau, m)]))
        own = self(s).reshape(len(s), -1)
        size = np.abs(own).max(axis=1)
        rw = (1 / np.maximum(size, 1e-12 * size.max()) if self.relative
              else np.full(len(s), 1 / max(size.max(), np.finfo(float).tiny)))
        pinv = np.linalg.pinv(_real_basis(s, self.a, self.b) * rw[:, None]) * rw[None, :]
        object.__setattr__(self, "_refit_cache", (s, pinv))
        return s, pinv


    def coefficient_sum(self) -> float:
        """The coefficients' size: compare with max |H| to see there is no cancellation.

        Returns
        -------
        float
            ``sum_k (|C_k| + |D_k|)``, its largest entry.
        """
        return float(np.max(np.sum(np.abs(self.C) + np.abs(self.D), axis=0)))

    def solution_bound(self, T: float, lipschitz: float, u_max: float, *, h: float | None = None) -> float:
        """A bound on ``max_{t <= T} |u(t) - u~(t)|``, u the solution with the kernel H, u~ with this fit.

        With ``eps = l1_error`` and ``gamma = lipschitz + kernel_l1`` (docs/kernels.md):

        - ``h`` None, the equation: ``eps u_max (e^{gamma T} - 1) / gamma``; ``lipschitz`` is the one-sided
          Lipschitz constant L of ``-f`` (``-(f(u) - f(v)).(u - v) <= L |u - v|^2``), ``u_max`` a bound
          of ``|u~|`` on ``[-tau, T]``; the maximal monotone A drops out.
        - ``h`` given, the scheme with exact cell weights (f explicit: ``lipschitz`` is f's Lipschitz
          constant): ``eps u_max ((1 + h gamma)^n - 1) / gamma``, ``n = ceil(T / h)``.

        A kernel singular at 0 counts from ``delta`` on (the cells below it are exact).

        Parameters
        ----------
        T : float
            The end of the interval, >= 0 (time units).
        lipschitz : float
            L as above, >= 0 (1 / time unit).
        u_max : float
            A bound of ``|u~|``, >= 0 (state units).
        h : float, optional
            The scheme's step, > 0 (time units); None: the equation.

        Returns
        -------
        float
            The bound (state units).

        Raises
        ------
        ValueError
            T, lipschitz or u_max negative (or NaN), or h not > 0.
        """
        if not (T >= 0 and lipschitz >= 0 and u_max >= 0):
            raise ValueError(f"T = {T}, lipschitz = {lipschitz}, u_max = {u_max}: expected >= 0")
        gamma = lipschitz + self.kernel_l1
        if h is None:
            growth = T if gamma == 0 else math.expm1(gamma * T) / gamma
        else:
            if not h > 0:
                raise ValueError(f"h = {h}: expected > 0")
            steps = math.ceil(T / h - 1e-12)
            growth = steps * h if gamma == 0 else math.expm1(steps * math.log1p(h * gamma)) / gamma
        return self.l1_error * u_max * growth

    # ---- printing for C and Fortran users ------------------------------------------------------
    def to_json(self) -> str:
        """The fit as JSON.

        Returns
        -------
        str
            An object with ``terms``, ``n``, ``tau``, ``delta``, ``max_error``, ``relative``,
            ``certified``, ``method`` and the arrays ``a``, ``b``, ``C``, ``D`` as nested lists.
        """
        return json.dumps({"terms": self.terms, "n": self.n, "tau": self.tau, "delta": self.delta,
                           "max_error": self.max_error, "relative": self.relative,
                           "certified": self.certified, "method": self.method,
                           "a": self.a.tolist(), "b": self.b.tolist(), "C": self.C.tolist(),
                           "D": self.D.tolist()}, indent=1)

    def to_c(self, name: str = "kernel") -> str:
        """The fit as C source for ``dmi_set_kernel_exp``.

        Parameters
        ----------
        name : str, optional
            The prefix of the names: a C identifier (letters, digits and _, not a digit first).

        Returns
        -------
        str
            A comment with the call, the constant ``<name>_K`` and the ``static const double``
            arrays ``<name>_a``, ``<name>_b``, ``<name>_C``, ``<name>_D``.

        Raises
        ------
        ValueError
            name is not a C identifier.
        """
        _check_name(name, "c")
        def arr(tag: str, x: np.ndarray) -> str:
            vals = ", ".join(repr(float(v)) for v in x.ravel())
            return f"static const double {name}_{tag}[{x.size}] = {{{vals}}};"
        head = (f"/* {self.terms} terms, n = {self.n}, max error {self.max_error:.3g} "
                f"({'relative' if self.relative else 'absolute'}) on [{self.delta!r}, {self.tau!r}]:\n"
                f"   dmi_set_kernel_exp(s, {name}_K, {name}_a, {name}_b, {name}_C, {name}_D); */")
        return "\n".join([head, f"enum {{ {name}_K = {self.terms} }};", arr("a", self.a), arr("b", self.b),
                          arr("C", self.C), arr("D", self.D)]) + "\n"

    def to_fortran(self, name: str = "kernel") -> str:
        """The fit as Fortran declarations for ``dmi_set_kernel_exp`` of the Fortran binding.

        Parameters
        ----------
        name : str, optional
            The prefix of the names: a Fortran name (a letter, then letters, digits and _; at
            most 61 characters).

        Returns
        -------
        str
            The parameter ``<name>_K`` and ``real(c_double)`` arrays with ``data`` statements;
            C and D flat in the C layout (row-major per term), as ``dmi_set_kernel_exp`` reads
            them.

        Raises
        ------
        ValueError
            name is not a Fortran name.
        """
        _check_name(name, "fortran")
        def arr(tag: str, x: np.ndarray) -> list[str]:
            # C, D: the C layout (row-major per term) as one flat array, as dmi_set_kernel_exp reads it
            vals = [repr(float(v)).replace("e", "d") if "e" in repr(float(v)) else repr(float(v)) + "d0"
                    for v in x.ravel()]
            lines = [f"real(c_double) :: {name}_{tag}({x.size})", f"data {name}_{tag} / &"]
            for i in range(0, len(vals), 3):
                sep = ", &" if i + 3 < len(vals) else " /"
                lines.append("  " + ", ".join(vals[i:i + 3]) + sep)
            return lines
        out = [f"! {self.terms} terms, n = {self.n}, max error {self.max_error:.3g}: "
               f"dmi_set_kernel_exp(s, {name}_K, {name}_a, {name}_b, {name}_C, {name}_D)",
               f"integer(c_size_t), parameter :: {name}_K = {self.terms}"]
        for tag, x in (("a", self.a), ("b", self.b), ("C", self.C), ("D", self.D)):
            out += arr(tag, x)
        return "\n".join(out) + "\n"


# ---- helpers ---------------------------------------------------------------------------------------

# The names to_c and to_fortran print: <name>_K, <name>_a, ... (Fortran: 63 characters at most).
_NAMES = {"c": (r"[A-Za-z_][A-Za-z0-9_]*", "a C identifier: letters, digits and _, not a digit first"),
          "fortran": (r"[A-Za-z][A-Za-z0-9_]{0,60}", "a Fortran name: a letter, then letters, digits "
                      "and _, at most 61 characters")}


def _check_name(name: Any, language: str) -> None:
    """ValueError unless name makes valid names <name>_K, <name>_a, ... in the language."""
    pattern, rule = _NAMES[language]
    if not (isinstance(name, str) and re.fullmatch(pattern, name)):
        raise ValueError(f"name {name!r} is not {rule}")


_COMPLEX = ("fit: H returns complex values; libdmi's kernels are real (a complex exponential "
            "exp((a + ib) s) is the real pair exp(a s) cos(b s), exp(a s) sin(b s): fit the real "
            "kernel)")


def _real(v: Any) -> np.ndarray:
    """v as a float64 array; ValueError for complex values (their imaginary part would be lost)."""
    v = np.asarray(v)
    if np.iscomplexobj(v):
        raise ValueError(_COMPLEX)
    return np.asarray(v, dtype=np.float64)


def _values(H: Callable[[float], Any], s: np.ndarray) -> np.ndarray:
    """H at the points s: (M,) or (M, n, n), vectorised when H takes arrays, else point by point."""
    complex_values = False
    try:
        v = np.asarray(H(s))
        complex_values = np.iscomplexobj(v)
        if v.shape[:1] == s.shape and not complex_values:
            return np.asarray(v, dtype=np.float64)
    except Exception:  # noqa: BLE001 - a scalar-only callable: evaluate point by point below
        pass
    if complex_values:
        raise ValueError(_COMPLEX)
    return np.array([_real(H(float(x))) for x in s])


def _err(ref: np.ndarray, got: np.ndarray, relative: bool) -> np.ndarray:
    """Pointwise error (largest over matrix entries), relative to max |H| at the point if asked."""
    d = np.abs(ref - got).reshape(len(ref), -1).max(axis=1)
    if relative:
        d = d / np.maximum(np.abs(ref).reshape(len(ref), -1).max(axis=1), np.finfo(float).tiny)
    return d


def _frob(x: np.ndarray) -> np.ndarray:
    return np.sqrt((x.reshape(len(x), -1) ** 2).sum(axis=1))


def _trapezoid(y: np.ndarray, s: np.ndarray) -> float:
    return float(np.sum((y[1:] + y[:-1]) * np.diff(s)) / 2)


def _real_basis(s: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Columns exp(a_k s) cos(b_k s) and, for b_k > 0, exp(a_k s) sin(b_k s)."""
    e = np.exp(np.multiply.outer(s, a))
    cols = [e * np.cos(np.multiply.outer(s, b))]
    osc = b > 0
    if osc.any():
        cols.append(e[:, osc] * np.sin(np.multiply.outer(s, b[osc])))
    return np.hstack(cols)


def _coefficients(s: np.ndarray, V: np.ndarray, a: np.ndarray, b: np.ndarray,
                  w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares C, D (K, E) for values V (M, E) at s, rows weighted by w."""
    B = _real_basis(s, a, b)
    return _split(np.linalg.lstsq(B * w[:, None], V * w[:, None], rcond=None)[0], b)


def _split(X: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(C, D) from the coefficients X of :func:`_real_basis` (K rows of C, then a row of D for
    each term with b > 0); D is 0 on the terms with b = 0."""
    K = len(b)
    C = X[:K]
    D = np.zeros_like(C)
    D[b > 0] = X[K:]
    return C, D


# ---- ESPRIT ------------------------------------------------------------------------------------------

def _esprit_candidates(s: np.ndarray, V: np.ndarray, max_rank: int, noisy: bool, seen: dict):
    """Yields (a, b) for ranks 1, 2, ... of the block-Hankel matrix of the uniform samples V (M, E);
    seen["rate"] becomes the rank-1 rate before it is bounded to <= 0 (> 0: the kernel grows)."""
    M, E = V.shape
    ds = s[1] - s[0]
    L = M // 2
    cols = M - L + 1
    Hk = np.hstack([np.lib.stride_tricks.sliding_window_view(V[:, e], L).T[:, :cols] for e in range(E)])
    U, sig, _ = np.linalg.svd(Hk, full_matrices=False)
    top = min(max_rank, len(sig) - 1)
    if noisy:  # the singular values of the noise: about the median of the lower half
        floor = np.median(sig[len(sig) // 2:])
        top = min(top, max(1, int(np.sum(sig > 8 * floor))))
    for r in range(1, top + 1):
        Ur = U[:, :r]
        Phi = np.linalg.lstsq(Ur[:-1], Ur[1:], rcond=None)[0]
        z = np.linalg.eigvals(Phi)
        z = z[np.abs(z) > 1e-300]
        mu = np.log(z.astype(np.complex128)) / ds
        if r == 1 and len(mu):
            seen["rate"] = float(mu.real.max())
        a = np.minimum(mu.real, 0.0)  # a decaying or constant term: the recursion refuses growth
        b = np.abs(mu.imag)
        # conjugate pairs (real data) give one (a, b) term: merge equal (a, |b|)
        order = np.lexsort((a, b))
        a, b = a[order], b[order]
        keep = np.ones(len(a), bool)
        for i in range(1, len(a)):
            if keep[i - 1] and b[i] > 0 and abs(b[i] - b[i - 1]) <= 1e-8 * (1 + b[i]) \
                    and abs(a[i] - a[i - 1]) <= 1e-8 * (1 + abs(a[i])):
                keep[i] = False
        b = np.where(b * ds < 1e-12, 0.0, b)
        yield r, a[keep], b[keep]


# ---- completely monotone kernels: Laplace quadrature and compression ---------------------------------

def _power_nodes(k: PowerKernel, delta: float, tau: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Rates t_j and weights w_j of the trapezoidal rule in x = log t for c s^-beta on [delta, tau]."""
    from scipy.special import gamma, gammainccinv
    beta = k.beta
    eps = tol / 10
    x_lo = (math.log(eps * beta * gamma(beta)) + beta * math.log(tau)) / beta  # left tail <= eps H(tau)
    x_hi = math.log(gammainccinv(beta, eps) / delta)                           # right tail <= eps H(delta)
    step = 2 * math.pi * 1.0 / math.log(3 / eps)  # strip half-width 1 < pi/2
    x = np.arange(x_lo, x_hi + step, step)
    return np.exp(x), k.c * step * np.exp(beta * x) / gamma(beta)


def _log_grid(lo: float, hi: float, m: int) -> np.ndarray:
    if lo > 0:
        return np.geomspace(lo, hi, m)
    g = np.geomspace(hi * 1e-6, hi, m - m // 4)  # H smooth at 0: a uniform part too
    return np.unique(np.concatenate([np.linspace(0.0, hi, m // 4), g]))


def _nnls(A: np.ndarray, y: np.ndarray) -> np.ndarray:
    from scipy.optimize import nnls
    scale = np.maximum(np.linalg.norm(A, axis=0), 1e-300)
    x = nnls(A / scale, y, maxiter=50 * A.shape[1])[0]
    return x / scale


def _compressor(t: np.ndarray, w: np.ndarray, s: np.ndarray, y: np.ndarray, rw: np.ndarray):
    """A function k -> (rates, positive weights) of k terms from the positive sum sum_j w_j e^{-t_j s}:
    Galerkin projection of the symmetric realisation (x' = -T x + sqrt(w) u, y = sqrt(w).x) onto the k
    leading right singular vectors of its weighted impulse-response samples on s (the directions that
    matter on [delta, tau]; the projected T is symmetric positive semi-definite, so the rates are real and
    >= 0), then a non-negative least-squares refit of y."""
    Psi = np.exp(-np.multiply.outer(s, t)) * np.sqrt(w) * rw[:, None]
    Vt = np.linalg.svd(Psi, full_matrices=False)[2]

    def compress(k: int) -> tuple[np.ndarray, np.ndarray]:
        V = Vt[:k].T
        Tk = V.T @ (t[:, None] * V)
        rates = np.maximum(np.linalg.eigvalsh((Tk + Tk.T) / 2), 0.0)
        c = _nnls(np.exp(-np.multiply.outer(s, rates)) * rw[:, None], y * rw)
        used = c > 0
        return rates[used], c[used]
    return compress


def _cm_fit(H, lo: float, tau: float, tol: float, relative: bool, max_terms: int, m: int):
    """(a, C) of a positive-weight fit, or None when H does not look completely monotone."""
    s = _log_grid(lo, tau, m)
    y = _values(H, s)
    if y.ndim != 1 or not np.all(np.isfinite(y)) or np.any(y <= 0) or np.any(np.diff(y) > 1e-12 * y[:-1]):
        return None
    rw = 1 / y if relative else np.ones_like(y) / y.max()
    if isinstance(H, PowerKernel):
        t, w = _power_nodes(H, max(lo, 1e-300), tau, tol)
    else:  # a dictionary of rates, weights by non-negative least squares
        t_hi = 60 / (lo if lo > 0 else tau * 1e-6)
        t = np.concatenate([[0.0], np.geomspace(0.05 / tau, t_hi, 12 * int(math.log10(t_hi * tau / 0.05) + 1))])
        w = _nnls(np.exp(-np.multiply.outer(s, t)) * rw[:, None], y * rw)
        t, w = t[w > 0], w[w > 0]
    compress = _compressor(t, w, s, y, rw)
    scale = 1 if relative else y.max()

    def ok(k: int) -> tuple[bool, tuple[np.ndarray, np.ndarray]]:
        rates, c = compress(k)
        got = np.exp(-np.multiply.outer(s, rates)) @ c
        return bool(np.max(np.abs(got - y) * rw * scale) <= tol * 0.8), (rates, c)
    hi = min(max_terms, len(t))
    good, fit_hi = ok(hi)
    if not good:
        return -fit_hi[0], fit_hi[1]
    lo_k = 0  # bisection for the fewest terms (the error falls with k)
    while hi - lo_k > 1:
        mid = (lo_k + hi) // 2
        good, f = ok(mid)
        if good:
            hi, fit_hi = mid, f
        else:
            lo_k = mid
    return -fit_hi[0], fit_hi[1]


# ---- the fit ---------------------------------------------------------------------------------------

def _build(a, b, C, D, shape, tau, delta, relative, method, check_s, check_v, certified_fn, l1_s, l1_v):
    C = C.reshape((len(a),) + shape)
    D = D.reshape((len(a),) + shape)
    fitted = _transform.evaluate(check_s, a, b, C, D)
    err = _err(check_v, fitted, relative)
    max_error = float(err.max())
    certified = bool(certified_fn(a, b, C, D, err)) if certified_fn else False
    diff = _frob(l1_v - _transform.evaluate(l1_s, a, b, C, D))
    return KernelFit(a=a, b=b, C=C, D=D, tau=tau, delta=delta, max_error=max_error, relative=relative,
                     certified=certified, l1_error=_trapezoid(diff, l1_s), kernel_l1=0.0, method=method,
                     grid_points=len(check_s))


def fit(H: Callable[[float], Any] | None, tau: float, *, tol: float = 1e-8, relative: bool = False,
        max_terms: int = 64, delta: float | None = None,
        samples: tuple[Sequence[float], Any] | None = None) -> KernelFit:
    """Fits ``H`` on ``[delta, tau]`` (``delta`` None: ``[0, tau]``) by an exponential sum.

    Parameters
    ----------
    H : callable, PowerKernel or None
        A function of s giving a scalar or an n x n matrix (vectorised or not), a
        :class:`PowerKernel`, or None with ``samples``.
    tau : float
        The right end, finite and > 0 (time units).
    tol : float, optional
        The largest error wanted, > 0: absolute, or (``relative``) relative to max |H(s)| at each s.
    relative : bool, optional
        Whether ``tol`` is relative.
    max_terms : int, optional
        The most terms, >= 1.
    delta : float, optional
        The left end for a kernel singular at 0, 0 <= delta < tau (the cells below it are integrated
        exactly).
    samples : tuple, optional
        ``(s, values)`` with H None: M >= 8 finite increasing points s and values (M,) or (M, n, n);
        uniform s for a matrix kernel (a non-uniform grid only for positive decreasing values).

    Returns
    -------
    KernelFit
        The fit with the fewest terms that meets ``tol`` (at most ``max_terms``); when none does,
        the best found, with a ``UserWarning`` that says why when it can: a growing kernel (fits
        allow only decaying terms), or for uniform samples their noise, estimated from their 4th
        differences, and the tol it allows.

    Raises
    ------
    ValueError
        tau, tol, max_terms or delta out of range; both or neither of H and samples; samples of
        other shapes, not finite or not increasing, or on a non-uniform grid and not positive and
        decreasing; complex values of H or the samples; a callable H whose integral of ||H|| over
        [0, tau] does not converge (not integrable at 0, as 1/s).
    """
    if not (tau > 0 and math.isfinite(tau)):
        raise ValueError(f"fit: tau = {tau}; expected a finite tau > 0")
    if not tol > 0:
        raise ValueError(f"fit: tol = {tol}; expected > 0")
    if int(max_terms) != max_terms or max_terms < 1:
        raise ValueError(f"fit: max_terms = {max_terms}; expected an integer >= 1")
    lo = 0.0 if delta is None else float(delta)
    if not 0 <= lo < tau:
        raise ValueError(f"fit: delta = {delta}; expected 0 <= delta < tau")
    if (H is None) == (samples is None):
        raise ValueError("fit: give H, or H = None and samples = (s, values)")
    candidates: list[KernelFit] = []
    seen: dict[str, Any] = {}   # what the fits saw that the warning reports
    if samples is not None:
        s = _real(samples[0])
        V = _real(samples[1])
        if s.ndim != 1 or len(s) < 8 or V.shape[:1] != s.shape or V.ndim not in (1, 3):
            raise ValueError(f"fit: samples of shapes {s.shape}, {V.shape}; expected (M,), (M,) or (M, n, n)"
                             ", M >= 8")
        if not (np.all(np.isfinite(s)) and np.all(np.isfinite(V)) and np.all(np.diff(s) > 0)):
            raise ValueError("fit: the sample points must be finite and increasing, the values finite")
        inside = (s >= lo) & (s <= tau)
        s, V = s[inside], V[inside]
        ds = np.diff(s)
        if np.ptp(ds) > 1e-6 * ds.mean():
            fn = _interpolated(s, V)
            candidates += _fit_callable(fn, tau, lo, tol, relative, max_terms, noisy=True, esprit=False,
                                        seen=seen)
            if not candidates:
                raise ValueError("fit: samples on a non-uniform grid are fitted only when positive and "
                                 "decreasing (a completely monotone kernel); resample them uniformly")
        else:
            seen["samples"] = V
            candidates += _fit_esprit(s, V, tau, lo, tol, relative, max_terms, noisy=True, check=(s, V),
                                      seen=seen)
    else:
        candidates += _fit_callable(H, tau, lo, tol, relative, max_terms, noisy=False, esprit=True,
                                    seen=seen)
    good = [c for c in candidates if c.max_error <= tol]
    if good:
        best = min(good, key=lambda c: (c.terms, c.max_error))
    else:
        best = min(candidates, key=lambda c: c.max_error)
        warnings.warn(f"fit: no fit of at most {max_terms} terms meets tol = {tol:g}; the best has "
                      f"{best.terms} terms and error {best.max_error:.3g}"
                      + _why_missed(seen, tau - lo, samples is not None, relative),
                      stacklevel=2)
    return _with_l1(best, H, samples)


def _why_missed(seen: dict, length: float, sampled: bool, relative: bool) -> str:
    """What keeps the fits from tol: a growing kernel, or the noise of uniform samples
    (seen["samples"])."""
    rate = seen.get("rate", 0.0)
    if rate * length > 0.1 and seen.get("larger_at_tau"):   # the leading term grows by > 10 %
        return (f". The kernel grows (its leading rate is +{rate:.3g} per time unit): fits allow "
                "only decaying or constant terms (a_k <= 0), and more terms do not help; a growing "
                "memory kernel makes the scheme's sum grow with tau")
    V = seen.get("samples")
    if V is None:
        return (": the samples are on a non-uniform grid (their noise is not estimated); more "
                "or smoother samples, or a larger tol" if sampled else
                ": more terms (max_terms) or a larger tol")
    d4 = np.diff(V.reshape(len(V), -1), 4, axis=0)   # white noise: var(d4) = 70 sigma^2
    sigma = float(1.4826 * np.median(np.abs(d4)) / math.sqrt(70)) if len(d4) else 0.0
    scale = float(np.max(np.abs(V))) if relative else 1.0
    largest = sigma * math.sqrt(2 * math.log(max(len(V), 2)))  # the largest of M Gaussian deviations
    return (f". The samples' noise, estimated from their 4th differences, is about "
            f"{sigma / scale:.2g}{' relative to max |H|' if relative else ''}: no fit can follow "
            f"them closer than that; the error is measured at the {len(V)} samples, whose largest "
            f"noise is about {largest / scale:.2g}, so a tol of about {largest / scale:.2g} or more "
            "is what the noise allows (or give smoother samples)")


def _with_l1(f: KernelFit, H, samples) -> KernelFit:
    """The fit with kernel_l1 = int_0^tau ||H||."""
    if samples is not None:
        s = np.asarray(samples[0], float)
        v = _frob(np.asarray(samples[1], float))
        l1 = _trapezoid(v, s) + float(v[0] * s[0]) if s[0] > 0 else _trapezoid(v, s)
    elif isinstance(H, PowerKernel):   # (0 < beta < 1)
        l1 = abs(H.c) * f.tau ** (1 - H.beta) / (1 - H.beta)
    else:
        from scipy.integrate import IntegrationWarning, quad
        with warnings.catch_warnings():
            warnings.simplefilter("error", IntegrationWarning)
            try:
                l1, err = quad(lambda x: float(_frob(_values(H, np.array([x])))[0]), 0, f.tau, limit=200)
            except IntegrationWarning:
                l1, err = math.inf, math.inf
        if not (math.isfinite(l1) and err <= 1e-6 * l1):
            raise ValueError(f"fit: int_0^tau ||H(s)|| ds does not converge (scipy's quad: {l1:.6g}, "
                             f"error {err:.3g}): H looks not integrable on [0, {f.tau!r}] (1/s is "
                             "not, s^-beta is for beta < 1), and a memory kernel must be")
    exact = H if isinstance(H, PowerKernel) else None  # (picklable: kept for the near cells)
    return KernelFit(**{**f.__dict__, "kernel_l1": float(l1), "kernel": exact})


def _interpolated(s: np.ndarray, V: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    def fn(x):
        return np.interp(np.log(x), np.log(s), V) if s[0] > 0 else np.interp(x, s, V)
    return fn


def _fit_esprit(s, V, tau, lo, tol, relative, max_terms, noisy, check, seen):
    shape = V.shape[1:]
    Vf = V.reshape(len(s), -1)
    cs, cv = check
    rw = np.ones(len(s))
    if relative:
        rw = 1 / np.maximum(np.abs(Vf).max(axis=1), np.finfo(float).tiny)
    best = None
    errors = []
    tenth = max(1, len(s) // 10)   # |H| larger on the last tenth than on the first: it grows
    seen["larger_at_tau"] = bool(np.abs(Vf[-tenth:]).max() > np.abs(Vf[:tenth]).max())
    for r, a, b in _esprit_candidates(s, Vf, 2 * max_terms, noisy, seen):
        if len(a) > max_terms:
            continue
        C, D = _coefficients(s, Vf, a, b, rw)
        f = _build(a, b, C, D, shape, tau, lo, relative, "esprit", cs, cv, None, cs, cv)
        errors.append((f.max_error, f))
        if best is None or f.max_error < best.max_error:
            best = f
        if f.max_error <= tol:
            return [f]
    if best is None:
        return []
    if noisy:  # the smallest fit whose error is within 1.5 times the least: the count saturates
        least = min(e for e, _ in errors)
        return [next(f for e, f in errors if e <= 1.5 * least)]
    return [best]


def _fit_callable(H, tau, lo, tol, relative, max_terms, noisy, esprit, seen):
    out = []
    m = 1000
    check_u = np.linspace(lo, tau, 10 * m + 1)
    check_l = _log_grid(lo, tau, 10 * 2000) if lo > 0 else check_u
    check_s = np.unique(np.concatenate([check_u, check_l]))
    if lo == 0 and isinstance(H, PowerKernel):
        raise ValueError("fit: a PowerKernel is singular at 0: give delta > 0")
    check_v = _values(H, check_s)
    if not np.all(np.isfinite(check_v)):
        raise ValueError("fit: H is not finite on [delta, tau] (a kernel singular at 0 needs delta > 0)")
    certified_fn = _certifier(H, lo, tau, tol, relative) if isinstance(H, PowerKernel) else None
    fewest = max_terms
    if check_v.ndim == 1:
        cm = _cm_fit(H, lo, tau, tol, relative, max_terms, 2000)
        if cm is not None:
            a, C = cm
            zero = np.zeros_like(a)
            out.append(_build(a, zero, C, np.zeros_like(C), (), tau, lo, relative, "laplace", check_s,
                              check_v, certified_fn, check_s, check_v))
            if out[-1].max_error <= tol:
                fewest = out[-1].terms - 1  # ESPRIT is of use only with fewer terms
    if esprit and not isinstance(H, PowerKernel) and fewest >= 1:
        s = np.linspace(lo, tau, m)
        out += _fit_esprit(s, _values(H, s), tau, lo, tol, relative, fewest, noisy, (check_s, check_v),
                           seen)
    return out


def _certifier(H: PowerKernel, lo: float, hi: float, tol: float, relative: bool):
    """Whether the error stays within tol between points too, on a geometric grid of its own: on
    [s_i, s_i+1] the error is at most the larger end value plus (s_i+1 - s_i)^2 / 8 max|e''|, and
    |e''| <= |H''(s_i)| + sum_k |C_k| a_k^2 e^{a_k s_i} (H and the fit are completely monotone: both second
    derivatives decrease).  Rigorous up to rounding."""
    def certify(a, b, C, D, err):
        if np.any(b != 0) or np.any(C < 0):
            return False
        beta = H.beta
        r = math.sqrt(tol / 4 * 8 / (beta * (beta + 1) * 2))  # relative spacing: H'' term <= tol / 4
        m = int(math.log(hi / lo) / math.log1p(r)) + 2
        if m > 2_000_000:
            return False
        s = np.geomspace(lo, hi, m)
        ref = H(s)
        e = np.abs(_transform.evaluate(s, a, b, C) - ref)
        d2 = abs(H.c) * beta * (beta + 1) * s[:-1] ** (-beta - 2) \
            + np.exp(np.multiply.outer(s[:-1], a)) @ (C * a * a)
        between = np.maximum(e[:-1], e[1:]) + np.diff(s) ** 2 / 8 * d2
        scale = np.abs(ref[1:]) if relative else 1.0
        return bool(np.all(between / scale <= tol))
    return certify


# ---- console script --------------------------------------------------------------------------------

def main(argv: Sequence[str] | None = None) -> int:
    """``dmi-kernel-fit``: fits a kernel given as a Python expression in s (numpy as np) or the power
    kernel, and prints the coefficients as C arrays, Fortran data statements or JSON."""
    p = argparse.ArgumentParser(prog="dmi-kernel-fit", description=main.__doc__)
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--expr", help="H(s) as a numpy expression in s, e.g. '1/(1+s)'")
    g.add_argument("--power", type=float, metavar="BETA", help="the kernel s^-BETA (times --scale)")
    g.add_argument("--samples", metavar="FILE", help="two columns s, H(s) (whitespace separated)")
    p.add_argument("--scale", type=float, default=1.0, help="factor of the power kernel (default 1)")
    p.add_argument("--tau", type=float, required=True)
    p.add_argument("--delta", type=float, default=None)
    p.add_argument("--tol", type=float, default=1e-8)
    p.add_argument("--relative", action="store_true")
    p.add_argument("--max-terms", type=int, default=64)
    p.add_argument("--format", choices=["c", "fortran", "json"], default="c")
    p.add_argument("--name", default="kernel", help="prefix of the printed names (default kernel)")
    args = p.parse_args(argv)
    try:
        if args.format != "json":
            try:
                _check_name(args.name, args.format)
            except ValueError as e:
                raise ValueError(f"--name: {e} (--format {args.format})") from None
        samples = None
        if args.power is not None:
            try:
                H: Any = PowerKernel(args.power, args.scale)
            except ValueError as e:
                raise ValueError(f"--power/--scale: {e}") from None
        elif args.expr is not None:
            H = _expression(args.expr, args.tau)
        else:
            H, samples = None, _sample_file(args.samples)
        f = fit(H, args.tau, tol=args.tol, relative=args.relative, max_terms=args.max_terms,
                delta=args.delta, samples=samples)
    except (ValueError, OSError) as e:
        print(f"dmi-kernel-fit: {e}", file=sys.stderr)
        return 2
    out = {"c": f.to_c, "fortran": f.to_fortran}.get(args.format)
    sys.stdout.write(out(args.name) if out else f.to_json() + "\n")
    return 0


def _expression(text: str, tau: float) -> Callable[[Any], np.ndarray]:
    """H(s) of --expr: the expression evaluated with s and np; ValueError naming --expr when it
    does not compile, raises, or gives no real numbers (tried at s = tau first)."""
    try:
        code = compile(text, "<expr>", "eval")
    except SyntaxError as e:
        raise ValueError(f"--expr {text!r} is not a Python expression: {e.msg}") from None

    def H(s: Any) -> np.ndarray:
        try:
            return _real(eval(code, {"np": np, "__builtins__": {}}, {"s": s}))  # noqa: S307
        except Exception as e:  # noqa: BLE001 - any failure of the user's expression, named
            raise ValueError(f"--expr {text!r} fails at s = {s!r}: {type(e).__name__}: {e} "
                             "(an expression in s, a float or an array, and np)") from None
    if tau > 0 and math.isfinite(tau):   # (a bad tau: fit says so)
        H(float(tau))
    return H


def _sample_file(path: str) -> tuple[np.ndarray, np.ndarray]:
    """(s, H(s)) of --samples: a text file of two whitespace-separated columns."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)   # (loadtxt's "no data": said below)
            data = np.loadtxt(path, ndmin=2)
    except (ValueError, UnicodeDecodeError) as e:
        raise ValueError(f"--samples {path}: not a text file of two columns s, H(s): {e}") from None
    except OSError as e:
        raise ValueError(f"--samples {path}: {e.strerror or e}") from None
    if data.size == 0 or data.shape[1] != 2:
        got = "no data" if data.size == 0 else f"{data.shape[1]} column(s)"
        raise ValueError(f"--samples {path}: {got}; expected two whitespace-separated columns s, H(s)")
    return data[:, 0], data[:, 1]


if __name__ == "__main__":
    sys.exit(main())
