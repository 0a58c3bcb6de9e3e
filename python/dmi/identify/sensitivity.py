# dmi.identify.sensitivity: dU/dp of the scheme, with the saltation jump at velocity reversals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Sensitivities dU^p/dp of the implicit Euler scheme (3.12)-(3.13) for a model ``make(p)``.

Where nothing switches, S^p = dU^p/dp is the exact tangent of the scheme,

    T^p = S^p - h (f_u S^p + f_p) - h dW^p,      S^{p+1} = R'(X^p) T^p + dR/dp,

with X^p = U^p - h f(t_p, U^p) - h W^p the resolvent's argument.  Where a friction component
reverses inside a step (directly, or through one step in the dead zone), S of that component is
multiplied by the saltation factor F+ / F- of the equation (F = u' just before and after the
reversal), which the plain tangent misses by O(1) however small h is; sticks, slip onsets and box
contacts need no correction (the tangent gives S = 0 while stuck, and F is continuous at a slip
onset).  S then converges at O(h) to the equation's sensitivity.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import fft as sp_fft

from .. import _lib
from .._errors import Error
from .._solver import Solver
from ._near import near_kernel_part, near_sum
from .._resolvent import (box_side, friction_slope, friction_slope_alpha, reaches_zero,
                          salted)
from ._saltation import REVERSAL, STICK, UNPLACED, reversal

#: Relative step of the directional differences (about the square root of the unit roundoff).
REL_STEP = 2.0 ** -26

#: Default bound on the steps of one run that :func:`sensitivities` (and so each record of
#: :func:`estimate`) accepts; more is refused up front with the memory it would take, unless an
#: explicit ``max_steps`` allows it.
MAX_STEPS = 2_000_000


def memory_bytes(steps: int, n: int, N: int, P: int) -> int:
    """About the memory a run of ``steps`` steps with its sensitivities holds (bytes): S of the
    history and the steps and dX/dp (n P numbers a step each), the states U and X, and the
    kernel's part of the tangent (n P a step)."""
    return 8 * ((N + steps + 1) * n * P + 2 * steps * n * P + 2 * (steps + 1) * n)


def check_steps(steps: int, n: int, N: int, P: int, h: float, max_steps: int | None,
                where: str) -> None:
    """ValueError, before any run, where ``steps`` exceeds the bound (MAX_STEPS unless
    ``max_steps`` is given), saying how much memory the run would hold."""
    bound = MAX_STEPS if max_steps is None else max_steps
    if not isinstance(bound, (int, np.integer)) or isinstance(bound, bool) or bound < 1:
        raise ValueError(f"max_steps = {max_steps!r}: expected an integer >= 1")
    if steps > bound:
        gib = memory_bytes(steps, n, N, P) / 2.0 ** 30
        raise ValueError(f"{where} asks for {steps} steps of h = {h:.6g} (up to t = {steps * h:.6g}), "
                         f"more than max_steps = {bound}{' (the default)' if max_steps is None else ''}; "
                         f"its run with the sensitivities in {P} parameter(s) would hold about "
                         f"{gib:.3g} GiB, and a fit runs it once per iteration.  Shorten the record, take "
                         "a larger h, or pass a larger max_steps if the memory and the time are there")


@dataclasses.dataclass
class Sensitivities:
    """States and sensitivities of one run of the scheme.

    Attributes
    ----------
    t : numpy.ndarray
        Shape (steps + 1,): times t_p = p h (time units).
    u : numpy.ndarray
        Shape (steps + 1, n): states U^p (state units).
    S : numpy.ndarray
        Shape (steps + 1, n, P): dU^p/dp_j (state units per unit of p_j).
    x : numpy.ndarray
        Shape (steps, n): resolvent arguments X^p of the step into U^{p+1}; (X^p - U^{p+1}) / h is the element of
        A(U^{p+1}) selected (the friction force).
    dx : numpy.ndarray
        Shape (steps, n, P): dX^p/dp_j.
    h : float
        The step (time units).
    switches : list of tuple
        (p, i, kind): friction component i reverses in step p (``"reversal"``, S_i multiplied by
        the saltation factor there), starts to stick (``"stick"``), or meets zero or changes
        sign in a way the loop cannot place as a reversal inside the step (``"unplaced"``: no
        saltation factor applied, S_i there is the plain tangent, off by O(1)).
    engine : str
        The loop over the steps that computed S: ``"compiled"`` (libdmi's, ``dmi_tangent_run``:
        f called through its C function) or ``"python"``.
    """

    t: np.ndarray
    u: np.ndarray
    S: np.ndarray
    x: np.ndarray
    dx: np.ndarray
    h: float
    switches: list
    engine: str = "python"

    @property
    def unplaced(self) -> list:
        """The steps p (increasing, each once) with a reversal the loop could not place inside the
        step: S is not the equation's sensitivity from there on (a smaller h resolves them); empty
        where every switch was placed.

        Returns
        -------
        list of int
            The steps.
        """
        return sorted({q for q, _, kind in self.switches if kind == "unplaced"})


@dataclasses.dataclass
class _Perturbed:
    """The model at p and at p + delta_j e_j, and what differs between them.  A grouped build
    (``_grouped.build``: several parameters moved in one model) gives, per parameter, the model
    the tangent loop reads for its f and resolvent (``others``), the one whose history carries its
    perturbation (``sources``), the kernel terms of its own perturbed model (``terms``) and the
    parameters that enter the history (``hist``); None: all read from ``others``."""

    base: Solver
    others: list        # the solvers at p + delta_j e_j
    delta: np.ndarray   # delta_j as applied: fl(p_j + step) - p_j
    sources: list | None = None
    terms: list | None = None
    hist: list | None = None

    def source(self, j: int) -> Solver:
        """The solver whose history carries parameter j's perturbation."""
        return self.others[j] if self.sources is None else self.sources[j]

    def terms_of(self, j: int) -> tuple:
        """The exponential kernel's terms (a, b, C, D) of the model at p + delta_j e_j."""
        return self.others[j].kernel_terms if self.terms is None else self.terms[j]


