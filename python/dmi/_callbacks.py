# A user's callback -> what libdmi is given: a C function's address (numba
# cfunc, ctypes function pointer, scipy.LowLevelCallable), checked against the
# C signature of include/dmi.h, or a ctypes trampoline around a Python function
# that converts arrays, checks the result's shape and keeps any exception for
# the solver to raise once the C call has returned.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Callbacks of the four kinds of include/dmi.h; private to the package."""
from __future__ import annotations

import ctypes
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from . import _lib
from ._errors import InvalidArgument

# The C signature of each kind (include/dmi.h) as scipy.LowLevelCallable writes it, its ctypes
# prototype, its argument kinds ("d" double, "p" pointer) and the numba signature string.
@dataclass(frozen=True)
class Kind:
    name: str
    c: str
    proto: Any
    args: str
    numba: str


RHS = Kind("rhs", "int (double, double *, double *, void *)", _lib.RhsFn, "dppp",
           "intc(float64, CPointer(float64), CPointer(float64), voidptr)")
RESOLVENT = Kind("resolvent", "int (double, double *, double *, void *)", _lib.ResolventFn, "dppp",
                 "intc(float64, CPointer(float64), CPointer(float64), voidptr)")
KERNEL = Kind("kernel", "int (double, double *, void *)", _lib.KernelFn, "dpp",
              "intc(float64, CPointer(float64), voidptr)")
HISTORY = Kind("history", "int (double, double *, void *)", _lib.HistoryFn, "dpp",
               "intc(float64, CPointer(float64), voidptr)")


@dataclass
class Bound:
    """What a setter hands to libdmi: the function's address and the user pointer (None: NULL),
    the objects that must stay alive as long as the solver uses them, and whether the address is
    a Python function's trampoline (``python``) or a jit=True callback's compiled code (``jit``,
    True on _jit.JitBound)."""
    address: int | None
    user: int | None
    keep: tuple
    python: bool = False
    jit: ClassVar[bool] = False


def _arg_kind(t: Any) -> str:
    if t is ctypes.c_double:
        return "d"
    if t is ctypes.c_void_p or (isinstance(t, type) and issubclass(t, ctypes._Pointer)):
        return "p"
    return "?"


def _c_kinds(signature: str) -> str:
    """The argument kinds of a C signature "int (double, double *, ...)" ("?" if not int-valued)."""
    m = re.fullmatch(r"\s*int\s*\((.*)\)\s*", signature)
    if not m:
        return "?"
    args = [a.strip() for a in m.group(1).split(",")]
    return "".join("p" if a.endswith("*") else "d" if a == "double" else "?" for a in args)


def _check_ctypes(kind: Kind, fn: Any, what: str) -> None:
    argtypes, restype = getattr(fn, "argtypes", None), getattr(fn, "restype", ctypes.c_int)
    if argtypes is None:  # a foreign function declared without a prototype: taken as it is
        return
    ok = "".join(_arg_kind(t) for t in argtypes) == kind.args and restype in (
        ctypes.c_int, ctypes.c_int32)
    if not ok:
        raise InvalidArgument(_lib.EINVAL, f"set_{kind.name}: {what} does not have libdmi's "
                              f"signature {kind.c} (numba: cfunc({kind.numba!r}))")


def _capsule_pointer(capsule: Any) -> int:
    api = ctypes.pythonapi
    api.PyCapsule_GetName.restype, api.PyCapsule_GetName.argtypes = ctypes.c_char_p, [ctypes.py_object]
    api.PyCapsule_GetPointer.restype = ctypes.c_void_p
    api.PyCapsule_GetPointer.argtypes = [ctypes.py_object, ctypes.c_char_p]
    return api.PyCapsule_GetPointer(capsule, api.PyCapsule_GetName(capsule))


def _pointer_value(p: Any) -> int | None:
    """A user pointer: None, an int address, a NumPy array or ctypes object (its data's address),
    a ctypes pointer, a capsule."""
    if p is None:
        return None
    if isinstance(p, int):
        return p
    if isinstance(p, np.ndarray):
        if not p.flags.c_contiguous:
            raise InvalidArgument(_lib.EINVAL, "user: a NumPy array must be C-contiguous")
        return p.ctypes.data
    if isinstance(p, ctypes.c_void_p):
        return p.value
    if isinstance(p, ctypes._Pointer):
        return ctypes.cast(p, ctypes.c_void_p).value
    if isinstance(p, ctypes._SimpleCData | ctypes.Structure | ctypes.Array | ctypes.Union):
        return ctypes.addressof(p)
    if type(p).__name__ == "PyCapsule":
        return _capsule_pointer(p)
    raise InvalidArgument(_lib.EINVAL, f"user = {p!r}: expected None, an address (int), a NumPy "
                          "array, a ctypes object or pointer, or a capsule")


