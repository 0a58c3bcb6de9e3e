# dmi.identify._compiled: the per-step loop of the sensitivities, compiled by numba (nopython).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The tangent loop of :func:`dmi.identify.sensitivities` compiled by numba, for models whose f is a
C function (a ``jit=True`` callback, a numba cfunc, a ctypes function): f is called through its
address, with no Python in between.  It does step by step what the Python loop of sensitivity.py
does, so the two agree to rounding.  What does not depend on the step comes from Python (the last
delay cell's weights, the kernel terms' derivatives, the friction's and the box's); the rest is done
here in the same pass over the steps: R' and dR/dp of the friction from the run, the exponential
memory's sums on S and the kernel parameters' part dG_l U^{p-l} by their recursions (started by
Horner's rule over the window, in real arithmetic where the exponents are real), and the saltation
test.  :func:`history_columns` samples compiled history callbacks as init does.  This module imports
numba (sensitivity.py imports it only where numba is installed); its functions are compiled on first
call and cached on disk."""
from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
from llvmlite import ir
from numba import types as nt
from numba.extending import intrinsic

from ._near import near_sum as _near_sum_python
from ._saltation import NONE, REVERSAL, STICK, UNPLACED
from ._saltation import reversal as _reversal_python

# codes of the memory and of the resolvent (arguments of the loop)
MEMORY_NONE, MEMORY_RECURSIVE, MEMORY_DIRECT = 0, 1, 2
RESOLVENT_NONE, RESOLVENT_FRICTION, RESOLVENT_BOX = 0, 1, 2
#: the test of a friction component at a step, the Python loop's function compiled
reversal = numba.njit(cache=True)(_reversal_python)
#: the near cells' part of the delay sum on S, the Python loop's function compiled
near_sum = numba.njit(cache=True)(_near_sum_python)


@intrinsic
def call_rhs(typingctx, address, t, u, out, user):
    """int f(double t, const double *u, double *out, void *user) at address."""
    sig = nt.int32(nt.int64, nt.float64, u, out, nt.int64)

    def codegen(context, builder, signature, args):
        addr, tt, ua, oa, us = args
        dbl = ir.DoubleType()
        fnty = ir.FunctionType(ir.IntType(32), [dbl, dbl.as_pointer(), dbl.as_pointer(),
                                                ir.IntType(8).as_pointer()])
        fn = builder.inttoptr(addr, fnty.as_pointer())
        up = context.make_array(signature.args[2])(context, builder, ua).data
        op = context.make_array(signature.args[3])(context, builder, oa).data
        return builder.call(fn, [tt, up, op, builder.inttoptr(us, ir.IntType(8).as_pointer())])
    return sig, codegen


@intrinsic
def call_history(typingctx, address, t, out, user):
    """int z(double t, double *out, void *user) at address."""
    sig = nt.int32(nt.int64, nt.float64, out, nt.int64)

    def codegen(context, builder, signature, args):
        addr, tt, oa, us = args
        dbl = ir.DoubleType()
        fnty = ir.FunctionType(ir.IntType(32), [dbl, dbl.as_pointer(), ir.IntType(8).as_pointer()])
        fn = builder.inttoptr(addr, fnty.as_pointer())
        op = context.make_array(signature.args[2])(context, builder, oa).data
        return builder.call(fn, [tt, op, builder.inttoptr(us, ir.IntType(8).as_pointer())])
    return sig, codegen


@numba.njit(cache=True)
def history_columns(addrs, users, N, h, tau, window, delta, cols, Sall):
    """The history's S, Sall[N - k, :, cols[j]] = (z_j(t_k) - z(t_k)) / delta_j, by calling the
    compiled history callbacks (addrs[1 + j], users[1 + j]) of the perturbed models at the times
    init uses, t_k = -k h (no lower than -tau, -tau at k = N); (addrs[0], users[0]) is the model's own, whose
    values must equal its window U^{-N}, ..., U^0 as init sampled it, bit for bit.  Returns 0 (and
    whether any S is nonzero), 1 where a call fails or gives a value that is not finite (init then
    raises the error), 2 where the model's own values differ from its window."""
    n = window.shape[1]
    u = np.empty(n)
    nonzero = False
    for j in range(addrs.shape[0]):
        for k in range(N + 1):
            tk = -k * h
            t = -tau if k == N else (0.0 if k == 0 else (-tau if tk < -tau else tk))
            u[:] = 0.0
            if call_history(addrs[j], t, u, users[j]) != 0:
                return 1, False
            row = window[N - k]
            for i in range(n):
                if not math.isfinite(u[i]):
                    return 1, False
                if j == 0:
                    if u[i] != row[i]:
                        return 2, False
                else:
                    d = (u[i] - row[i]) / delta[j - 1]
                    Sall[N - k, i, cols[j - 1]] = d
                    nonzero = nonzero or d != 0.0
    return 0, nonzero


@numba.njit(cache=True)
def loop(steps, N, h, t, U, X, phi, window, Sall, dX, delta, has_f, addrs, users, fcols, fpar,
         rel, memory, fresh, zcols, E, r, rN, rlast, last, flat, dWU, E0, cw, c1, wlast, wslast,
         dE, dl, near, dWn, kind, alpha, dalpha, jumps, lo, hi, dlo, dhi, sw_q, sw_i, sw_kind):
    """Fills Sall[N + 1:] and dX; returns (switches recorded, the step whose f call failed or -1).

    f_u S + f_p by directional differences (fcols False: one call of f per parameter) or, where
    fcols, f_u by n forward-difference columns (steps rel max(1, |u_i|) as applied) times S plus
    f_p by one call of f for each parameter in fpar (those f depends on; f_p is 0 for the others).
    zcols: the columns of the history's S that may be nonzero (the others are 0).

    The memory's arrays (E, r, rN, rlast, E0, cw, c1, wlast, wslast, dE, dl) are all real where
    the kernel's exponents and their derivatives are real, else all complex: numba compiles the
    loop once for each.  near (m, n, n) and dWn (steps, n, P): the near cells' part of the weights
    and of the kernel parameters' part beside the recursion (m = 0: none)."""
    n = U.shape[1]
    P = delta.shape[0]
    K = r.shape[0]
    zero = r[0] * 0.0 if K > 0 else 0.0 * r.sum()
    T = np.empty((n, P))
    acc = np.empty((n, P))
    f0 = np.empty(n)
    fj = np.empty(n)
    Fd = np.empty((n, P))
    J = np.empty((n, n))
    moved = np.empty(n)
    nacc = np.zeros((n, P))                    # the near cells' part of the delay sum on S
    Z = np.zeros((K, n, P), dtype=r.dtype)     # Z_k = sum_l r_k^l S^{q-l}
    Y = np.zeros((K, n), dtype=r.dtype)        # Y_k = sum_l r_k^l U^{q-l}
    Y1 = np.zeros((K, n), dtype=r.dtype)       # Y1_k = sum_l l r_k^l U^{q-l}
    A = np.zeros((K, n), dtype=r.dtype)
    EB = np.zeros((K, n), dtype=r.dtype)
    B = np.zeros(n, dtype=r.dtype)
    count = 0
    since = 0
    dl_used = np.empty(K, np.bool_)            # which kernel terms' derivatives are not all zero
    dE_used = np.empty((K, n, n), np.bool_)
    Z_used = np.empty((K, n), np.bool_)        # which columns of S the memory's terms read
    for k in range(K):
        dl_used[k] = np.any(dl[k] != 0.0)
        for i in range(n):
            Z_used[k, i] = np.any(E[k, :, i] != 0.0)
            for m in range(n):
                dE_used[k, i, m] = np.any(dE[k, i, m] != 0.0)
    Sflat = Sall.reshape(Sall.shape[0] * n, P)
    every = np.ones(P, np.bool_)
    if memory == MEMORY_RECURSIVE:
        _window_sums(0, N, window, U, Sall, r, Z, Y, Y1, fresh, zcols, Z_used)
    for q in range(steps):
        Sq = Sall[q + N]
        Sold = Sall[q + 1]                      # S^{q+1-N}
        Snew = Sall[q + 1 + N]
        # T = S - h (f_u S_j + f_p_j): one call of f at p and one at p + delta_j e_j per parameter
        if has_f:
            if call_rhs(addrs[0], t[q], U[q], f0, users[0]) != 0:
                return count, q
        if has_f and fcols:
            for c in range(n):                  # J[:, c] = (f(U + e_c e) - f(U)) / e_c
                for i in range(n):
                    moved[i] = U[q, i]
                e = (U[q, c] + rel * max(1.0, abs(U[q, c]))) - U[q, c]
                moved[c] = U[q, c] + e
                if call_rhs(addrs[0], t[q], moved, fj, users[0]) != 0:
                    return count, q
                for i in range(n):
                    J[i, c] = (fj[i] - f0[i]) / e
            for i in range(n):
                for j in range(P):
                    v = 0.0
                    for c in range(n):
                        v += J[i, c] * Sq[c, j]
                    Fd[i, j] = v
            for m in range(fpar.shape[0]):       # f_p_j = (f(U; p + delta_j e_j) - f(U)) / delta_j
                j = fpar[m]
                if call_rhs(addrs[j + 1], t[q], U[q], fj, users[j + 1]) != 0:
                    return count, q
                for i in range(n):
                    Fd[i, j] += (fj[i] - f0[i]) / delta[j]
            for i in range(n):
                for j in range(P):
                    T[i, j] = Sq[i, j] - h * Fd[i, j]
        elif has_f:
            for j in range(P):
                for i in range(n):
                    moved[i] = U[q, i] + delta[j] * Sq[i, j]
                if call_rhs(addrs[j + 1], t[q], moved, fj, users[j + 1]) != 0:
                    return count, q
                for i in range(n):
                    T[i, j] = Sq[i, j] - h * ((fj[i] - f0[i]) / delta[j])
        else:
            for i in range(n):
                for j in range(P):
                    T[i, j] = Sq[i, j]
        # T -= h (sum_l G_l S^{q-l} + sum_l dG_l U^{q-l}); U^{q+1-N} is the last cell's state
        ulast = window[q + 1] if q + 1 <= N else U[q + 1 - N]
        if memory == MEMORY_RECURSIVE:
            if since >= 4 * N:                  # the sums afresh, against the drift of the recursion
                _window_sums(q, N, window, U, Sall, r, Z, Y, Y1, True, every, Z_used)
                since = 0
            for k in range(K):
                # A_k = sum_l w_kl U^{q-l}, B = sum_l ws_kl U^{q-l}: the full cells from Y and Y1,
                # the last one mended
                fa = wlast[k] - cw[k] * rlast[k]
                fb = wslast[k] - rlast[k] * ((N - 1) * h * cw[k] + c1[k])
                for i in range(n):
                    A[k, i] = cw[k] * Y[k, i] + fa * ulast[i]
                    B[i] = h * cw[k] * Y1[k, i] + c1[k] * Y[k, i] + fb * ulast[i]
                for i in range(n):
                    s = zero
                    for m in range(n):
                        s += E0[k, i, m] * B[m]
                    EB[k, i] = s
            # (the blocks whose weights are zero, as for a kernel acting on some components
            # only, are skipped)
            for i in range(n):
                for j in range(P):
                    acc[i, j] = 0.0
                for m in range(n):
                    g = last[i, m]
                    if g != 0.0:
                        for j in range(P):
                            acc[i, j] += g * Sold[m, j]
                for k in range(K):
                    for m in range(n):
                        e = E[k, i, m]
                        if e != 0.0:
                            for j in range(P):   # the real part of E_k Z_k
                                z = Z[k, m, j]
                                acc[i, j] += e.real * z.real - e.imag * z.imag
                    # the kernel parameters' part: sum_k dE_jk A_k + dl_jk EB_k (real part)
                    v = EB[k, i]
                    if dl_used[k] and v != 0.0:
                        for j in range(P):
                            d = dl[k, j]
                            acc[i, j] += d.real * v.real - d.imag * v.imag
                    for m in range(n):
                        a = A[k, m]
                        if dE_used[k, i, m] and a != 0.0:
                            for j in range(P):
                                d = dE[k, i, m, j]
                                acc[i, j] += d.real * a.real - d.imag * a.imag
                for j in range(P):
                    T[i, j] -= h * acc[i, j]
            if near.shape[0] > 0:               # the near cells, beside the recursion
                nacc[:, :] = 0.0
                near_sum(near, Sall, q, N, nacc)
                for i in range(n):
                    for j in range(P):
                        T[i, j] -= h * (nacc[i, j] + dWn[q, i, j])
        elif memory == MEMORY_DIRECT:
            W = flat @ Sflat[(q + 1) * n:(q + N + 1) * n]
            for i in range(n):
                for j in range(P):
                    T[i, j] -= h * (W[i, j] + dWU[q, i, j])
        dX[q] = T
        if kind == RESOLVENT_FRICTION:
            # R' = 1 where U^{q+1} slips (dR/dp = -h sign(X) dalpha), 0 where it sticks
            for i in range(n):
                if U[q + 1, i] != 0.0:
                    sx = math.copysign(h, X[q, i]) if X[q, i] != 0.0 else 0.0
                    for j in range(P):
                        Snew[i, j] = T[i, j] - sx * dalpha[i, j]
                else:
                    for j in range(P):
                        Snew[i, j] = 0.0
            if jumps:
                # the components that slip at U^q and meet zero or change sign in the step
                for i in range(n):
                    if U[q, i] == 0.0 or U[q, i] * U[q + 1, i] > 0.0 or not alpha[i] > 0.0:
                        continue
                    what, rho = reversal(q, i, U, phi, alpha)
                    if what == REVERSAL:
                        sm = math.copysign(h, U[q, i])
                        for j in range(P):
                            Snew[i, j] = rho * (T[i, j] - sm * dalpha[i, j])
                    if what != NONE:
                        sw_q[count], sw_i[count], sw_kind[count] = q, i, what
                        count += 1
        elif kind == RESOLVENT_BOX:
            for i in range(n):
                for j in range(P):
                    if X[q, i] < lo[i]:
                        Snew[i, j] = dlo[i, j]
                    elif X[q, i] > hi[i]:
                        Snew[i, j] = dhi[i, j]
                    else:
                        Snew[i, j] = T[i, j]
        else:
            for i in range(n):
                for j in range(P):
                    Snew[i, j] = T[i, j]
        if memory == MEMORY_RECURSIVE:          # the sums from step q to q + 1
            unew = U[q + 1]
            for k in range(K):
                rk, rNk = r[k], rN[k]
                for i in range(n):
                    if Z_used[k, i]:            # (a column of S that E_k does not read is not kept)
                        for j in range(P):
                            Z[k, i, j] = rk * Z[k, i, j] + (Snew[i, j] - rNk * Sold[i, j])
                    Y1[k, i] = rk * (Y1[k, i] + Y[k, i]) - N * rNk * ulast[i]
                    Y[k, i] = rk * Y[k, i] + unew[i] - rNk * ulast[i]
            since += 1
    return count, -1


@numba.njit(cache=True)
def _window_sums(q, N, window, U, Sall, r, Z, Y, Y1, with_S, cols, rows):
    """Z_k, Y_k and Y1_k at step q by Horner's rule over the window U^{q-N+1}, ..., U^q (Z only
    where with_S: it is zero while the history's S is; only its columns j with cols[j] and its
    rows i with rows[k, i], the others left 0: S is 0 there, or Z is not read there)."""
    K, n, P = Z.shape
    for k in range(K):
        rk = r[k]
        for i in range(n):
            Y[k, i] = 0.0
            Y1[k, i] = 0.0
            for j in range(P):
                Z[k, i, j] = 0.0
        for m in range(q - N + 1, q + 1):
            u = window[m + N] if m <= 0 else U[m]
            for i in range(n):
                Y1[k, i] = rk * (Y1[k, i] + Y[k, i])
                Y[k, i] = rk * Y[k, i] + u[i]
            if with_S:
                S = Sall[m + N]
                for i in range(n):
                    if rows[k, i]:
                        for j in range(P):
                            if cols[j]:
                                Z[k, i, j] = rk * Z[k, i, j] + S[i, j]


def run(steps: int, N: int, h: float, t: np.ndarray, U: np.ndarray, X: np.ndarray, phi: np.ndarray,
        window: np.ndarray, Sall: np.ndarray, fresh: bool, delta: np.ndarray, rhs: list | None,
        memory: Any, kind: str, friction: tuple | None, box: tuple | None, jumps: bool,
        fpar: np.ndarray | None = None, rel: float = 0.0, hist: list | None = None
        ) -> tuple[np.ndarray, list, int]:
    """The loop over the steps: fills Sall[N + 1:] and returns dX, the switches (p, i, kind) and
    the step whose f call failed (-1: none; the caller then takes the Python loop, which raises
    the callback's own error).

    ``window``: U^{-N}, ..., U^0; ``fresh``: whether the history's S in Sall[:N + 1] is nonzero
    anywhere; ``rhs``: [(address, user)] of f at p and at p + delta_j e_j, or
    None without f; ``memory``: the _Memory of sensitivity.py; ``friction``: (alpha, dalpha);
    ``box``: (lo, hi, dlo, dhi); ``fpar``: None (f_u S_j + f_p_j by one directional difference
    per parameter) or the parameters f depends on (f_u by n columns of relative step ``rel``, f_p
    by one call for each of these); ``hist``: the parameters whose columns of the history's S
    may be nonzero (None: all)."""
    n, P = U.shape[1], len(delta)
    f64, cplx = np.float64, np.complex128
    c = np.ascontiguousarray
    t, U, X, phi, window = c(t, f64), c(U, f64), c(X, f64), c(phi, f64), c(window, f64)
    if rhs is None:
        addrs, users = np.zeros(1, np.int64), np.zeros(1, np.int64)
    else:
        addrs = np.array([a for a, _ in rhs], np.int64)
        users = np.array([u for _, u in rhs], np.int64)
    none2, none3 = np.zeros((0, 0), f64), np.zeros((0, 0, 0), f64)
    flat, dWU, last = none2, none3, np.zeros((n, n))
    near, dWn = np.zeros((0, n, n)), none3
    code = MEMORY_NONE
    dtype = f64
    if memory.recursive:
        code = MEMORY_RECURSIVE
        # real arithmetic where the exponents and their derivatives are real (a Prony series)
        real = not (np.any(memory.lam.imag) or np.any(memory.dl.imag))
        dtype = f64 if real else cplx

        def cast(a: np.ndarray) -> np.ndarray:
            return c(a.real if real else a, dtype)
        E, r, rN, rlast = cast(memory.E), cast(memory.r), cast(memory.rN), cast(memory.rlast)
        E0, cw, c1 = cast(memory.E0), cast(memory.c), cast(memory.c1)
        wlast, wslast = cast(memory.wlast), cast(memory.wslast)
        dE, dl = cast(memory.dE.transpose(1, 2, 3, 0)), cast(memory.dl.T)
        last = c(memory.last, f64)
        if len(memory.near):
            near, dWn = c(memory.near, f64), c(memory.near_kernel_part(), f64)
    else:
        E, r, rN, rlast = (np.zeros((0, n, n), dtype), np.zeros(0, dtype), np.zeros(0, dtype),
                           np.zeros(0, dtype))
        E0, cw, c1, wlast, wslast = (np.zeros((0, n, n), dtype), np.zeros(0, dtype),
                                     np.zeros(0, dtype), np.zeros(0, dtype), np.zeros(0, dtype))
        dE, dl = np.zeros((0, n, n, P), dtype), np.zeros((0, P), dtype)
        if memory.active:
            code = MEMORY_DIRECT
            dWU = memory.kernel_part()
            flat = memory.flat()
    kcode = RESOLVENT_NONE
    alpha, dalpha = np.zeros(0), none2
    lo, hi, dlo, dhi = np.zeros(0), np.zeros(0), none2, none2
    if kind == "friction":
        kcode = RESOLVENT_FRICTION
        alpha, dalpha = (c(a, f64) for a in friction)
    elif kind == "box":
        kcode = RESOLVENT_BOX
        lo, hi, dlo, dhi = (c(a, f64) for a in box)
    dX = np.empty((steps, n, P))
    cap = steps * n if kind == "friction" else 0
    sw_q, sw_i, sw_kind = np.empty(cap, np.int64), np.empty(cap, np.int64), np.empty(cap, np.int64)
    fcols = fpar is not None
    fpar = np.zeros(0, np.int64) if fpar is None else np.asarray(fpar, np.int64)
    zcols = np.ones(P, np.bool_)
    if hist is not None:
        zcols[:] = False
        zcols[list(hist)] = True
    count, failed = loop(steps, N, float(h), t, U, X, phi, window, Sall, dX, delta, rhs is not None,
                         addrs, users, fcols, fpar, float(rel), code, fresh, zcols,
                         E, r, rN, rlast, last, flat, dWU, E0, cw, c1, wlast, wslast, dE, dl,
                         near, dWn, kcode, alpha, dalpha, bool(jumps), lo, hi, dlo, dhi, sw_q, sw_i, sw_kind)
    names = {STICK: "stick", REVERSAL: "reversal", UNPLACED: "unplaced"}
    switches = [(q, i, names[k]) for q, i, k in zip(sw_q[:count].tolist(), sw_i[:count].tolist(),
                                                    sw_kind[:count].tolist())]
    return dX, switches, int(failed)