def perturbed_step(p: np.ndarray, j: int) -> float:
    """p_j + delta_j, delta_j = REL_STEP max(1, |p_j|) before rounding (the step applied is the
    difference of the two)."""
    return p[j] + REL_STEP * max(1.0, abs(p[j]))


def _build(make: Callable[[np.ndarray], Solver], p: np.ndarray,
           base: Solver | None = None) -> _Perturbed:
    """The solvers at p (``base``, else made here) and p + delta_j e_j, after checking that the
    parameters change nothing the sensitivities cannot follow."""
    base = _call_make(make, p, "p") if base is None else base
    structure = _structure(base)
    others, delta = [], np.empty(len(p))
    for j in range(len(p)):
        q = p.copy()
        q[j] = perturbed_step(p, j)
        delta[j] = q[j] - p[j]          # the step actually applied
        other = _call_make(make, q, f"p + delta e_{j}")
        _same_structure(structure, other, j)
        others.append(other)
    return _Perturbed(base, others, delta)


def _call_make(make: Callable[[np.ndarray], Solver], q: np.ndarray, what: str) -> Solver:
    try:
        s = make(q.copy())
    except Exception as e:
        raise ValueError(f"make({what} = {q.tolist()}) raised {type(e).__name__}: {e}; "
                         "sensitivities need make to accept parameters near p") from e
    if not isinstance(s, Solver):
        raise TypeError(f"make({what}) returned {type(s).__name__}; expected a dmi.Solver")
    return s


def _structure(s: Solver) -> list:
    """(name, value) of what a parameter may not change."""
    terms = s.kernel_terms
    return [("n", s.n), ("N", s.N), ("h", s.h), ("tau", s.tau), ("the kind of A", s.resolvent_kind),
            ("the kind of kernel", s.kernel_kind), ("the convolution method", s.convolution),
            ("the quadrature rule", s.quadrature), ("the near kernel's delta", s.kernel_near_delta),
            ("the number of kernel terms", None if terms is None else len(terms[0]))]


def _same_structure(structure: list, b: Solver, j: int) -> None:
    """ValueError naming what parameter j changes among the things a sensitivity cannot follow."""
    for (name, x), (_, y) in zip(structure, _structure(b)):
        if x != y:
            hint = (" (dmi.kernels.fit chooses its terms anew for each kernel: fit once, outside "
                    "make, and set KernelFit.refit(kernel) in make, which keeps the rates)"
                    if name == "the number of kernel terms" and b.kernel_fit is not None else "")
            raise ValueError(f"parameter {j} changes {name} ({x!r} -> {y!r}){hint}; a parameter may "
                             "change values of the model, not its structure: keep n, N, h, tau, the "
                             "kinds of A and kernel, the number of kernel terms, the convolution "
                             "method and the quadrature fixed in make")


def _theta(s: Solver) -> float:
    """Weight of the last delay cell relative to h (1 when h = tau / N, as libdmi decides it)."""
    N, h, tau = s.N, s.h, s.tau
    M = round(tau / h)
    if M >= 1 and tau / M == h:
        return 1.0
    return tau / h - (N - 1)


def _refit_terms(fitted: Any, other: Any, delta: float, n: int) -> np.ndarray | None:
    """dE_j = dC - i dD of a kernel set from KernelFit.refit of a PowerKernel, where the model at
    p + delta e_j refits another PowerKernel: the refit's linear map applied to the closed-form
    derivative of c s^-beta in c and beta (dc and dbeta by differences of the two kernels'
    parameters), shaped (K, n, n); None for other kernels (their terms are then differentiated
    by differences)."""
    from ..kernels import PowerKernel
    if fitted is None or other is None:
        return None
    f, entry = fitted
    k0, k1 = getattr(f, "kernel", None), getattr(other[0], "kernel", None)
    if (getattr(f, "method", "") != "fixed" or not isinstance(k0, PowerKernel)
            or not isinstance(k1, PowerKernel) or other[1] != entry
            or not np.array_equal(other[0].a, f.a) or not np.array_equal(other[0].b, f.b)):
        return None
    dbeta, dc = (k1.beta - k0.beta) / delta, (k1.c - k0.c) / delta
    dC, dDs = f.refit_derivative(lambda x: k0(x) * (dc / k0.c - dbeta * np.log(x)))
    out = np.zeros((len(f.a), n, n), dtype=complex)
    if entry is None:
        out[:] = dC - 1j * dDs
    else:
        out[:, entry[0], entry[1]] = dC - 1j * dDs
    return out


def _weights_of(other: Solver, j: int) -> tuple[np.ndarray, np.ndarray]:
    """Solver.kernel_weights of the model at p + delta_j e_j, initialised for them."""
    try:
        other.init()
    except Exception as e:
        raise ValueError(f"the model at p + delta e_{j} fails in init ({type(e).__name__}: {e}); "
                         "its kernel's weights, which the sensitivities differentiate, are "
                         "computed there") from e
    return other.kernel_weights()


# ---- the kernel's weights and their derivatives --------------------------------------------------

_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


