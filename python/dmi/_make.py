# Calling a user's model make(...) -> dmi.Solver: its own exception kept, with a note naming the call.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The model's construction for dmi.analysis (its step maps and its equilibria); private to the
package.  Imports nothing of dmi.analysis, so that the scheme's step map and the model's
linearisation both call models without importing each other."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ._solver import Solver


def call_make(make: Callable[..., Any], *args: Any, **kw: Any) -> Solver:
    """make(*args, **kw), checked to be a dmi.Solver; its exception (the model's own) gets a
    note naming the call, ``make(p = ...)``."""
    call = ", ".join([f"p = {a!r}" if i == 0 else repr(a) for i, a in enumerate(args)]
                     + [f"{k}={v!r}" for k, v in kw.items()])
    try:
        s = make(*args, **kw)
    except Exception as e:
        e.add_note(f"dmi.analysis: raised by the model make({call})")
        raise
    if not isinstance(s, Solver):
        raise TypeError(f"dmi.analysis: the model make({call}) returned {type(s).__name__}, "
                        "not a dmi.Solver")
    return s
