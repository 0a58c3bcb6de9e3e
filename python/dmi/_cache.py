# The one cache of a problem: recent objects built from a model, by key, the least recently used
# dropped first.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The cache every problem of dmi.analysis (:class:`dmi.analysis.scheme.problem.Problem`) and
dmi.identify (a fit's residuals and Jacobian) keeps of what it builds; private to the package.
Nothing else in those packages memoises per problem (tests/python/analysis/test_structure.py
finds memoising dicts and ``lru_cache`` tables by what they are)."""
from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any


class Cache:
    """Recent objects by key, at most ``keep`` of them (the least recently used goes first).

    Parameters
    ----------
    keep : int
        Objects kept (>= 1).
    """

    def __init__(self, keep: int):
        self.keep = max(1, int(keep))
        self._items: OrderedDict[Hashable, Any] = OrderedDict()

    def cached(self, key: Hashable, factory: Callable[[], Any]) -> Any:
        """The object kept under key, built by factory() (and kept) when absent."""
        if key in self._items:
            self._items.move_to_end(key)
            return self._items[key]
        got = factory()
        self._items[key] = got
        while len(self._items) > self.keep:
            self._items.popitem(last=False)
        return got

    def pop(self, key: Hashable) -> Any:
        """The object kept under key, taken out of the cache; None when absent."""
        return self._items.pop(key, None)

    def __len__(self) -> int:
        return len(self._items)
