# Closed forms of exponential-sum kernels: phi1, the truncated Laplace transform, exact cell weights.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Closed forms for the exponential-sum kernels of ``dmi_set_kernel_exp``.

The kernel is, with K terms, exponents ``a`` (decay, <= 0 for the recursion), angular frequencies ``b``
and n x n coefficient matrices ``C``, ``D`` (``D`` None: zero)::

    H(s) = sum_k exp(a_k s) (C_k cos(b_k s) + D_k sin(b_k s))
         = sum_k Re[(C_k - i D_k) exp(mu_k s)],   mu_k = a_k + i b_k.

Everything here follows from the one function :func:`phi1`, ``phi1(z) = (e^z - 1) / z``, the mean of
``e^{z x}`` over ``x`` in [0, 1]:

- :func:`laplace` (``Hhat``): ``int_0^tau H(s) e^{-lambda s} ds``; each term gives
  ``tau phi1((mu - lambda) tau)``, for complex ``lambda`` too, and ``tau = inf`` is the full Laplace transform;
- :func:`cell_weights`: the exact integral of ``H`` over each cell ``[l h, (l + 1) h)``,
  ``h e^{mu l h} phi1(mu h)`` per term, and ``theta h e^{mu (N - 1) h} phi1(mu theta h)`` for a partial
  last cell of length ``theta h``.

Shapes: a scalar kernel has ``C`` of shape (K,) and gives scalars per point; a matrix kernel has ``C`` of
shape (K, n, n) and gives an n x n matrix per point (trailing axes).
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.special import roots_jacobi

__all__ = ["phi1", "laplace", "Hhat", "cell_weights", "evaluate", "power_laplace", "near_shift",
           "gauss_jacobi"]

# Below this |z| the series 1 + z/2 + z^2/6 is exact to rounding (the next term z^3/24 < 4e-17).
_SERIES = 1e-5


def phi1(z: Any) -> np.ndarray:
    """``phi1(z) = (e^z - 1) / z``, 1 at ``z = 0``, elementwise, for real or complex ``z``.

    Accurate to a few units of rounding everywhere (no cancellation near 0): the numerator is
    ``expm1(x) cos y - 2 sin^2(y / 2) + i e^x sin y`` for ``z = x + i y``, and below ``|z| = 1e-5`` the
    Taylor series is used.  Real input gives real output (float64), complex gives complex128.
    ``phi1(z) -> -1/z`` as ``Re z -> -inf``; it overflows only where ``e^z`` does.
    """
    z = np.asarray(z)
    if not np.iscomplexobj(z):
        x = z.astype(np.float64)
        small = np.abs(x) < _SERIES
        safe = np.where(small, 1.0, x)
        with np.errstate(over="ignore"):
            out = np.expm1(safe) / safe
        return np.where(small, 1.0 + x / 2 + x * x / 6, out)
    z = z.astype(np.complex128)
    small = np.abs(z) < _SERIES
    safe = np.where(small, 1.0, z)
    x, y = safe.real, safe.imag
    with np.errstate(over="ignore", invalid="ignore"):
        num = (np.expm1(x) * np.cos(y) - 2.0 * np.sin(y / 2) ** 2) + 1j * (np.exp(x) * np.sin(y))
        out = num / safe
    return np.where(small, 1.0 + z / 2 + z * z / 6, out)


