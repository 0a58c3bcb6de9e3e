# What the Python benchmarks of bench/ share: CPU time of a call, and the argparse types of their
# command lines.  (A package, not a bench/*.py file: those are the programs.)
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from typing import Any


def cpu(f: Callable[[], Any]) -> float:
    """The CPU time of the process (seconds) that f() takes."""
    t = time.process_time()
    f()
    return time.process_time() - t


def positive_int(text: str) -> int:
    """An argparse type: a whole number >= 1, also written 1e5."""
    try:
        value = int(float(text)) if "e" in text.lower() else int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not >= 1")
    return value


def nonempty(text: str) -> str:
    """An argparse type: a string that is not empty."""
    if not text:
        raise argparse.ArgumentTypeError("'' is empty")
    return text


def dir_holding(inside: str) -> Callable[[str], str]:
    """An argparse type: a directory holding the file ``inside`` (a path relative to it)."""
    def check(text: str) -> str:
        if not text or not os.path.isfile(os.path.join(text, inside)):
            raise argparse.ArgumentTypeError(f"{text!r} is not a directory holding {inside}")
        return text
    return check