def _exp_weights(s: Solver, lam: np.ndarray, cells: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per term k and cell l of ``cells``: w[k, l], the complex weight of e^{lam_k s} over cell l,
    and ws[k, l], that of s e^{lam_k s} (its derivative in lam_k); c[k] and c1[k], the factors of
    the full cells (w[k, l] = c_k r_k^l and ws[k, l] = r_k^l (l h c_k + c1_k) for l < N - 1,
    r_k = e^{lam_k h})."""
    N, h = s.N, s.h
    lags = cells * h
    length = np.where(cells == N - 1, _theta(s) * h, h)
    if s.quadrature == "left":
        e = np.exp(np.outer(lam, lags))
        return (length * e, length * lags * e, np.full(len(lam), h, dtype=complex),
                np.zeros(len(lam), dtype=complex))
    # the cell rule: the integrals over each cell, by Gauss-Legendre (the integrands are smooth)
    nodes = lags[:, None] + 0.5 * length[:, None] * (1.0 + _GL_X[None, :])     # (L, G)
    wts = 0.5 * length[:, None] * _GL_W[None, :]
    e = np.exp(lam[:, None, None] * nodes[None])                                  # (K, L, G)
    w = np.sum(e * wts[None], axis=2)
    ws = np.sum(e * (nodes * wts)[None], axis=2)
    x = 0.5 * h * (1.0 + _GL_X)
    e1 = np.exp(lam[:, None] * x[None]) * (0.5 * h * _GL_W)[None]
    return w, ws, np.sum(e1, axis=1), np.sum(e1 * x[None], axis=1)


class _Memory:
    """The delay sum of the tangent, sum_l G_l S^{p-l}, and the kernel's part dG_l U^{p-l}
    (:meth:`kernel_part`).  An exponential kernel's recursion needs only its last cell's weights
    (O(K)); the weights of all N cells (``G``, ``w``, ``ws``, ``powers``) are computed where a
    loop first asks for them."""

    def __init__(self, mod: _Perturbed, Uext: Callable[[], np.ndarray], P: int):
        s = mod.base
        self.N, self.n, self.h = s.N, s.n, s.h
        self._solver = s
        self._Uext, self.P = Uext, P
        self._flat: np.ndarray | None = None
        self._dWU: np.ndarray | None = None
        kind = s.kernel_kind
        self.kind = kind
        self.active = kind in ("exp", "callback")
        self.recursive = False
        self.Z = None
        n, N = self.n, self.N
        if kind == "exp":
            a, b, C, D = s.kernel_terms
            self.lam = a + 1j * b
            self.E0 = C - 1j * D                                                 # (K, n, n)
            # the terms' derivatives: dE[j, k] of C - iD and dl[j, k] of lam_k in p_j
            terms = [mod.terms_of(j) for j in range(P)]
            a2, b2, C2, D2 = (np.array([t[i] for t in terms]) for i in range(4))
            self.dl = ((a2 - a) + 1j * (b2 - b)) / mod.delta[:, None]
            self.dE = ((C2 - C) - 1j * (D2 - D)) / mod.delta[:, None, None, None]
            fitted = s.kernel_fit
            for j, other in enumerate(mod.others if fitted is not None else []):
                refit = _refit_terms(fitted, other.kernel_fit, mod.delta[j], n)
                if refit is not None:
                    self.dE[j] = refit
                elif (fitted is not None and getattr(fitted[0], "method", "") == "fixed"
                        and np.any(self.dE[j] != 0)):
                    warnings.warn(f"sensitivities: parameter {j} changes the coefficients of a "
                                  "KernelFit.refit of a kernel that is not a PowerKernel: they are "
                                  "differentiated by differences, which the refit's least-squares "
                                  "conditioning makes inaccurate (to about 1e-3 on a 25-term fit); "
                                  "set the kernel's terms from its parameters (set_kernel_exp) or "
                                  "use a PowerKernel", RuntimeWarning, stacklevel=4)
                elif (fitted is not None and getattr(fitted[0], "method", "") in ("esprit", "laplace")
                        and np.any(self.dl[j] != 0)):
                    raise ValueError(f"parameter {j} moves the rates of the kernel's fit "
                                     f"(dmi.kernels.fit, method {fitted[0].method!r}): fit chooses "
                                     "its rates anew for each kernel, a choice that is not "
                                     "differentiable, so the sensitivities would follow it wrongly; "
                                     "fit once, outside make, and set KernelFit.refit(kernel) in "
                                     "make (the same rates, coefficients linear in the kernel)")
            # the recursion: Z_k^p = sum_l r_k^l S^{p-l} (all N cells), then the last cell mended
            # (its factors, which only the Python loop reads, computed on first use: _recursion)
            self.recursive = bool((a <= 0.0).all() and (np.abs(b) * self.h <= math.pi).all())
        elif kind == "callback":
            # the weights libdmi computed in init (the left rule's, or the cell rule's integrals),
            # and their derivatives from those of the models whose kernel differs
            self.G = s.kernel_weights()[0]
            self.dG = np.zeros((P, N, n, n))
            for j, other in enumerate(mod.others):
                if not s.same_callback(other, "kernel"):
                    self.dG[j] = (_weights_of(other, j)[0] - self.G) / mod.delta[j]
        # the near cells' part of the weights (set_kernel_near, set_kernel_fit with delta > 0):
        # what they add to the exponential sum's weights, D (m, n, n), and its derivatives: the
        # whole weights' derivative on the near cells (differences of libdmi's weights, in which
        # the sum's coefficients do not enter) less the exponential sum's there
        self.near = np.zeros((0, n, n))
        self.dnear = np.zeros((P, 0, n, n))
        if kind == "exp" and s.has("kernel_near"):
            q = s.kernel_near_delta / s.h
            m = N if q >= N else math.ceil(q)
            G0, D = s.kernel_weights()
            K = len(self.lam)
            wm, wsm, _, _ = _exp_weights(s, self.lam, np.arange(m))
            dD = np.zeros((P, m, n, n))
            terms = s.kernel_terms
            for j, other in enumerate(mod.others):
                if (s.same_callback(other, "kernel_near")
                        and all(np.array_equal(x, y) for x, y in zip(terms, other.kernel_terms))):
                    continue
                whole = (_weights_of(other, j)[0][:m] - G0[:m]) / mod.delta[j]
                summed = (wm.T @ self.dE[j].reshape(K, n * n)
                          + (wsm * self.dl[j][:, None]).T @ self.E0.reshape(K, n * n))
                dD[j] = whole - summed.real.reshape(m, n, n)
            self.near = np.ascontiguousarray(D[:m])
            self.dnear = dD

    def _recursion(self) -> None:
        """The last cell's weights (``wlast``, ``wslast``), the full cells' factors (``c``,
        ``c1``) and, under the recursion, its multipliers and the last cell's mend (``E``, ``r``,
        ``rN``, ``rlast``, ``last``) of an exponential kernel."""
        s, N = self._solver, self.N
        wl, wsl, self.c, self.c1 = _exp_weights(s, self.lam, np.array([N - 1]))
        self.wlast, self.wslast = wl[:, 0], wsl[:, 0]
        if self.recursive:
            self.E = self.E0 * self.c[:, None, None]
            self.r = np.exp(self.lam * s.h)
            self.rN = np.exp(self.lam * s.h * N)
            self._r3, self._rN3 = self.r[:, None, None], self.rN[:, None, None]
            self.rlast = np.exp(self.lam * s.h * (N - 1))
            # G_{N-1} less what the full-cell recursion puts on the last cell
            self.last = np.einsum("k,kij->ij", self.wlast - self.rlast * self.c, self.E0).real

    def __getattr__(self, name: str) -> Any:
        # the recursion's factors and the all-cells weights of an exponential kernel, computed on
        # first use
        if (name in ("wlast", "wslast", "c", "c1", "E", "r", "rN", "_r3", "_rN3", "rlast", "last")
                and self.__dict__.get("kind") == "exp" and "lam" in self.__dict__):
            self._recursion()
            if name in self.__dict__:
                return self.__dict__[name]
        if name in ("w", "ws", "G", "powers") and self.__dict__.get("kind") == "exp":
            N, K, n = self.N, len(self.lam), self.n
            w, ws, _, _ = _exp_weights(self._solver, self.lam, np.arange(N))
            self.w, self.ws = w, ws
            # sum_k w[k, l] E_k as one matrix product (N, K) @ (K, n n)
            self.G = (w.T @ self.E0.reshape(K, n * n)).real.reshape(N, n, n)
            self.G[:len(self.near)] += self.near
            self.powers = np.exp(np.outer(self.lam, np.arange(N) * self.h))       # (K, N)
            return self.__dict__[name]
        raise AttributeError(name)

    def kernel_part(self) -> np.ndarray:
        """dWU[p, :, j] = sum_l dG_j[l] U^{p-l} for all steps at once (steps, n, P): one FFT
        convolution per parameter, U transformed once (memory O((N + steps) n^2), not times P)."""
        if self._dWU is not None:
            return self._dWU
        N, P, Uext = self.N, self.P, self._Uext()
        n = Uext.shape[1]
        if self.kind == "exp":
            K = len(self.lam)
            Ef = self.E0.reshape(K, n * n)
            wT = self.w.T
            dG = [(wT @ self.dE[j].reshape(K, n * n)
                   + (self.ws * self.dl[j][:, None]).T @ Ef).real.reshape(N, n, n) for j in range(P)]
        else:
            dG = self.dG
        steps = len(Uext) - N
        if len(self.near):
            self._dWU = self.near_kernel_part()
        else:
            self._dWU = np.zeros((steps, n, P))
        size = sp_fft.next_fast_len(N + len(Uext) - 1, real=True)
        FU = sp_fft.rfft(Uext, size, axis=0)[:, :, None]                       # (F, n, 1)
        for j in range(P):
            conv = sp_fft.irfft((sp_fft.rfft(dG[j], size, axis=0) @ FU)[:, :, 0], size, axis=0)
            self._dWU[:, :, j] += conv[N - 1:N - 1 + steps]
        return self._dWU

    def near_kernel_part(self) -> np.ndarray:
        """sum_{l<m} dD_j[l] U^{p-l} for all steps (steps, n, P): the near cells' part of
        :meth:`kernel_part`, which the compiled loop takes on its own beside its recursion."""
        Uext = self._Uext()
        return near_kernel_part(self.dnear, Uext, self.N, len(Uext) - self.N)

    def _recompute(self, Sall: np.ndarray, p: int) -> None:
        window = Sall[p + 1:p + self.N + 1][::-1]                                # S^{p-l}
        self.Z = np.einsum("kl,lnq->knq", self.powers, window)
        self.since = 0

    def sum_S(self, Sall: np.ndarray, p: int) -> np.ndarray:
        """sum_l G_l S^{p-l}, (n, P); Sall[q + N] = S^q."""
        N = self.N
        if self.recursive:
            if self.Z is None or self.since >= 4 * N:
                self._recompute(Sall, p)
            out = np.einsum("kij,kjq->iq", self.E, self.Z).real + self.last @ Sall[p + 1]
            near_sum(self.near, Sall, p, N, out)
            return out
        rows = Sall[p + 1:p + N + 1]
        return self.flat() @ rows.reshape(N * rows.shape[1], rows.shape[2])

    def flat(self) -> np.ndarray:
        """The weights as one (n, N n) matrix [G_{N-1} ... G_0], so that sum_l G_l S^{p-l} =
        sum_m G_{N-1-m} S^{p-N+1+m} is one matrix product on the stored rows S^{p-N+1}, ..., S^p."""
        if self._flat is None:
            n = self.G.shape[1]
            self._flat = np.ascontiguousarray(self.G[::-1].transpose(1, 0, 2).reshape(n, self.N * n))
        return self._flat

    def push(self, Sall: np.ndarray, p: int) -> None:
        """Advances Z from step p to p + 1 once S^{p+1} is in Sall."""
        if self.recursive and self.Z is not None:
            self.Z = self._r3 * self.Z + (Sall[p + 1 + self.N] - self._rN3 * Sall[p + 1])
            self.since += 1


# ---- the run --------------------------------------------------------------------------------------

def sensitivities(make: Callable[[np.ndarray], Solver], p: Any, steps: int, *,
                  rhs: Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None = None,
                  jumps: bool = True, engine: str = "auto", max_steps: int | None = None
                  ) -> Sensitivities:
    """The states U^p and their sensitivities dU^p/dp of the model ``make(p)`` over ``steps``
    steps from t = 0.

    Parameters
    ----------
    make : callable
        ``make(p) -> dmi.Solver``, the model at the parameter vector p (a new solver, set but
        not necessarily initialised; it is initialised here).  p may enter f, the friction
        coefficients, the box, the kernel (its exponential terms a, b, C, D, a kernel callback
        under either rule, the near kernel of ``set_kernel_near``, a ``PowerKernel``'s c and beta
        through ``KernelFit.refit``: through the weights libdmi computes, ``Solver.kernel_weights``)
        and the history; it may not change n, N, h, tau, the kinds of A and kernel,
        the number of kernel terms, the convolution method or the quadrature rule.  A parameter
        enters f (or the history) unless :meth:`dmi.Solver.same_callback` finds the perturbed
        model's callback the same as the model's; f and the history are differentiated only in the
        parameters that enter them.
    p : array_like, shape (P,)
        The parameters.
    steps : int
        Number of steps, >= 1.
    rhs : callable, optional
        ``rhs(t, u, p) -> (n,)``, the model's f as a Python function of complex u and p: f_u S +
        f_p by complex step (checked once against a directional difference) instead of
        directional differences of the solver's f.
    jumps : bool, optional
        True (default): the saltation factor at reversals (S converges to the equation's
        sensitivity); False: the plain tangent of the scheme everywhere.
    engine : str, optional
        The loop over the steps: ``"auto"`` (default) the compiled one where it applies, else
        the Python one; ``"compiled"`` (libdmi's loop, ``dmi_tangent_run``, nothing compiled
        at the first call; f a C function in every model (``jit=True``, a cfunc, a ctypes
        function) or no f, A zero, friction or a box, no ``rhs``): an error where it does not
        apply; ``"python"``: one step at a time in Python, calling f through
        :meth:`dmi.Solver.eval_rhs`.  Both give the same S to rounding.
    max_steps : int, optional
        The most steps accepted (default :data:`MAX_STEPS`, 2 000 000); more is refused before
        any run, with the memory it would take (:func:`memory_bytes`).

    Returns
    -------
    Sensitivities
        t, u, S (dU/dp), the resolvent arguments x and dx, h, and the reversals and sticks met.

    Raises
    ------
    ValueError
        p not a finite vector, steps < 1, make raising at p or near it, a parameter changing the
        model's structure or the rates of a kernel fit chosen by ``dmi.kernels.fit`` (use
        ``KernelFit.refit``), more steps than ``max_steps``, a perturbed model failing in init,
        ``rhs`` disagreeing with the solver's f, an unknown ``engine``, or
        ``engine="compiled"`` where it does not apply (the message says why).
    TypeError
        make not returning a dmi.Solver.
    """
    p = _checked(p, steps, engine)
    return _sensitivities_of(_build(make, p), p, steps, rhs=rhs, jumps=jumps, engine=engine,
                             max_steps=max_steps)


def _sensitivities_of(mod: _Perturbed, p: np.ndarray, steps: int, *,
                      rhs: Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None = None,
                      jumps: bool = True, engine: str = "auto", max_steps: int | None = None
                      ) -> Sensitivities:
    """:func:`sensitivities` of the models ``mod`` (:func:`_build`: the model at p and at
    p + delta_j e_j) made at the checked p; the models may be those of an earlier call at the
    same p (each run starts from their init)."""
    s = mod.base
    check_steps(steps, s.n, s.N, len(p), s.h, max_steps, "sensitivities")
    s.init()
    window = s.get_window()                                          # U^{-N}, ..., U^0
    run: list = []                      # [U] of the run, once made
    memory = _Memory(mod, lambda: np.concatenate([window[1:], run[0][1:]]), len(p))
    has_f = s.has("rhs") or any(o is not s and o.has("rhs") for o in mod.others)
    # f_u S + f_p: by n columns of f_u and one call for each parameter f depends on, where that
    # makes fewer calls of f than one directional difference per parameter
    fpar = depends = None
    if has_f and rhs is None:
        depends = np.array([o is not s and not s.same_callback(o, "rhs") for o in mod.others])
        if s.n + int(depends.sum()) < len(p):
            fpar = np.flatnonzero(depends).astype(np.int64)
    why = _not_compiled(mod, has_f, rhs) if engine != "python" else "engine='python'"
    if why and engine == "compiled":
        raise ValueError(f"engine='compiled' does not apply: {why}; use engine='auto' or 'python'")
    # S of the history: dz(t_q)/dp for q = -N, ..., 0, only for the parameters whose perturbed
    # model has another history (Solver.same_callback); the other columns are 0.  libdmi's loop
    # samples compiled history callbacks itself (dmi_tangent_sample_history, as init does);
    # otherwise each such perturbed model's init samples its own
    hist = (mod.hist if mod.hist is not None else
            [j for j, o in enumerate(mod.others) if not s.same_callback(o, "history")])
    handles = _history_handles(mod, hist)
    compiled_history = handles is not None and all(m.c_callback("history") is not None
                                                   for m in [s, *(handles[j] for j in hist)])
    if not why:
        history = (hist if hist and compiled_history else _history_by_init(mod, hist, window))
        fast = _libdmi_loop(mod, steps, history, memory, run, depends, jumps,
                            handles if compiled_history else mod.others)
        if fast is not None:
            return fast
        # a call of f failed: the Python loop below raises the callback's own error
        s.init()
    return _python_loop(_Loop(mod, p, steps, rhs, jumps, has_f, fpar, memory, run),
                        _history_by_init(mod, hist, window))


def _checked(p: Any, steps: Any, engine: str) -> np.ndarray:
    """The parameters as a vector of floats; a ValueError for bad p, steps or engine."""
    p = np.array(p, dtype=float).reshape(-1) if np.ndim(p) <= 1 else None
    if p is None or len(p) == 0 or not np.all(np.isfinite(p)):
        raise ValueError("p: expected a nonempty vector of finite numbers")
    if not isinstance(steps, (int, np.integer)) or steps < 1:
        raise ValueError(f"steps = {steps!r}: expected an integer >= 1")
    if engine not in ("auto", "compiled", "python"):
        raise ValueError(f"engine = {engine!r}: expected 'auto', 'compiled' or 'python'")
    return p


@dataclasses.dataclass
class _Loop:
    """What the Python loop over the steps needs: the models, the parameters, the run's length and
    options, how f is differentiated (``fpar``: the parameters f depends on, when by columns), the
    memory of S and the run (filled by the loop)."""
    mod: _Perturbed
    p: np.ndarray
    steps: int
    rhs: Callable | None
    jumps: bool
    has_f: bool
    fpar: np.ndarray | None
    memory: _Memory
    run: list


@dataclasses.dataclass
class _Resolvent:
    """The resolvent's kind and its derivatives in p, which do not depend on the step: the
    friction levels and their derivatives, or the box's faces and theirs."""
    kind: str
    alpha: Any = None
    dalpha: Any = None
    lo: Any = None
    hi: Any = None
    dlo: Any = None
    dhi: Any = None


