# The exceptions of the package.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.Error and dmi.InvalidArgument."""
from __future__ import annotations

from . import _lib


class Error(Exception):
    """A failure of libdmi or of the binding: ``code`` is the ``DMI_E*`` value of include/dmi.h
    (``dmi.EINVAL``, ``dmi.ENOMEM``, ``dmi.ECALLBACK``, ``dmi.ENONFINITE``, ``dmi.ESTATE``) and
    ``message`` the library's description (``dmi_last_error``).  The solver is as it was before
    the failing call (``advance`` and ``run`` keep the steps before the failing one)."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code
        self.message = message

    def __str__(self) -> str:
        return f"{self.message} [{_lib.lib.dmi_strerror(self.code).decode()}]"


class InvalidArgument(Error, ValueError):
    """An invalid argument or call (a wrong shape, NaN, a negative friction coefficient, n = 0,
    a setter of sampled data after init, a step before init, a callback's result of the wrong
    shape): both a :class:`dmi.Error` and a :class:`ValueError`.  ``code`` is ``dmi.EINVAL``,
    ``dmi.ESTATE`` (a call not allowed in the solver's state) or ``dmi.ECALLBACK`` (a Python
    callback returned something unusable).  The solver is unchanged."""


def from_code(code: int, message: str) -> Error:
    """The exception for a libdmi return code."""
    cls = InvalidArgument if code in (_lib.EINVAL, _lib.ESTATE) else Error
    return cls(code, message)
