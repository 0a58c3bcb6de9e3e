# libdmi through ctypes: the library and libdmipy.so (Solver.run's loop) are
# loaded from this package's folder, and the C prototypes of include/dmi.h are
# declared here once.  ctypes.CDLL releases the GIL around every call into C;
# a callback written in Python takes it back while it runs.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""ctypes declarations of libdmi (include/dmi.h); private to the package."""
from __future__ import annotations

import ctypes
from ctypes import POINTER, c_char_p, c_double, c_int, c_size_t, c_uint64, c_void_p
from pathlib import Path

HERE = Path(__file__).resolve().parent
SONAME = "libdmi.so.1"

OK, EINVAL, ENOMEM, ECALLBACK, ENONFINITE, ESTATE = 0, -1, -2, -3, -4, -5
CONV = {"auto": 0, "direct": 1, "fft": 2, "recursive": 3}
#: dmi_set_quadrature's rules DMI_QUAD_*.
QUAD = {"left": 0, "cell": 1}

# The callback types of dmi.h (pointers as c_void_p: a Python callback gets addresses).
RhsFn = ctypes.CFUNCTYPE(c_int, c_double, c_void_p, c_void_p, c_void_p)
ResolventFn = ctypes.CFUNCTYPE(c_int, c_double, c_void_p, c_void_p, c_void_p)
KernelFn = ctypes.CFUNCTYPE(c_int, c_double, c_void_p, c_void_p)
HistoryFn = ctypes.CFUNCTYPE(c_int, c_double, c_void_p, c_void_p)


def _load(name: str) -> ctypes.CDLL:
    path = HERE / name
    if not path.exists():
        raise ImportError(f"dmi: {path} is missing: the package dmi is imported from its sources, "
                          "not from an installation (pip install <the dmi checkout>, or "
                          "PYTHONPATH=<build>/python after a CMake build)")
    return ctypes.CDLL(str(path))


lib = _load(SONAME)  # first, so that libdmipy.so finds it already loaded
pylib = _load("libdmipy.so")

_solver_p = c_void_p
_d = POINTER(c_double)
_PROTOTYPES = {
    "dmi_version": (c_char_p, []),
    "dmi_create": (c_int, [POINTER(c_void_p), c_size_t, c_double, c_size_t]),
    "dmi_create_h": (c_int, [POINTER(c_void_p), c_size_t, c_double, c_double]),
    "dmi_free": (None, [POINTER(c_void_p)]),
    "dmi_set_rhs": (c_int, [_solver_p, c_void_p, c_void_p]),
    "dmi_set_resolvent": (c_int, [_solver_p, c_void_p, c_void_p]),
    "dmi_set_friction": (c_int, [_solver_p, _d]),
    "dmi_set_box": (c_int, [_solver_p, _d, _d]),
    "dmi_set_kernel": (c_int, [_solver_p, c_void_p, c_void_p]),
    "dmi_set_kernel_exp": (c_int, [_solver_p, c_size_t, _d, _d, _d, _d]),
    "dmi_set_history": (c_int, [_solver_p, c_void_p, c_void_p]),
    "dmi_set_convolution": (c_int, [_solver_p, c_int]),
    "dmi_set_quadrature": (c_int, [_solver_p, c_int]),
    "dmi_set_kernel_near": (c_int, [_solver_p, c_void_p, c_void_p, c_double]),
    "dmi_set_kernel_singularity": (c_int, [_solver_p, c_double]),
    "dmi_init": (c_int, [_solver_p]),
    "dmi_step": (c_int, [_solver_p]),
    "dmi_advance": (c_int, [_solver_p, c_size_t]),
    "dmi_time": (c_double, [_solver_p]),
    "dmi_get_step_index": (c_int, [_solver_p, POINTER(c_uint64)]),
    "dmi_get_h": (c_double, [_solver_p]),
    "dmi_get_N": (c_size_t, [_solver_p]),
    "dmi_get_state": (c_int, [_solver_p, _d]),
    "dmi_get_past": (c_int, [_solver_p, c_size_t, _d]),
    "dmi_get_step_terms": (c_int, [_solver_p, _d, _d]),
    "dmi_get_kernel_weights": (c_int, [_solver_p, c_size_t, c_size_t, _d, _d]),
    "dmi_get_window": (c_int, [_solver_p, _d]),
    "dmi_set_window": (c_int, [_solver_p, _d]),
    "dmi_state_size": (c_size_t, [_solver_p]),
    "dmi_state_save": (c_int, [_solver_p, c_void_p, c_size_t]),
    "dmi_state_load": (c_int, [_solver_p, c_void_p, c_size_t]),
    "dmi_tangent_create": (c_int, [POINTER(c_void_p), _solver_p, c_size_t, POINTER(c_void_p), _d]),
    "dmi_tangent_set_history": (c_int, [c_void_p, _d]),
    "dmi_tangent_sample_history": (c_int, [c_void_p, POINTER(c_int)]),
    "dmi_tangent_set_kernel_terms": (c_int, [c_void_p, _d, _d, _d, _d]),
    "dmi_tangent_set_rhs_parameters": (c_int, [c_void_p, POINTER(c_int)]),
    "dmi_tangent_run": (c_int, [c_void_p, c_size_t, c_int, _d, _d, _d, _d, _d, c_void_p]),
    "dmi_tangent_free": (None, [POINTER(c_void_p)]),
    "dmi_last_error": (c_char_p, [_solver_p]),
    "dmi_strerror": (c_char_p, [c_int]),
}
for _name, (_res, _args) in _PROTOTYPES.items():
    _f = getattr(lib, _name)
    _f.restype, _f.argtypes = _res, _args

pylib.dmi_py_run.restype = c_int
pylib.dmi_py_run.argtypes = [_solver_p, c_size_t, c_size_t, c_size_t, _d, _d, _d,
                             POINTER(c_size_t)]
# out = M x (libdmi's rhs and resolvent signature), the tangent map of dmi.analysis
pylib.dmi_py_linear.restype = c_int
pylib.dmi_py_linear.argtypes = [c_double, c_void_p, c_void_p, c_void_p]
