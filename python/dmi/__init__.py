# The Python binding of libdmi.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi: libdmi from Python.

The implicit Euler scheme for differential inclusions with a delay term of convolution type,

    u'(t) + A(u(t)) + f(t, u(t)) + int_0^tau H(s) u(t - s) ds ∋ 0,   u = z on [-tau, 0],

through :class:`Solver`, which mirrors include/dmi.h one function to one method.  Errors raise
:class:`Error` (``.code`` is the ``DMI_E*`` value); invalid arguments raise
:class:`InvalidArgument`, also a ``ValueError``.  The ``*_SIGNATURE`` strings are the numba
``cfunc`` signatures of the four callbacks, the ``*_C_SIGNATURE`` strings their C types as
``scipy.LowLevelCallable`` writes them; ``RhsFn`` etc. are the ctypes prototypes.
"""
from __future__ import annotations

from . import _callbacks as _cb
from . import _lib
from ._errors import Error, InvalidArgument
from ._solver import Solver

OK: int = _lib.OK
EINVAL: int = _lib.EINVAL
ENOMEM: int = _lib.ENOMEM
ECALLBACK: int = _lib.ECALLBACK
ENONFINITE: int = _lib.ENONFINITE
ESTATE: int = _lib.ESTATE

#: numba signatures: ``@numba.cfunc(dmi.RHS_SIGNATURE)`` etc.
RHS_SIGNATURE: str = _cb.RHS.numba
RESOLVENT_SIGNATURE: str = _cb.RESOLVENT.numba
KERNEL_SIGNATURE: str = _cb.KERNEL.numba
HISTORY_SIGNATURE: str = _cb.HISTORY.numba
#: C signatures, as scipy.LowLevelCallable(..., signature=...) takes them.
RHS_C_SIGNATURE: str = _cb.RHS.c
RESOLVENT_C_SIGNATURE: str = _cb.RESOLVENT.c
KERNEL_C_SIGNATURE: str = _cb.KERNEL.c
HISTORY_C_SIGNATURE: str = _cb.HISTORY.c
#: ctypes prototypes of the callbacks (pointers as c_void_p): ``dmi.RhsFn(address)``.
RhsFn = _lib.RhsFn
ResolventFn = _lib.ResolventFn
KernelFn = _lib.KernelFn
HistoryFn = _lib.HistoryFn


def version() -> str:
    """Version "MAJOR.MINOR.PATCH" of the libdmi in this package (``dmi_version``)."""
    return _lib.lib.dmi_version().decode()


__version__: str = version()

__all__ = ["Solver", "Error", "InvalidArgument", "version", "OK", "EINVAL", "ENOMEM", "ECALLBACK",
           "ENONFINITE", "ESTATE", "RHS_SIGNATURE", "RESOLVENT_SIGNATURE", "KERNEL_SIGNATURE",
           "HISTORY_SIGNATURE", "RHS_C_SIGNATURE", "RESOLVENT_C_SIGNATURE", "KERNEL_C_SIGNATURE",
           "HISTORY_C_SIGNATURE", "RhsFn", "ResolventFn", "KernelFn", "HistoryFn"]