def _resolvent_of(mod: _Perturbed) -> _Resolvent:
    """The base model's resolvent and its differences against the perturbed models'."""
    s = mod.base
    r = _Resolvent(s.resolvent_kind, alpha=s.friction)
    if r.kind == "friction":
        r.dalpha = np.stack([(o.friction - r.alpha) / d for o, d in zip(mod.others, mod.delta)],
                            axis=1)
    elif r.kind == "box":
        r.lo, r.hi = s.box
        r.dlo = np.stack([_bound_diff(o.box[0], r.lo) / d for o, d in zip(mod.others, mod.delta)],
                         axis=1)
        r.dhi = np.stack([_bound_diff(o.box[1], r.hi) / d for o, d in zip(mod.others, mod.delta)],
                         axis=1)
    return r


def _f_directions(L: _Loop, t: float, u: np.ndarray, Sq: np.ndarray) -> np.ndarray:
    """f_u S + f_p at one step: by complex step, by columns, or one directional difference per
    parameter (zero without f)."""
    mod, s = L.mod, L.mod.base
    if L.rhs is not None:
        return _complex_directions(L.rhs, t, u, L.p, Sq)
    if L.fpar is not None:
        return _f_columns(s, mod, L.fpar, t, u, Sq)
    if not L.has_f:
        return np.zeros((s.n, len(L.p)))
    f0 = s.eval_rhs(t, u)
    moved = u + mod.delta[:, None] * Sq.T                             # (P, n): U + delta_j S_j
    return (np.array([o.eval_rhs(t, m) for o, m in zip(mod.others, moved)]).T
            - f0[:, None]) / mod.delta


