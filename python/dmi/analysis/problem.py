# The problem of a continuation: the model, its step policy and one cache of what is built from it.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""One value for what every analysis builds from a model ``make(p) -> dmi.Solver``.

A :class:`Problem` holds the model, its step policy (the model keeps its own step h, or gets
h through ``make(p, h=...)``), one cache of the recent objects built from it (step maps,
one-step maps of equilibria: each built once per key), and the probe solvers read for h, tau
and N through Solver's public accessors (built once per (p, h), never run).  The memory a
step h needs, N = ceil(tau / h) steps, is asked of the probe (:meth:`Problem.memory`): one
place for the rule.
"""
from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from typing import Any

from .._solver import Solver
from .stepmap import Model, build

#: Objects the cache keeps (the least recently used goes first).
KEEP = 8


class Problem:
    """A model, its step policy and one cache of recent objects built from it.

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver`` (configured, not initialised); with ``make(p,
        h=...)`` when the step is given.
    keep : int
        Objects the cache keeps.
    """

    def __init__(self, make: Model, keep: int = KEEP):
        self.model = make                        # make(p) as given
        self.make = getattr(make, "base", make)  # the user's model (a FixedStep's own)
        self.keep = int(keep)
        self._cache: OrderedDict[Any, Any] = OrderedDict()

    def solver(self, p: float, h: float | None = None) -> Solver:
        """A new solver of the model at p (and the step h when given).

        Parameters
        ----------
        p : float
            The parameter.
        h : float, optional
            The step (the model must take ``h=``).

        Returns
        -------
        dmi.Solver
            Configured, not initialised; the caller owns it.

        Raises
        ------
        Exception
            The model's own, with a note naming the call.
        """
        if h is None:
            return build(self.model, p)
        return build(self.make, p, h=h)

    def cached(self, key: Any, factory: Callable[[], Any]) -> Any:
        """The object cached under key, built by factory() when absent.

        Parameters
        ----------
        key : hashable
            What the object is of (its kind, p, h, ...).
        factory : callable
            Builds it.

        Returns
        -------
        object
            The cached or new object.
        """
        got = self._cache.get(key)
        if got is None:
            got = factory()
            self._cache[key] = got
            while len(self._cache) > self.keep:
                self._cache.popitem(last=False)
        else:
            self._cache.move_to_end(key)
        return got

    def probe(self, p: float, h: float | None = None) -> Solver:
        """The probe solver at (p, h): read for its h, tau, N and model (never run).

        Parameters
        ----------
        p : float
            The parameter.
        h : float, optional
            The step.

        Returns
        -------
        dmi.Solver
            Cached: do not run or close it.
        """
        return self.cached(("probe", float(p), h), lambda: self.solver(p, h))

    def memory(self, p: float, h: float | None = None) -> int:
        """N, the steps of memory of the model at (p, h): the probe's ``N`` (ceil(tau / h)).

        Parameters
        ----------
        p : float
            The parameter.
        h : float, optional
            The step.

        Returns
        -------
        int
            N.
        """
        return int(self.probe(p, h).N)
