# BLAS on one thread for the small dense and long Arnoldi problems of dmi.analysis.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""A context that keeps BLAS on one thread (imports nothing of the package, so that the
collocation's multipliers and the roots of equilibria share it without a deep import chain)."""
from __future__ import annotations

import contextlib
from typing import Any

_BLAS: list = []


def _one_blas_thread() -> Any:
    """A context with BLAS on one thread (threadpoolctl, if installed): Arnoldi's vectors are long
    and few, and OpenBLAS's threads spinning on a loaded machine made roots 40x slower
    (measured)."""
    if not _BLAS:
        try:
            from threadpoolctl import ThreadpoolController
            _BLAS.append(ThreadpoolController())
        except ImportError:
            _BLAS.append(None)
    return contextlib.nullcontext() if _BLAS[0] is None else _BLAS[0].limit(limits=1,
                                                                                user_api="blas")