def _python_loop(L: _Loop, history: np.ndarray) -> Sensitivities:
    """The tangent step by step in Python, f through :meth:`dmi.Solver.eval_rhs`."""
    mod, s, steps, memory = L.mod, L.mod.base, L.steps, L.memory
    n, N, h, P = s.n, s.N, s.h, len(L.p)
    r = _resolvent_of(mod)
    Sall = np.empty((N + steps + 1, n, P))
    Sall[:N + 1] = history
    t, U, X = s.run_terms(steps)
    L.run[:] = [U]
    if L.rhs is not None:
        _check_complex_rhs(L.rhs, mod, L.p, t[0], U[0], Sall[N])
    phi = (U[:-1] - X) / h                                            # f + W at each step
    if r.kind == "friction":
        # R' (1 slipping, 0 stuck) and dR/dp = -h sign(X) dalpha where slipping, for every step
        slipping = friction_slope(X, h * r.alpha)
        dR = friction_slope_alpha(X, h * r.alpha, h)[:, :, None] * r.dalpha[None]
        # the steps where a slipping friction component meets zero or changes sign
        meets = np.any(reaches_zero(U[:-1], U[1:]) & (r.alpha > 0.0), axis=1)
    dX = np.empty((steps, n, P))
    switches: list = []
    dWU = memory.kernel_part() if memory.active else None
    for q in range(steps):
        Sq = Sall[q + N]
        T = Sq - h * _f_directions(L, t[q], U[q], Sq)
        if memory.active:
            T -= h * (memory.sum_S(Sall, q) + dWU[q])
        dX[q] = T
        Snew = Sall[q + 1 + N]
        if r.kind == "friction":
            np.multiply(T, slipping[q][:, None], out=Snew)
            Snew += dR[q]
            if L.jumps and meets[q]:
                _reversals(q, U, phi, r.alpha, r.dalpha, T, Snew, h, switches)
        elif r.kind == "box":
            side = box_side(X[q], r.lo, r.hi)[:, None]
            Snew[:] = np.where(side < 0, r.dlo, np.where(side > 0, r.dhi, T))
        elif r.kind == "callback":
            for j, other in enumerate(mod.others):
                Snew[:, j] = (other.eval_resolvent(h, X[q] + mod.delta[j] * T[:, j])
                              - U[q + 1]) / mod.delta[j]
        else:
            Snew[:] = T
        memory.push(Sall, q)
    return _result(t, U, Sall[N:], X, dX, h, switches, "python")