def _c_function(kind: Kind, f: Any, user: Any) -> Bound | None:
    """The address of a C-callable f, checked against kind's signature; None if f is not one."""
    if type(f).__name__ == "LowLevelCallable" and hasattr(f, "signature"):  # scipy
        if _c_kinds(f.signature) != kind.args:
            raise InvalidArgument(_lib.EINVAL, f"set_{kind.name}: the LowLevelCallable has the "
                                  f"signature {f.signature!r}, libdmi calls {kind.c!r}")
        fn = f.function
        address = (ctypes.cast(fn, ctypes.c_void_p).value if isinstance(fn, ctypes._CFuncPtr)
                   else _capsule_pointer(fn))
        user_ptr = _pointer_value(user if user is not None else f.user_data)
        return Bound(address, user_ptr, (f, user))
    if isinstance(getattr(f, "ctypes", None), ctypes._CFuncPtr) and hasattr(f, "address"):  # numba
        _check_ctypes(kind, f.ctypes, "the numba cfunc")
        return Bound(int(f.address), _pointer_value(user), (f, user))
    if isinstance(f, ctypes._CFuncPtr):
        _check_ctypes(kind, f, "the ctypes function")
        return Bound(ctypes.cast(f, ctypes.c_void_p).value, _pointer_value(user), (f, user))
    return None


_ARRAY_TYPES: dict[int, Any] = {}


def _view(address: int, size: int) -> np.ndarray:
    """The size doubles at address as a NumPy array (no copy)."""
    t = _ARRAY_TYPES.get(size)
    if t is None:
        t = _ARRAY_TYPES[size] = ctypes.c_double * size
    return np.frombuffer(t.from_address(address), dtype=np.float64)


def _store(kind: Kind, value: Any, address: int, shape: tuple[int, ...]) -> None:
    """Writes a Python callback's result to libdmi's output array, checking its shape."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InvalidArgument(_lib.ECALLBACK, f"the {kind.name} callback returned {type(value).__name__}"
                              f", not an array of floats of shape {shape}: {e}") from None
    if a.shape != shape:
        raise InvalidArgument(_lib.ECALLBACK, f"the {kind.name} callback returned an array of shape "
                              f"{a.shape}; libdmi needs shape {shape}")
    _view(address, a.size)[:] = a.reshape(-1)


def _python_function(kind: Kind, f: Callable, n: int, failure: list) -> Bound:
    """A ctypes trampoline calling f with NumPy arrays; an exception is kept in failure[0] and
    makes the callback return 1, so libdmi fails with DMI_ECALLBACK and rolls the step back."""
    vec, mat = (n,), (n, n)

    if kind.args == "dppp":  # rhs f(t, u), resolvent r(lam, x): the input is copied
        def trampoline(x: float, u: int, out: int, _user: int) -> int:
            try:
                _store(kind, f(x, _view(u, n).copy()), out, vec)
                return 0
            except BaseException as e:  # also KeyboardInterrupt: raised again by the solver
                failure[0] = e
                return 1
    else:  # kernel H(s) -> (n, n), history z(t) -> (n,)
        shape = mat if kind is KERNEL else vec

        def trampoline(x: float, out: int, _user: int) -> int:
            try:
                _store(kind, f(x), out, shape)
                return 0
            except BaseException as e:
                failure[0] = e
                return 1

    c = kind.proto(trampoline)
    return Bound(ctypes.cast(c, ctypes.c_void_p).value, None, (c, f), python=True)


def bind(kind: Kind, f: Any, user: Any, n: int, failure: list) -> Bound:
    """What set_<kind>(f, user) hands to libdmi; None gives NULL (the library's default)."""
    if f is None:
        if user is not None:
            raise InvalidArgument(_lib.EINVAL, f"set_{kind.name}: a user pointer without a function")
        return Bound(None, None, ())
    c = _c_function(kind, f, user)
    if c is not None:
        return c
    if not callable(f):
        raise InvalidArgument(_lib.EINVAL, f"set_{kind.name}: {f!r} is neither callable nor a C "
                              "function (numba cfunc, ctypes function pointer, LowLevelCallable)")
    if user is not None:
        raise InvalidArgument(_lib.EINVAL, f"set_{kind.name}: a user pointer is for C functions; a "
                              "Python function keeps its data in a closure")
    return _python_function(kind, f, n, failure)