def _terms(a: Any, b: Any, C: Any, D: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """mu (K,) and the complex coefficients G = C - i D, (K,) or (K, n, n), checked."""
    a = np.atleast_1d(np.asarray(a, dtype=np.float64))
    b = np.atleast_1d(np.asarray(b, dtype=np.float64))
    C = np.asarray(C, dtype=np.float64)
    if a.ndim != 1 or b.shape != a.shape or C.shape[:1] != a.shape or C.ndim not in (1, 3):
        raise ValueError(f"a {a.shape}, b {b.shape}, C {C.shape}: expected (K,), (K,), (K,) or (K, n, n)")
    if C.ndim == 3 and C.shape[1] != C.shape[2]:
        raise ValueError(f"C has shape {C.shape}: the matrices must be square")
    G = C.astype(np.complex128)
    if D is not None:
        D = np.asarray(D, dtype=np.float64)
        if D.shape != C.shape:
            raise ValueError(f"D has shape {D.shape}, C {C.shape}: expected the same")
        G = G - 1j * D
    return a + 1j * b, G, C


def _combine(weights: np.ndarray, G: np.ndarray) -> np.ndarray:
    """sum_k Re[weights[..., k] G_k]: shape weights.shape[:-1] (+ (n, n))."""
    out = np.tensordot(weights, G, axes=([-1], [0]))
    return out.real


def evaluate(s: Any, a: Any, b: Any, C: Any, D: Any = None) -> np.ndarray:
    """``H(s)`` at the points ``s`` (any shape): shape ``s.shape`` (+ (n, n))."""
    mu, G, _ = _terms(a, b, C, D)
    s = np.asarray(s, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        e = np.exp(np.multiply.outer(s, mu))
    return _combine(e, G)


def laplace(lam: Any, a: Any, b: Any, C: Any, D: Any = None, tau: float = np.inf) -> np.ndarray:
    """``Hhat(lambda) = int_0^tau H(s) e^{-lambda s} ds`` in closed form, at the (complex) points ``lam``.

    Each term ``Re[G e^{mu s}]`` (``G = C - i D``) is ``(G e^{mu s} + conj(G) e^{conj(mu) s}) / 2``, and
    ``int_0^tau e^{(mu - lambda) s} ds = tau phi1((mu - lambda) tau)``.  With ``tau = inf`` (the default)
    this is the Laplace transform ``1 / (lambda - mu)`` per exponential, valid for ``Re lambda > max a``
    (elsewhere the integral diverges and the result is inf or nan).  Returns complex values of shape
    ``lam.shape`` (+ (n, n) for a matrix kernel).
    """
    mu, G, _ = _terms(a, b, C, D)
    lam = np.asarray(lam, dtype=np.complex128)
    tau = float(tau)
    if not tau > 0:
        raise ValueError(f"tau = {tau}: expected > 0 (or inf)")
    out = 0
    for m, g in ((mu, G), (mu.conj(), G.conj())):
        z = np.subtract.outer(-lam, -m)  # mu - lambda, shape lam.shape + (K,)
        if np.isinf(tau):
            with np.errstate(divide="ignore", invalid="ignore"):
                w = np.where(z.real < 0, -1.0 / z, np.inf)
        else:
            w = tau * phi1(z * tau)
        out = out + 0.5 * np.tensordot(w, g, axes=([-1], [0]))
    return out


#: The name the characteristic-root code uses for :func:`laplace`.
Hhat = laplace


def cell_weights(a: Any, b: Any, C: Any, D: Any = None, *, h: float, N: int,
                 theta: float = 1.0) -> np.ndarray:
    """The exact integrals ``int H`` over the N cells ``[l h, (l + 1) h)``, ``l < N - 1``, and the last cell
    ``[(N - 1) h, (N - 1 + theta) h]`` (``0 < theta <= 1``): shape (N,) (+ (n, n)).

    Per term ``mu = a + i b`` the cell integral of ``e^{mu s}`` is ``h e^{mu l h} phi1(mu h)`` (the
    constant kernel, ``mu = 0``, gives ``h``), the partial last cell ``theta h e^{mu (N-1) h}
    phi1(mu theta h)``; the complex factor mixes ``C`` and ``D``: the weight is ``Re[(C - i D) ...]``.
    """
    mu, G, _ = _terms(a, b, C, D)
    if not (h > 0 and np.isfinite(h)):
        raise ValueError(f"h = {h}: expected a finite h > 0")
    if int(N) != N or N < 1:
        raise ValueError(f"N = {N}: expected an integer >= 1")
    if not 0 < theta <= 1:
        raise ValueError(f"theta = {theta}: expected 0 < theta <= 1")
    N = int(N)
    l = np.arange(N, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        w = np.exp(np.multiply.outer(l * h, mu)) * (h * phi1(mu * h))
        w[-1] = np.exp(mu * ((N - 1) * h)) * (theta * h * phi1(mu * (theta * h)))
    return _combine(w, G)



# ---- the near part of a fitted singular kernel ------------------------------------------------

#: Nodes of the Gauss-Jacobi rule on the first panel and of Gauss-Legendre on the others.
_NEAR_NODES = 40


@functools.lru_cache(maxsize=64)
def gauss_jacobi(q: int, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """The Gauss-Jacobi rule of the near part's weight y^-beta on [0, 1] (q nodes):
    ``int_0^1 y^-beta P(y) dy = sum w P(y)``, exact for P of degree <= 2 q - 1.  On [0, w] the
    nodes are w y and the weights w^(1 - beta) w.  Computed once for each (q, beta); the arrays
    are read-only (shared by every caller: the near part's transform here, the collocation's
    product integration in :mod:`dmi.analysis.collocation.mesh`)."""
    x, wx = roots_jacobi(q, 0.0, -beta)
    y, w = 0.5 * (x + 1.0), wx / 2.0 ** (1.0 - beta)
    y.setflags(write=False)
    w.setflags(write=False)
    return y, w


def power_laplace(lam: Any, beta: float, c: float, delta: float) -> np.ndarray:
    """``int_0^delta c s^-beta e^{-lambda s} ds`` (0 < beta < 1) at the (complex) points ``lam``:
    ``c lambda^(beta - 1) gamma(1 - beta, lambda delta)``, the lower incomplete gamma function.

    Computed by quadrature exact for the weight s^-beta: panels of width at most
    w = min(delta, 4 / max|lambda|), the first ``[0, w]`` by Gauss-Jacobi with the weight
    ``s^-beta`` (40 nodes: e^{-lambda s} on it is a polynomial to rounding), the others by
    Gauss-Legendre (40 nodes, the integrand smooth there).  Relative error below 1e-11 (checked
    against mpmath's incomplete gamma in tests/python/analysis/equilibria/test_verified_equation.py).

    Parameters
    ----------
    lam : array_like of complex
        The points lambda.
    beta : float
        The exponent, 0 < beta < 1.
    c : float
        The factor.
    delta : float
        The upper limit, > 0 (time units).

    Returns
    -------
    numpy.ndarray of complex
        Shape ``lam.shape``.

    Raises
    ------
    ValueError
        beta outside (0, 1) or delta <= 0.
    """
    if not 0 < beta < 1:
        raise ValueError(f"beta = {beta!r}: the near part needs 0 < beta < 1 (integrable)")
    if not (delta > 0 and math.isfinite(delta)):
        raise ValueError(f"delta = {delta!r}: expected a finite delta > 0")
    lam = np.asarray(lam, dtype=np.complex128)
    reach = float(np.max(np.abs(lam))) if lam.size else 0.0
    w = min(delta, 4.0 / reach) if reach > 0 else delta
    panels = max(1, math.ceil(delta / w - 1e-9))
    w = delta / panels
    # Gauss-Jacobi on [0, w] with the weight s^-beta
    y, wy = gauss_jacobi(_NEAR_NODES, float(beta))
    s = w * y
    ws = wy * w ** (1 - beta)
    out = np.tensordot(np.exp(-np.multiply.outer(lam, s)), ws, axes=(-1, 0))
    if panels > 1:
        g, wg = np.polynomial.legendre.leggauss(_NEAR_NODES)
        lo = w * np.arange(1, panels)
        s2 = (lo[:, None] + w * (1 + g[None, :]) / 2).ravel()
        w2 = np.tile(wg * w / 2, panels - 1) * s2 ** -beta
        out = out + np.tensordot(np.exp(-np.multiply.outer(lam, s2)), w2, axes=(-1, 0))
    return c * out


def near_shift(solver: Any) -> Callable[[Any], np.ndarray] | None:
    """What the near cells of a fitted singular kernel change in the equation's transform.

    A solver set by ``set_kernel_fit`` with ``delta > 0`` runs the exact kernel H on [0, delta]
    (its near cells) and the fit's exponential sum on [delta, tau]; the closed form
    :func:`laplace` of the sum over [0, tau] therefore needs ``int_0^delta (H(s) - sum(s))
    e^{-lambda s} ds`` added.  H is the fit's :class:`dmi.kernels.PowerKernel` (exact:
    :func:`power_laplace`); another near kernel (another fit's, or one given as ``near=``,
    which the near cells' samples at 3 points tell) is refused.

    Parameters
    ----------
    solver : dmi.Solver
        The model's solver (read through ``kernel_fit``, ``kernel_near_delta``, ``kernel_terms``
        and ``n``).

    Returns
    -------
    callable or None
        ``lam -> array`` of shape ``lam.shape + (n, n)`` (complex); None without near cells.

    Raises
    ------
    ValueError
        Near cells whose kernel is not the fit's PowerKernel (its transform on [0, delta] is
        not known here).
    """
    delta = float(solver.kernel_near_delta)
    fitted = solver.kernel_fit
    if not delta > 0 or fitted is None:
        return None
    fit, entry = fitted
    exact = getattr(fit, "kernel", None)
    if type(exact).__name__ != "PowerKernel" or entry is None:
        raise ValueError(f"the near cells (delta = {delta!r}) run a kernel whose transform on "
                         "[0, delta] dmi.analysis does not know (the equation's answers need "
                         "it): give set_kernel_fit a fit of a dmi.kernels.PowerKernel, or "
                         "use the scheme's answers (of=\"scheme\")")
    a, b, C, D = solver.kernel_terms
    n = int(solver.n)
    i, j = entry
    beta, c = float(exact.beta), float(exact.c)
    # the near cells run the fit's own kernel, not another one given as near=
    for q in (0.1, 0.5, 1.0):
        s = q * delta
        ran = float(solver.eval_kernel_near(s)[i, j])
        if not abs(ran - c * s ** -beta) <= 1e-12 * abs(c * s ** -beta):
            raise ValueError(f"the near cells (delta = {delta!r}) run a kernel other than the "
                             f"fit's PowerKernel (at s = {s!r}: {ran!r}, the fit's kernel "
                             f"{c * s ** -beta!r}): dmi.analysis does not know its transform on "
                             "[0, delta] (the equation's answers need it): set the fit without "
                             "near=, or use the scheme's answers (of=\"scheme\")")

    def shift(lam: Any) -> np.ndarray:
        lam = np.asarray(lam, dtype=np.complex128)
        out = np.zeros(lam.shape + (n, n), dtype=np.complex128)
        fit_part = laplace(lam, a, b, C[:, i, j], D[:, i, j], tau=delta)
        out[..., i, j] = power_laplace(lam, beta, c, delta) - fit_part
        return out
    return shift