def _kernel_depends(memory: _Memory) -> bool:
    """Whether a parameter moves the kernel's weights (the tangent then has dG_l U^{p-l})."""
    if not memory.active:
        return False
    if memory.kind == "exp":
        return bool(np.any(memory.dE) or np.any(memory.dl) or np.any(memory.dnear))
    return bool(np.any(memory.dG))


def _history_handles(mod: _Perturbed, hist: list) -> list | None:
    """The models libdmi's loop is given per parameter so that its own sampling of the history
    (``dmi_tangent_sample_history``) reads each parameter in ``hist`` from the model carrying its
    perturbation: ``mod.others``, with a grouped build's history source put in the place of the
    base model it reads f and the resolvent from, where that changes nothing else the loop reads
    of it (f is read only for the parameters flagged as moving it, and the source's friction or
    box is the base model's); None where a source cannot take that place."""
    if mod.sources is None:
        return mod.others
    base, handles = mod.base, list(mod.others)
    for j in hist:
        src = mod.sources[j]
        if src is handles[j]:
            continue
        if (handles[j] is not base or not _same_resolvent(base, src)
                or src.has("rhs") != base.has("rhs")):
            return None
        handles[j] = src
    return handles


def _same_resolvent(a: Solver, b: Solver) -> bool:
    """Whether the two models' friction coefficients or boxes are the same, bit for bit."""
    kind = a.resolvent_kind
    if kind != b.resolvent_kind or kind not in ("", "friction", "box"):
        return False
    if kind == "friction":
        return np.array_equal(a.friction, b.friction)
    if kind == "box":
        return all(np.array_equal(x, y) for x, y in zip(a.box, b.box))
    return True


