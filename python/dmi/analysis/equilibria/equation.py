# The characteristic matrix of the continuous equation at an equilibrium, and its roots refined
# from the scheme's.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The equation's answers, where the scheme's lie O(h) away.

At an equilibrium u_eq in a smooth region of the resolvent, the continuous equation
u' + A(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0 linearised has the characteristic matrix

    Delta(lambda) = lambda I + f_u(u_eq) + A'(u_eq) + Hhat(lambda),
    Hhat(lambda) = int_0^tau H(s) e^(-lambda s) ds,

its roots the lambda with det Delta(lambda) = 0.  A' is 0 for dry friction and the box away from
their thresholds; a component their resolvent holds (a stuck velocity, a face in contact) has no
dynamics and is removed; for a smooth user resolvent J (its derivative DJ at the scheme's X*)
A' = ((DJ)^-1 - I) / h, the generator whose resolvent (I + h A')^-1 is DJ.  Hhat is the closed
form of :func:`dmi._transform.laplace` for an exponential-sum kernel (``set_kernel_exp``; a fit
of a singular :class:`dmi.kernels.PowerKernel` with near cells has its exact transform on
[0, delta] instead of the sum's there, :func:`dmi._transform.near_shift`), and
Gauss-Legendre quadrature on panels sampled once for a callback kernel (panels of at most
1 / |lambda|_max, 16 nodes each, lambda_max the largest root asked for).

Each of the scheme's roots (:func:`dmi.analysis.roots`) is refined by Newton's method on
det Delta(lambda) = 0, the step 1 / tr(Delta^-1 Delta'(lambda)) (Delta' = I + Hhat', Hhat' by a
central difference of the analytic Hhat, :meth:`Characteristic.prime`), until |dlambda| <= 1e-10 max(1, |lambda|) twice
running; a root that does not converge in 40 iterations, or converges onto another's, is
reported (:class:`RefinementWarning`) and returned as nan.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from ..._transform import laplace, near_shift
from ..._solver import Solver
from ..core.model import (Linearisation, _resolvent_derivative, equation_terms, kernel_of,
                          kernel_panels, rhs_jacobian)

#: Relative tolerance of a refined root: |dlambda| <= ROOT_TOL max(1, |lambda|).
ROOT_TOL = 1e-10

#: Central stencils of a first derivative by their order: offsets (times the step), weights and
#: the step relative to max(1, |lambda|) (order 2 for Newton's step and the argument principle,
#: order 4 for the normal forms, whose Hhat' is then about 1e-13 off).
SLOPE = {2: (np.array([1.0, -1.0]), np.array([0.5, -0.5]), 1e-6),
         4: (np.array([-2.0, -1.0, 1.0, 2.0]), np.array([1.0, -8.0, 8.0, -1.0]) / 12, 1e-3)}


class RefinementWarning(RuntimeWarning):
    """A root of the scheme could not be refined to one of the equation (returned as nan)."""


class Characteristic:
    """Delta(lambda) of the equation at the linearisation ``lin``'s equilibrium, on its free
    components (those the resolvent does not hold); ``reach``: the largest |lambda| it will be
    asked about (sets a callback kernel's panels)."""

    def __init__(self, lin: Linearisation, reach: float = 10.0):
        h, D = lin.h, lin.D
        # the components the resolvent holds: a zero row and column of its derivative
        held = np.all(np.abs(D) <= 1e-12, axis=0) & np.all(np.abs(D) <= 1e-12, axis=1)
        free = np.nonzero(~held)[0]
        Df = D[np.ix_(free, free)]
        if lin.resolvent_kind in ("friction", "box"):
            Ap = np.zeros_like(Df)                   # A' = 0 away from the thresholds
        else:
            if abs(np.linalg.det(Df)) < 1e-12:
                raise ValueError("dmi.analysis: the resolvent's derivative at the equilibrium is "
                                 "singular on its free components: no generator A' there")
            Ap = (np.linalg.inv(Df) - np.eye(len(free))) / h
        self.free = free
        self.B = lin.J[np.ix_(free, free)] + Ap
        self.m = len(free)
        self.tau = lin.tau
        self._terms = lin.kernel_terms
        # a fitted singular kernel's near cells: the exact kernel on [0, delta], not the sum
        self._near = near_shift(lin.tangent) if self._terms is not None else None
        # (c, beta, delta) of those near cells' power kernel c s^-beta (for :meth:`bound`)
        self._power: tuple[float, float, float] | None = None
        if self._near is not None:
            fit, _ = lin.tangent.kernel_fit
            self._power = (float(fit.kernel.c), float(fit.kernel.beta),
                           float(lin.tangent.kernel_near_delta))
        self._panel: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        if self._terms is None and lin.kernel is not None:
            s, w, H = kernel_panels(lin.kernel, lin.tau, max(1.0, float(reach)))
            self._panel = (s, w, H[:, free][:, :, free])

    def hhat(self, lam: complex | np.ndarray) -> np.ndarray:
        """Hhat(lambda) on the free components, (m, m) complex, or (k, m, m) for k values."""
        lam = np.asarray(lam, dtype=complex)
        if self._terms is not None:
            a, b, C, D = self._terms
            H = laplace(lam, a, b, C, D, tau=self.tau)
            if self._near is not None:
                H = H + self._near(lam)
            return H[..., self.free[:, None], self.free[None, :]]
        if self._panel is not None:
            s, w, H = self._panel
            return np.tensordot(w * np.exp(-np.multiply.outer(lam, s)), H, axes=(-1, 0))
        return np.zeros(lam.shape + (self.m, self.m), dtype=complex)

    def bound(self, sigma: float, scale: np.ndarray | None = None) -> float:
        """A bound on |S^-1 Hhat(lambda) S|_2 over the half-plane Re lambda >= sigma (S =
        diag(scale) on the free components, default I): int_0^tau |S^-1 H(s) S|_F e^(-sigma s)
        ds, in closed form for an exponential sum (each term's |C_k|_F + |D_k|_F times
        int_0^tau e^((a_k - sigma) s) ds; a fitted singular kernel's near cells add int_0^delta
        |c| s^-beta e^(-sigma s) ds and the sum's own part there again), twice the panels'
        quadrature of it for a callback kernel."""
        d = np.ones(self.m) if scale is None else np.asarray(scale, dtype=float)
        ratio = d[None, :] / d[:, None]          # (S^-1 X S)_ij = X_ij d_j / d_i
        if self._terms is not None:
            a, _, C, D = self._terms
            f = self.free
            C = np.asarray(C, dtype=float)[:, f][:, :, f] * ratio
            D = (np.zeros_like(C) if D is None
                 else np.asarray(D, dtype=float)[:, f][:, :, f] * ratio)
            size = np.linalg.norm(C, axis=(1, 2)) + np.linalg.norm(D, axis=(1, 2))
            r = (np.asarray(a, dtype=float) - sigma) * self.tau
            with np.errstate(over="ignore"):
                grow = np.where(np.abs(r) < 1e-8, 1.0 + r / 2, np.expm1(r) / np.where(r == 0, 1, r))
            total = float(np.sum(size * self.tau * grow))
            if self._power is not None:
                c, beta, delta = self._power
                total = 2 * total + float(np.max(ratio)) * abs(c) \
                    * math.exp(max(0.0, -sigma) * delta) * delta ** (1 - beta) / (1 - beta)
            return total
        if self._panel is not None:
            s, w, H = self._panel
            return 2.0 * float(np.sum(w * np.exp(-sigma * s)
                                      * np.linalg.norm(H * ratio, axis=(1, 2))))
        return 0.0

    @classmethod
    def at(cls, s: Solver, u: np.ndarray, reach: float = 10.0) -> Characteristic:
        """Delta of the equation of the solver s at any state u, not only at an equilibrium (a
        corrector asks between them): f_u(u), the resolvent's derivative at the equation's X(u)
        and the kernel's transform, as a :class:`Linearisation` gives them at an equilibrium."""
        return cls(_Terms(s, u), reach)

    def __call__(self, lam: complex) -> np.ndarray:
        """Delta(lambda) (m x m, complex)."""
        return complex(lam) * np.eye(self.m) + self.B + self.hhat(lam)

    def prime(self, lam: complex | np.ndarray, order: int = 2) -> np.ndarray:
        """Delta'(lambda) = I + Hhat'(lambda), (m, m) complex, or (k, m, m) for k values; Hhat'
        by the central difference of :data:`SLOPE` of this order (2 or 4)."""
        lam = np.asarray(lam, dtype=complex)
        offsets, w, rel = SLOPE[order]
        flat = lam.reshape(-1)
        d = rel * np.maximum(1.0, np.abs(flat))
        H = self.hhat((flat[:, None] + offsets[None, :] * d[:, None]).reshape(-1))
        dH = np.einsum("s,ksij->kij", w, H.reshape(flat.size, offsets.size, self.m, self.m))
        dH = dH / d[:, None, None]
        return (np.eye(self.m) + dH).reshape(lam.shape + (self.m, self.m))

    def newton_step(self, lam: complex) -> complex:
        """det Delta / (det Delta)' = 1 / tr(Delta^-1 Delta'(lambda))."""
        tr = np.trace(np.linalg.solve(self(lam), self.prime(lam)))
        return 1.0 / tr


class _Terms:
    """What :class:`Characteristic` reads of a linearisation, at any state u of the solver s."""

    def __init__(self, s: Solver, u: np.ndarray):
        X, _ = equation_terms(s)(u)
        scale = max(float(np.max(np.abs(u))), float(np.max(np.abs(X)))) or 1.0
        self.h, self.tau = s.h, s.tau
        self.J = rhs_jacobian(s, 0.0, u)
        self.D = _resolvent_derivative(s, X, s.h, scale)
        self.resolvent_kind = s.resolvent_kind if s.resolvent_kind != "callback" else ""
        self.kernel_terms, self.kernel = kernel_of(s)
        self.tangent = s


def refine(ch: Characteristic, lam0: complex, max_iter: int = 40) -> tuple[complex, str]:
    """The root of det Delta near lam0 by Newton; (root, "") or (nan, why)."""
    lam = complex(lam0)
    small = 0
    for _ in range(max_iter):
        try:
            step = ch.newton_step(lam)
        except np.linalg.LinAlgError:
            return lam, ""   # Delta singular: lam is the root to rounding
        if not np.isfinite(step):
            return complex(np.nan, np.nan), f"Newton met a non-finite step at {lam:.6g}"
        lam = lam - step
        if abs(step) <= ROOT_TOL * max(1.0, abs(lam)):
            small += 1
            if small == 2:
                return lam, ""
        else:
            small = 0
    return complex(np.nan, np.nan), (f"Newton did not converge in {max_iter} iterations (last "
                                     f"{lam:.6g}): the scheme's root is too far from the "
                                     "equation's (a smaller h, or a multiple root)")


def equation_roots(lin: Linearisation, scheme: np.ndarray) -> np.ndarray:
    """The scheme's roots (rightmost first) refined to the equation's; -inf roots (components
    the resolvent holds) kept; each root that cannot be refined is nan, with a
    :class:`RefinementWarning` saying why."""
    finite = np.isfinite(scheme)
    reach = float(np.max(np.abs(scheme[finite]))) if finite.any() else 1.0
    ch = Characteristic(lin, 1.5 * reach + 1.0)
    out = np.array(scheme, dtype=complex)
    done: list[complex] = []
    for i, lam0 in enumerate(scheme):
        if not np.isfinite(lam0):
            continue
        lam, why = refine(ch, lam0)
        if not why:
            for other in done:
                if abs(lam - other) <= 1e-8 * max(1.0, abs(lam)):
                    why = (f"it converged onto the equation's root {other:.10g}, refined from "
                           "another scheme root: the scheme is too coarse to separate them")
                    break
        if why:
            warnings.warn(f"dmi.analysis: the scheme's root {lam0:.10g} could not be refined to "
                          f"the equation's: {why}", RefinementWarning, stacklevel=3)
            out[i] = complex(np.nan, np.nan)
            continue
        if lam0.imag == 0 and abs(lam.imag) <= 1e-12 * max(1.0, abs(lam)):
            lam = complex(lam.real, 0.0)
        done.append(lam)
        out[i] = lam
    return out


__all__ = ["Characteristic", "RefinementWarning", "equation_roots", "refine"]
