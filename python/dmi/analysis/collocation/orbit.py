# A periodic orbit of the equation (not of the scheme): a piecewise polynomial of one period.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The :class:`EquationOrbit` that :func:`dmi.analysis.collocate` returns, and the one way a solution
becomes one (:func:`equation_orbit`, its stability verified against its errors)."""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .mesh import Basis, periodic_locator
from .signature import Signature
from .system import CollocationWarning


@dataclass
class EquationOrbit:
    """A periodic orbit of the equation u' + A(u) + f(t, u) + int_0^tau H(s) u(t - s) ds ∋ 0,
    by orthogonal collocation (:func:`dmi.analysis.collocate`).

    Attributes
    ----------
    p : float
        The parameter.
    period : float
        The period (time units).
    amplitude : numpy.ndarray
        Shape (n,): (max - min) / 2 of each component over the period, its extrema located on
        the piecewise polynomial (state units).
    multipliers : numpy.ndarray of complex
        The leading Floquet multipliers, largest |mu| first (with the saltation at every switch).
    stable : bool or None
        All |mu| < 1 (an autonomous orbit: but its trivial multiplier), verified: the margin
        exceeds the multipliers' estimated error; None when it does not.
    mesh : numpy.ndarray
        The L + 1 mesh points of one period, 0 ... period (time units).
    signature : Signature
        The modes of each component on each segment (one segment: a smooth orbit).
    switches : numpy.ndarray
        The switching times b_1 < ... < b_S in (0, period) (time units; empty when smooth).
    make : callable
        The model ``make(p) -> dmi.Solver``.
    autonomous : bool
        The period is an unknown (with an integral phase condition).
    errors : dict
        Estimated errors (same units): ``"period"``, ``"amplitude"`` (n,), ``"multipliers"``
        (as ``multipliers``), ``"u"`` (the largest over the period, at equal phase t / T; an
        autonomous orbit's after aligning the two solutions' phase: the error of its shape),
        from the difference to the solve on another mesh (collocate: the orbit's mesh halved, in
        a refinement twice their difference, the orbit returned the coarser; with ``intervals=L``
        the L-interval mesh, the orbit returned the finer; a continuation point: its mesh with
        every pair of intervals merged), an upper estimate; empty where that solve failed.
    degree : int
        m, the polynomials' degree.
    nodes : numpy.ndarray
        Shape (L m, n): the values at the nodes t_i + k h_i / m, k = 0..m-1 of each interval.
    fractions : list of numpy.ndarray
        Each piece's mesh as fractions of the piece (the pieces: the signature's segments in
        order over [0, period], cut again at the carried breakpoints).
    carried : tuple of float
        The lags c at which the memory carries each switch: the mesh has points at
        (switch + c) mod period.
    kernel_jumps : tuple of float
        The lags of the kernel's jumps given to :func:`dmi.analysis.collocate` (its
        continuation cuts the delay integral there too).
    """
    p: float
    period: float
    amplitude: np.ndarray
    multipliers: np.ndarray
    stable: bool | None
    mesh: np.ndarray
    signature: Signature
    switches: np.ndarray
    make: Any = field(repr=False)
    autonomous: bool = False
    errors: dict[str, Any] = field(default_factory=dict)
    degree: int = 4
    nodes: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    fractions: list = field(default_factory=list, repr=False)
    carried: tuple = ()
    kernel_jumps: tuple = ()

    #: What the orbit is of: ``refine_orbit`` and ``floquet_multipliers`` refuse it by this.
    of = "equation"

    def u_at(self, t: Any) -> np.ndarray:
        """The state at times t (any reals: the orbit is periodic).

        Parameters
        ----------
        t : float or array_like
            Times (time units).

        Returns
        -------
        numpy.ndarray
            Shape (n,) for a scalar t, else (len(t), n) (state units).
        """
        tt = np.atleast_1d(np.asarray(t, dtype=float)).ravel()
        basis = Basis(self.degree, self.degree)
        _, z, cols = periodic_locator(self.mesh, self.degree)(tt)
        out = np.einsum("pk,pkn->pn", basis.values(z), self.nodes[cols])
        return out[0] if np.ndim(t) == 0 else out

    @property
    def intervals(self) -> int:
        """L, the mesh's intervals."""
        return self.mesh.size - 1


def stable(mu: np.ndarray, err: np.ndarray, autonomous: bool, p: float) -> bool | None:
    """All |mu| < 1 but the trivial one (autonomous), verified against the errors; None (with a
    CollocationWarning naming p) when a multiplier's |mu| is within its error of 1."""
    if mu.size == 0:
        return None
    keep = np.ones(mu.size, bool)
    if autonomous:
        keep[int(np.argmin(np.abs(mu - 1)))] = False
    a, e = np.abs(mu[keep]), err[keep]
    if np.any(a > 1 + e):
        return False
    if np.all(a < 1 - e):
        return True
    warnings.warn(f"p = {p!r}: a multiplier's modulus is within its estimated error of 1 "
                  f"({a[np.argmin(np.abs(a - 1))]:.12g}): stability not verified (None)",
                  CollocationWarning, stacklevel=3)
    return None


def equation_orbit(f: Any, p: float, make: Any, errors: dict[str, Any],
                   kernel_jumps: tuple[float, ...] = ()) -> EquationOrbit:
    """The EquationOrbit of a solution ``f`` (an :class:`~.adapt.Solved`: lay, x, amplitude, mu),
    its stability verified against ``errors``."""
    V, b, T = f.lay.split(f.x)
    return EquationOrbit(p=p, period=T, amplitude=f.amplitude, multipliers=f.mu,
                         stable=stable(f.mu, errors.get("multipliers", np.full(f.mu.shape,
                                                                                np.inf)),
                                        f.lay.autonomous, p),
                         mesh=f.lay.mesh(b, T), signature=f.lay.signature, switches=b.copy(),
                         make=make, autonomous=f.lay.autonomous, errors=errors,
                         degree=f.lay.m, nodes=V.copy(),
                         fractions=[fr.copy() for fr in f.lay.fractions], carried=f.lay.carried,
                         kernel_jumps=tuple(kernel_jumps))