def _history_by_init(mod: _Perturbed, hist: list, window: np.ndarray) -> np.ndarray:
    """The history's S, (N + 1, n, P): for the parameters in ``hist``, the window of the
    perturbed model (after its init, which samples its own history) less the model's, over
    delta_j; 0 for the others."""
    S0 = np.zeros(window.shape + (len(mod.delta),))
    for j in hist:
        other = mod.source(j)
        other.init()
        d = other.get_window() - window
        if d.any():                     # (the columns of parameters the history has not stay 0)
            S0[:, :, j] = d / mod.delta[j]
    return S0


def _libdmi_loop(mod: _Perturbed, steps: int, history: np.ndarray | list, memory: _Memory,
                 run: list, depends: np.ndarray | None, jumps: bool,
                 handles: list | None = None) -> Sensitivities | None:
    """The run and its tangent by libdmi's loop (dmi_tangent_run) from the initialised model;
    None where it fails (the model is then where it was).  The history's S is ``history``,
    (N + 1, n, P), or, where it lists parameters, sampled by libdmi from those perturbed models'
    compiled history callbacks.  Where a parameter moves the kernel, the kernel parameters' part of the
    delay sum, sum_l dG_l U^{p-l}, comes from the exponential terms' derivatives in libdmi's loop
    or, for what they do not say, needs the states first: a plain run gives them, and the model
    goes back to its start (its saved state) for libdmi's.  ``handles``: the models given to
    libdmi per parameter (:func:`_history_handles`; None: ``mod.others``)."""
    s = mod.base
    h = s.h
    dWU = terms = None
    # an exponential kernel under the recursion: libdmi differentiates its terms in the loop;
    # the near cells' part, and any other kernel's, come as dWU from the states of a plain run
    by_terms = (memory.kind == "exp" and memory.recursive
                and s.convolution in ("auto", "recursive"))
    if by_terms and (memory.dE.any() or memory.dl.any()):
        dE = memory.dE.transpose(1, 2, 3, 0)                    # (K, n, n, P)
        terms = (memory.dl.real.T, memory.dl.imag.T, dE.real, -dE.imag)
    if (memory.dnear.any() if by_terms else _kernel_depends(memory)):
        start = s.save_state()
        run[:] = [s.run_terms(steps)[1]]
        dWU = memory.near_kernel_part() if by_terms else memory.kernel_part()
        s.load_state(start)
    try:
        U, X, S, dX, codes = s._tangent(mod.others if handles is None else handles, mod.delta,
                                        steps, history, dWU, depends, jumps, terms)
    except Error as e:
        if e.code != _lib.ECALLBACK:
            raise
        return None     # a failing callback: the Python loop raises the callback's own error
    names = {1: "stick", 2: "reversal", 3: "unplaced"}
    qs, comps = np.nonzero(codes) if codes.any() else (np.zeros(0, int), np.zeros(0, int))
    switches = [(q, i, names[int(codes[q, i])]) for q, i in zip(qs.tolist(), comps.tolist())]
    t = np.arange(steps + 1) * h
    return _result(t, U, S, X, dX, h, switches, "compiled")


