# dmi.identify._compiled: the per-step loop of the sensitivities, compiled by numba (nopython).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The tangent loop of :func:`dmi.identify.sensitivities` compiled by numba, for models whose f is a
C function (a ``jit=True`` callback, a numba cfunc, a ctypes function): f is called through its
address, with no Python in between.  It does step by step what the Python loop of sensitivity.py
does, on the same precomputed arrays (the memory's weights and the kernel terms' derivatives, the
resolvent's derivatives along the run), so the two agree to rounding; the exponential kernel's part
dG_l U^{p-l}, which the Python loop takes from FFT convolutions, runs here by its recursions.  This module imports numba (sensitivity.py imports
it only where numba is installed); the loop is compiled on first call and cached on disk."""
from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
from llvmlite import ir
from numba import types as nt
from numba.extending import intrinsic

from ._saltation import REVERSAL, STICK
from ._saltation import reversal as _reversal_python

# codes of the memory and of the resolvent (arguments of the loop)
MEMORY_NONE, MEMORY_RECURSIVE, MEMORY_DIRECT = 0, 1, 2
RESOLVENT_NONE, RESOLVENT_FRICTION, RESOLVENT_BOX = 0, 1, 2
#: the test of a friction component at a step, the Python loop's function compiled
reversal = numba.njit(cache=True)(_reversal_python)


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


@numba.njit(cache=True)
def loop(steps, N, h, t, U, X, phi, Sall, dX, delta, has_f, addrs, users,
         memory, E, r, rN, powers, last, flat, dWU,
         Uext, E0, cw, c1, wlast, wslast, dE, dl,
         kind, slipping, dR, meets, alpha, dalpha, jumps, lo, hi, dlo, dhi,
         sw_q, sw_i, sw_kind):
    n = U.shape[1]
    P = delta.shape[0]
    K = r.shape[0]
    Fd = np.zeros((n, P))
    T = np.empty((n, P))
    f0 = np.empty(n)
    fj = np.empty(n)
    moved = np.empty(n)
    Z = np.zeros((K, n, P), dtype=np.complex128)
    # the kernel's part by recursion: Y_k = sum_l r_k^l U^{q-l}, Y1_k = sum_l l r_k^l U^{q-l}
    Y = np.zeros((K, n), dtype=np.complex128)
    Y1 = np.zeros((K, n), dtype=np.complex128)
    A = np.zeros((K, n), dtype=np.complex128)
    EB = np.zeros((K, n), dtype=np.complex128)
    B = np.zeros(n, dtype=np.complex128)
    since = 4 * N                       # Z is computed at the first step
    count = 0
    Sflat = Sall.reshape(Sall.shape[0] * n, P)
    for q in range(steps):
        Sq = Sall[q + N]
        # f_u S_j + f_p_j: one call of f at p and one of f at p + delta_j e_j per parameter
        if has_f:
            if call_rhs(addrs[0], t[q], U[q], f0, users[0]) != 0:
                return count, q
            for j in range(P):
                for i in range(n):
                    moved[i] = U[q, i] + delta[j] * Sq[i, j]
                if call_rhs(addrs[j + 1], t[q], moved, fj, users[j + 1]) != 0:
                    return count, q
                for i in range(n):
                    Fd[i, j] = (fj[i] - f0[i]) / delta[j]
        for i in range(n):
            for j in range(P):
                T[i, j] = Sq[i, j] - h * Fd[i, j]
        # the delay sum sum_l G_l S^{q-l} and the kernel's part dWU
        if memory == MEMORY_RECURSIVE:
            if since >= 4 * N:          # Z_k = sum_l r_k^l S^{q-l}, Y_k and Y1_k afresh
                for k in range(K):
                    for i in range(n):
                        for j in range(P):
                            acc = 0j
                            for l in range(N):
                                acc += powers[k, l] * Sall[q + N - l, i, j]
                            Z[k, i, j] = acc
                        acc = 0j
                        acc1 = 0j
                        for l in range(N):
                            v = powers[k, l] * Uext[q + N - 1 - l, i]
                            acc += v
                            acc1 += l * v
                        Y[k, i] = acc
                        Y1[k, i] = acc1
                since = 0
            # sum_l w_kl U^{q-l} (A_k) and E_k sum_l ws_kl U^{q-l} (EB_k): the full cells from
            # Y and Y1, the last one (U^{q-N+1}, weights w_k,N-1, ws_k,N-1) mended
            for k in range(K):
                rl = powers[k, N - 1]
                fa = wlast[k] - cw[k] * rl
                fb = wslast[k] - rl * ((N - 1) * h * cw[k] + c1[k])
                for i in range(n):
                    A[k, i] = cw[k] * Y[k, i] + fa * Uext[q, i]
                    B[i] = h * cw[k] * Y1[k, i] + c1[k] * Y[k, i] + fb * Uext[q, i]
                for i in range(n):
                    acc = 0j
                    for m in range(n):
                        acc += E0[k, i, m] * B[m]
                    EB[k, i] = acc
            for i in range(n):
                for j in range(P):
                    acc = 0.0
                    for k in range(K):
                        for m in range(n):
                            e, z = E[k, i, m], Z[k, m, j]     # the real part only
                            acc += e.real * z.real - e.imag * z.imag
                    for m in range(n):
                        acc += last[i, m] * Sall[q + 1, m, j]
                    # the kernel's part: sum_k dE_jk A_k + dl_jk EB_k
                    part = 0.0
                    for k in range(K):
                        d, v = dl[j, k], EB[k, i]
                        part += d.real * v.real - d.imag * v.imag
                        for m in range(n):
                            d, v = dE[j, k, i, m], A[k, m]
                            part += d.real * v.real - d.imag * v.imag
                    T[i, j] -= h * (acc + part)
        elif memory == MEMORY_DIRECT:
            rows = Sflat[(q + 1) * n:(q + N + 1) * n]
            W = flat @ rows
            for i in range(n):
                for j in range(P):
                    T[i, j] -= h * (W[i, j] + dWU[q, i, j])
        dX[q] = T
        Snew = Sall[q + 1 + N]
        if kind == RESOLVENT_FRICTION:
            for i in range(n):
                for j in range(P):
                    Snew[i, j] = T[i, j] * slipping[q, i] + dR[q, i, j]
            if jumps and meets[q]:
                # the reversals of the step: S_i multiplied by the saltation factor F+ / F-
                for i in range(n):
                    what, rho = reversal(q, i, U, phi, alpha)
                    if what == STICK:
                        sw_q[count], sw_i[count], sw_kind[count] = q, i, STICK
                        count += 1
                    elif what == REVERSAL:
                        sm = math.copysign(1.0, U[q, i])
                        for j in range(P):
                            Snew[i, j] = rho * (T[i, j] - h * sm * dalpha[i, j])
                        sw_q[count], sw_i[count], sw_kind[count] = q, i, REVERSAL
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
        if memory == MEMORY_RECURSIVE:      # Z from step q to q + 1
            for k in range(K):
                for i in range(n):
                    for j in range(P):
                        Z[k, i, j] = r[k] * Z[k, i, j] + (Sall[q + 1 + N, i, j]
                                                          - rN[k] * Sall[q + 1, i, j])
                    # U^{q+1} = Uext[q + N], U^{q+1-N} = Uext[q]
                    Y1[k, i] = r[k] * (Y1[k, i] + Y[k, i]) - N * rN[k] * Uext[q, i]
                    Y[k, i] = r[k] * Y[k, i] + Uext[q + N, i] - rN[k] * Uext[q, i]
            since += 1
    return count, -1


def run(steps: int, N: int, h: float, t: np.ndarray, U: np.ndarray, X: np.ndarray, phi: np.ndarray,
        Sall: np.ndarray, delta: np.ndarray, rhs: list | None, memory: Any, kind: str,
        friction: tuple | None, box: tuple | None, jumps: bool
        ) -> tuple[np.ndarray, list, int]:
    """The loop over the steps: fills Sall[N + 1:] and returns dX, the switches (p, i, kind) and
    the step whose f call failed (-1: none; the caller then takes the Python loop, which raises
    the callback's own error).

    ``rhs``: [(address, user)] of f at p and at p + delta_j e_j, or None without f; ``memory``:
    the _Memory of sensitivity.py; ``friction``: (slipping, dR, meets, alpha, dalpha);
    ``box``: (lo, hi, dlo, dhi)."""
    n, P = U.shape[1], len(delta)
    f64 = np.float64
    c = np.ascontiguousarray
    t, U, X, phi = c(t, f64), c(U, f64), c(X, f64), c(phi, f64)
    if rhs is None:
        addrs, users = np.zeros(1, np.int64), np.zeros(1, np.int64)
    else:
        addrs = np.array([a for a, _ in rhs], np.int64)
        users = np.array([u for _, u in rhs], np.int64)
    none2, none3 = np.zeros((0, 0), f64), np.zeros((0, 0, 0), f64)
    E, r, rN = np.zeros((0, n, n), complex), np.zeros(0, complex), np.zeros(0, complex)
    powers, last, flat, dWU = np.zeros((0, 0), complex), none2, none2, none3
    cplx = np.complex128
    Uext, E0, cw, c1 = none2, np.zeros((0, n, n), cplx), np.zeros(0, cplx), np.zeros(0, cplx)
    wlast, wslast = np.zeros(0, cplx), np.zeros(0, cplx)
    dE, dl = np.zeros((0, 0, n, n), cplx), np.zeros((0, 0), cplx)
    code = MEMORY_NONE
    if memory.G is not None:
        if memory.recursive:
            code = MEMORY_RECURSIVE
            E = c(memory.E, cplx)
            r, rN = memory.r[:, 0, 0].copy(), memory.rN[:, 0, 0].copy()
            powers, last = c(memory.powers, cplx), c(memory.last, f64)
            Uext, E0 = c(memory.Uext, f64), c(memory.E0, cplx)
            cw, c1 = c(memory.c, cplx), c(memory.c1, cplx)
            wlast, wslast = c(memory.w[:, -1], cplx), c(memory.ws[:, -1], cplx)
            dE, dl = c(memory.dE, cplx), c(memory.dl, cplx)
        else:
            code = MEMORY_DIRECT
            dWU = memory.kernel_part()
            flat = memory.flat()
    kcode = RESOLVENT_NONE
    slipping, dR, meets = none2, none3, np.zeros(0, np.bool_)
    alpha, dalpha = np.zeros(0), none2
    lo, hi, dlo, dhi = np.zeros(0), np.zeros(0), none2, none2
    if kind == "friction":
        kcode = RESOLVENT_FRICTION
        slipping, dR, meets, alpha, dalpha = (c(a) for a in friction)
    elif kind == "box":
        kcode = RESOLVENT_BOX
        lo, hi, dlo, dhi = (c(a, f64) for a in box)
    dX = np.empty((steps, n, P))
    cap = steps * n if kind == "friction" else 0
    sw_q, sw_i, sw_kind = np.empty(cap, np.int64), np.empty(cap, np.int64), np.empty(cap, np.int64)
    count, failed = loop(steps, N, float(h), t, U, X, phi, Sall, dX, delta, rhs is not None,
                         addrs, users, code, E, r, rN, powers, last, flat, dWU,
                         Uext, E0, cw, c1, wlast, wslast, dE, dl,
                         kcode, slipping, dR, meets, alpha, dalpha, bool(jumps),
                         lo, hi, dlo, dhi, sw_q, sw_i, sw_kind)
    names = {STICK: "stick", REVERSAL: "reversal"}
    switches = [(q, i, names[k]) for q, i, k in zip(sw_q[:count].tolist(), sw_i[:count].tolist(),
                                                    sw_kind[:count].tolist())]
    return dX, switches, int(failed)
