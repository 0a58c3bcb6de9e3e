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

#: ``DMI_OK`` (0), success.
OK: int = _lib.OK
#: ``DMI_EINVAL`` (-1), an invalid argument (NULL, out of range, NaN); :class:`InvalidArgument`.
EINVAL: int = _lib.EINVAL
#: ``DMI_ENOMEM`` (-2), memory could not be allocated (or its size overflows); :class:`Error`.
ENOMEM: int = _lib.ENOMEM
#: ``DMI_ECALLBACK`` (-3), a callback failed; a C callback returned nonzero (:class:`Error`), or a
#: Python callback returned a result of another shape or type (:class:`InvalidArgument`).
ECALLBACK: int = _lib.ECALLBACK
#: ``DMI_ENONFINITE`` (-4), a NaN or infinity appeared (a callback's output or the new state);
#: :class:`Error`.
ENONFINITE: int = _lib.ENONFINITE
#: ``DMI_ESTATE`` (-5), a call not allowed in the solver's state (a step before ``init``, a
#: kernel or history set after it, a closed solver or one in use); :class:`InvalidArgument`.
ESTATE: int = _lib.ESTATE

#: numba signature of the right-hand side f(t, u), for ``@numba.cfunc(dmi.RHS_SIGNATURE)``.
RHS_SIGNATURE: str = _cb.RHS.numba
#: numba signature of the resolvent r(lam, x) (``Solver.set_resolvent``).
RESOLVENT_SIGNATURE: str = _cb.RESOLVENT.numba
#: numba signature of the kernel H(s) (``Solver.set_kernel``, ``Solver.set_kernel_near``).
KERNEL_SIGNATURE: str = _cb.KERNEL.numba
#: numba signature of the history z(t) (``Solver.set_history``).
HISTORY_SIGNATURE: str = _cb.HISTORY.numba
#: C type of the right-hand side, as ``scipy.LowLevelCallable(..., signature=...)`` takes it.
RHS_C_SIGNATURE: str = _cb.RHS.c
#: C type of the resolvent, as ``scipy.LowLevelCallable(..., signature=...)`` takes it.
RESOLVENT_C_SIGNATURE: str = _cb.RESOLVENT.c
#: C type of the kernel, as ``scipy.LowLevelCallable(..., signature=...)`` takes it.
KERNEL_C_SIGNATURE: str = _cb.KERNEL.c
#: C type of the history, as ``scipy.LowLevelCallable(..., signature=...)`` takes it.
HISTORY_C_SIGNATURE: str = _cb.HISTORY.c
#: ctypes prototypes of the callbacks (pointers as c_void_p): ``dmi.RhsFn(address)``.
RhsFn = _lib.RhsFn
ResolventFn = _lib.ResolventFn
KernelFn = _lib.KernelFn
HistoryFn = _lib.HistoryFn


def version() -> str:
    """The version of the libdmi in this package (``dmi_version``).

    Returns
    -------
    str
        ``"MAJOR.MINOR.PATCH"``.
    """
    return _lib.lib.dmi_version().decode()


__version__: str = version()

__all__ = ["Solver", "Error", "InvalidArgument", "version", "OK", "EINVAL", "ENOMEM", "ECALLBACK",
           "ENONFINITE", "ESTATE", "RHS_SIGNATURE", "RESOLVENT_SIGNATURE", "KERNEL_SIGNATURE",
           "HISTORY_SIGNATURE", "RHS_C_SIGNATURE", "RESOLVENT_C_SIGNATURE", "KERNEL_C_SIGNATURE",
           "HISTORY_C_SIGNATURE", "RhsFn", "ResolventFn", "KernelFn", "HistoryFn"]
