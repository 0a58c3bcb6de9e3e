# The exceptions of the package.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.Error and dmi.InvalidArgument."""
from __future__ import annotations

from . import _lib


class Error(Exception):
    """A failure of libdmi or of the binding.  The solver is as it was before the failing call
    (``advance`` and ``run`` keep the steps before the failing one).  ``str()`` gives the message
    and the code's generic description (``dmi_strerror``).

    Parameters
    ----------
    code : int
        The ``DMI_E*`` value of include/dmi.h: ``dmi.EINVAL``, ``dmi.ENOMEM``,
        ``dmi.ECALLBACK``, ``dmi.ENONFINITE`` or ``dmi.ESTATE``.
    message : str
        What failed: the library's description (``dmi_last_error``) or the binding's.

    Both are kept as the attributes ``code`` and ``message``.
    """

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code
        self.message = message

    def __str__(self) -> str:
        return f"{self.message} [{_lib.lib.dmi_strerror(self.code).decode()}]"


class InvalidArgument(Error, ValueError):
    """An invalid argument or call (a wrong shape, NaN, a negative friction coefficient, n = 0,
    a setter of sampled data after init, a step before init, a callback's result of the wrong
    shape): both a :class:`dmi.Error` and a :class:`ValueError`.  The solver is unchanged.

    Parameters
    ----------
    code : int
        ``dmi.EINVAL``, ``dmi.ESTATE`` (a call not allowed in the solver's state) or
        ``dmi.ECALLBACK`` (a Python callback returned something unusable).
    message : str
        What was wrong.
    """


def from_code(code: int, message: str) -> Error:
    """The exception for a libdmi return code."""
    cls = InvalidArgument if code in (_lib.EINVAL, _lib.ESTATE) else Error
    return cls(code, message)
