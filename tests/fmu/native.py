# A native libdmi run of the oscillator (4.1), through ctypes on libdmi.so, with
# the FMU's parameters: what the FMU's outputs are compared with.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import ctypes as C
import math

import numpy as np

# The FMU's start values (Example 4.3), written here from the contract.
START = dict(b=1.0, alpha=1.0, tau=1.0, w0=0.0, v0=0.0, H_c0=0.0, H_c1=0.0, H_lambda=0.0,
             H_a1=1.0, H_omega1=2 * math.pi, H_a2=1.0, H_omega2=10 * math.pi,
             H_a3=1.0, H_omega3=20 * math.pi, g_offset=0.0, g_amp=1.3, g_omega=8.0,
             g_phase=0.0, N=1000)

# Times closer than this fraction of h are the same time (as the FMU's contract says).
TOL = 1e-6

_RHS = C.CFUNCTYPE(C.c_int, C.c_double, C.POINTER(C.c_double), C.POINTER(C.c_double), C.c_void_p)
_KERNEL = C.CFUNCTYPE(C.c_int, C.c_double, C.POINTER(C.c_double), C.c_void_p)
_HISTORY = C.CFUNCTYPE(C.c_int, C.c_double, C.POINTER(C.c_double), C.c_void_p)


def _lib(path):
    lib = C.CDLL(path)
    lib.dmi_create.argtypes = [C.POINTER(C.c_void_p), C.c_size_t, C.c_double, C.c_size_t]
    for name in ("dmi_init", "dmi_step"):
        getattr(lib, name).argtypes = [C.c_void_p]
    lib.dmi_set_rhs.argtypes = [C.c_void_p, _RHS, C.c_void_p]
    lib.dmi_set_kernel.argtypes = [C.c_void_p, _KERNEL, C.c_void_p]
    lib.dmi_set_history.argtypes = [C.c_void_p, _HISTORY, C.c_void_p]
    lib.dmi_set_friction.argtypes = [C.c_void_p, C.POINTER(C.c_double)]
    lib.dmi_get_state.argtypes = [C.c_void_p, C.POINTER(C.c_double)]
    lib.dmi_get_step_terms.argtypes = [C.c_void_p, C.POINTER(C.c_double), C.POINTER(C.c_double)]
    lib.dmi_free.argtypes = [C.POINTER(C.c_void_p)]
    lib.dmi_free.restype = None
    return lib


class Run:
    """U^p for p = 0..M and the terms W^p, X^p of each step, with the given
    parameters; g_in(p) is the input used by step p (default 0)."""

    def __init__(self, libpath, M, g_in=None, t_start=0.0, **params):
        P = dict(START, **params)
        self.h = P["tau"] / P["N"]
        self.P, self.t_start = P, t_start
        lib = _lib(libpath)
        current = [0.0]  # g_in of the step being taken

        def H(s):
            return (P["H_c0"] + P["H_c1"] * math.exp(-P["H_lambda"] * s)
                    + P["H_a1"] * math.cos(P["H_omega1"] * s) + P["H_a2"] * math.cos(P["H_omega2"] * s)
                    + P["H_a3"] * math.cos(P["H_omega3"] * s))

        def rhs(t, u, out, _):
            tt = t_start + t
            g = P["g_offset"] + P["g_amp"] * math.cos(P["g_omega"] * tt + P["g_phase"]) + current[0]
            out[0] = -u[1]
            out[1] = P["b"] * u[0] + g
            return 0

        def kernel(s, out, _):
            out[2] = H(s)
            return 0

        def history(t, out, _):
            out[0], out[1] = P["w0"], P["v0"]
            return 0

        cb = (_RHS(rhs), _KERNEL(kernel), _HISTORY(history))
        s = C.c_void_p()
        assert lib.dmi_create(C.byref(s), 2, P["tau"], P["N"]) == 0
        alpha = (C.c_double * 2)(0.0, P["alpha"])
        assert lib.dmi_set_rhs(s, cb[0], None) == 0
        assert lib.dmi_set_kernel(s, cb[1], None) == 0
        assert lib.dmi_set_history(s, cb[2], None) == 0
        assert lib.dmi_set_friction(s, alpha) == 0
        assert lib.dmi_init(s) == 0
        U = np.empty((M + 1, 2))
        W = np.zeros((M + 1, 2))  # W[p], X[p]: terms of the step p-1 -> p
        X = np.zeros((M + 1, 2))
        u, w, x = (C.c_double * 2)(), (C.c_double * 2)(), (C.c_double * 2)()
        lib.dmi_get_state(s, u)
        U[0] = u[:]
        for p in range(M):
            current[0] = g_in(p) if g_in else 0.0
            assert lib.dmi_step(s) == 0
            lib.dmi_get_state(s, u)
            lib.dmi_get_step_terms(s, w, x)
            U[p + 1], W[p + 1], X[p + 1] = u[:], w[:], x[:]
        lib.dmi_free(C.byref(s))
        self.U, self.W, self.X = U, W, X

    def at(self, t):
        """w, v (the interpolant u_h), friction, delay_force, sticking at time t."""
        s = (t - self.t_start) / self.h
        q = round(s)
        if abs(s - q) > TOL:
            q = math.ceil(s)
        if q == 0:
            v0 = self.U[0, 1]
            return self.U[0, 0], v0, 0.0, 0.0, v0 == 0.0
        theta = s - (q - 1)
        if theta >= 1 - TOL:
            w, v = self.U[q]
        else:
            w, v = self.U[q - 1] + theta * (self.U[q] - self.U[q - 1])
        friction = (self.X[q, 1] - self.U[q, 1]) / self.h
        return w, v, friction, self.W[q, 1], self.U[q, 1] == 0.0

    def table(self, times):
        return np.array([self.at(t) for t in times], dtype=float)