def _f_columns(s: Solver, mod: _Perturbed, fpar: np.ndarray, t: float, u: np.ndarray,
               S: np.ndarray) -> np.ndarray:
    """f_u S + f_p at (t, u): f_u by forward differences of n columns (step 2^-26 max(1, |u_i|)
    as applied), f_p_j by a difference in p_j for the parameters in fpar (0 for the others)."""
    n = len(u)
    f0 = s.eval_rhs(t, u)
    e = (u + REL_STEP * np.maximum(1.0, np.abs(u))) - u
    J = (s.eval_rhs_many(np.full(n, t), u + np.diag(e)) - f0).T / e
    Fd = J @ S
    for j in fpar:
        Fd[:, j] += (mod.others[j].eval_rhs(t, u) - f0) / mod.delta[j]
    return Fd


def _result(t: np.ndarray, U: np.ndarray, S: np.ndarray, X: np.ndarray, dX: np.ndarray, h: float,
            switches: list, engine: str) -> Sensitivities:
    """The Sensitivities of a run, with a RuntimeWarning where a reversal could not be placed."""
    out = Sensitivities(t, U, S, X, dX, h, switches, engine)
    if out.unplaced:
        steps = out.unplaced
        shown = ", ".join(str(q) for q in steps[:5]) + (", ..." if len(steps) > 5 else "")
        warnings.warn(f"sensitivities: {len(steps)} reversal(s) of a friction component could not be "
                      f"placed inside their step (steps {shown}, t = {t[steps[0]]:.6g} first): the "
                      "velocities interpolated there do not have the signs of a reversal, so S is the "
                      "plain tangent of the scheme there, off by O(1) from the equation's "
                      f"sensitivity; take a smaller h (now {h:.6g}) so that each reversal is "
                      "resolved", RuntimeWarning, stacklevel=3)
    return out


def _not_compiled(mod: _Perturbed, has_f: bool, rhs: Callable | None) -> str:
    """Why the compiled loop does not apply ("" where it does)."""
    if rhs is not None:
        return "rhs= (complex step) calls a Python function"
    kind = mod.base.resolvent_kind
    if kind not in ("", "friction", "box"):
        return f"A is a {kind} (its resolvent is called from Python)"
    if has_f:
        for j, m in enumerate([mod.base, *mod.others]):
            if (j == 0 or m is not mod.base) and m.c_callback("rhs") is None:
                where = "p" if j == 0 else f"p + delta e_{j - 1}"
                return (f"f of the model at {where} is a Python function (set_rhs(f, jit=True) or a "
                        "C function makes it compiled)")
    return ""


def _bound_diff(b2: np.ndarray, b: np.ndarray) -> np.ndarray:
    """b2 - b, 0 where both bounds are the same infinity."""
    with np.errstate(invalid="ignore"):
        d = b2 - b
    return np.where(b2 == b, 0.0, d)


def _reversals(q: int, U: np.ndarray, phi: np.ndarray, alpha: np.ndarray, dalpha: np.ndarray,
               T: np.ndarray, Snew: np.ndarray, h: float, switches: list) -> None:
    """At step q, for each friction component that reverses during the step (see
    :func:`_saltation.reversal`), S_i^{q+1} = rho (T_i - h s dalpha_i), rho = F+ / F- the
    saltation factor and s the sign of U_i^q; a component that lands in the dead zone and stays
    is recorded as a stick."""
    for i in range(U.shape[1]):
        what, rho = reversal(q, i, U, phi, alpha)
        if what == STICK:
            switches.append((q, i, "stick"))
        elif what == UNPLACED:
            switches.append((q, i, "unplaced"))
        elif what == REVERSAL:
            Snew[i] = salted(rho, T[i], h, math.copysign(1.0, U[q, i]), dalpha[i])
            switches.append((q, i, "reversal"))


def _complex_directions(rhs: Callable, t: float, u: np.ndarray, p: np.ndarray,
                        S: np.ndarray) -> np.ndarray:
    """f_u S_j + f_p_j for each j by complex step."""
    eps = 1e-30
    out = np.empty(S.shape)
    for j in range(len(p)):
        pc = p.astype(complex)
        pc[j] += 1j * eps
        out[:, j] = np.imag(np.asarray(rhs(t, u + 1j * eps * S[:, j], pc))) / eps
    return out


def _check_complex_rhs(rhs: Callable, mod: _Perturbed, p: np.ndarray, t: float, u: np.ndarray,
                       S: np.ndarray) -> None:
    """ValueError unless rhs(t, u, p) is the solver's f and its complex-step directions agree with
    the directional differences at the first step (to 1e-5 relative)."""
    s = mod.base
    try:
        f = np.asarray(rhs(t, u.astype(complex), p.astype(complex)))
    except Exception as e:
        raise ValueError(f"rhs(t, u, p) raised {type(e).__name__} on complex arguments: {e}") from e
    f0 = s.eval_rhs(t, u)
    if f.shape != (s.n,) or not np.allclose(f.real, f0, rtol=1e-12, atol=1e-12 * (1 + np.abs(f0).max())):
        raise ValueError(f"rhs(t, u, p) = {f!r} at t = {t}, u = {u!r} is not the solver's f = {f0!r}")
    # a direction with a state part too, so that f_u is checked as well as f_p
    S1 = S + 1.0
    cs = _complex_directions(rhs, t, u, p, S1)
    for j, other in enumerate(mod.others):
        d = mod.delta[j]
        fd = (other.eval_rhs(t, u + d * S1[:, j]) - f0) / d
        scale = max(1.0, float(np.abs(cs[:, j]).max()), float(np.abs(fd).max()))
        if np.abs(cs[:, j] - fd).max() > 1e-5 * scale:
            raise ValueError(f"rhs: its complex-step derivative in direction {j} ({cs[:, j]!r}) "
                             f"disagrees with a difference of the solver's f ({fd!r}); rhs must "
                             "be the model's f(t, u, p), analytic in u and p")
