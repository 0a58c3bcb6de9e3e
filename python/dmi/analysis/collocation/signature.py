# The signature of a nonsmooth orbit: the mode of each component on each segment of the period,
# read from the scheme's orbit, with the switching condition at each segment end and the
# inequalities each mode must keep.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Signatures for :mod:`dmi.analysis.collocation.collocate`; private to the package.

A component i of a model with the built-in friction (alpha_i > 0) slips (+1 or -1: u_i > 0 or
u_i < 0, the force alpha_i sigma(u_i) constant) or sticks (u_i = 0, the net force inside
[-alpha_i, alpha_i]); a component of a model with the built-in box is free (lo_i < u_i < hi_i) or
on a face (held there, the net force pushing outward); every other component is free.  The period
is cut into segments; at each segment end exactly one component changes its mode, and the end's
time is an unknown fixed by its switching condition.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import _resolvent as rule
from ..._resolvent import FREE, HI, LO, SLIP_NEG, SLIP_POS, STUCK

NAMES = {FREE: "free", SLIP_POS: "slip +", SLIP_NEG: "slip -", STUCK: "stuck", LO: "on lo",
         HI: "on hi"}


@dataclass(frozen=True)
class Signature:
    """The modes (S, n) of the S distinct segments around the circle, the first the one holding
    t = 0 (S = 1: a smooth orbit, no switch).  With S >= 2 the period [0, T] holds S + 1 pieces:
    segments 0, 1, ..., S - 1 and segment 0 again (it wraps around t = T), cut by S switching
    times 0 < b_1 < ... < b_S < T."""
    modes: np.ndarray

    @property
    def switches(self) -> int:
        """S, the switching times (0 for a smooth orbit)."""
        return 0 if len(self.modes) == 1 else len(self.modes)

    def pieces(self) -> list[np.ndarray]:
        """The modes of the pieces of [0, T] in order (S + 1 of them, or 1)."""
        if self.switches == 0:
            return [self.modes[0]]
        return [self.modes[j] for j in range(len(self.modes))] + [self.modes[0]]

    def switch(self, k: int) -> tuple[int, int, int]:
        """(component, mode before, mode after) at b_k (k = 1..S)."""
        before, after = self.modes[k - 1], self.modes[k % len(self.modes)]
        i = int(np.flatnonzero(before != after)[0])
        return i, int(before[i]), int(after[i])

    def run_end(self, k: int) -> int:
        """The switch that ends the run of the mode that b_k's component enters there: that
        component's next switch around the circle (k' > k, or k' <= k past t = T)."""
        i = self.switch(k)[0]
        S = self.switches
        return next(kk for kk in ((k - 1 + d) % S + 1 for d in range(1, S + 1))
                    if self.switch(kk)[0] == i)

    def rotates_to(self, other: Signature) -> bool:
        """Whether ``other`` has the same segments around the circle in the same order, another
        one holding t = 0 (a forced orbit's switch that crossed t = 0 = T); False when equal."""
        a, b = np.asarray(self.modes), np.asarray(other.modes)
        if a.shape != b.shape or len(a) < 2 or np.array_equal(a, b):
            return False
        return any(np.array_equal(np.roll(a, -k, axis=0), b) for k in range(1, len(a)))

    def describe(self) -> list[str]:
        """One line a segment: its modes by component."""
        return ["(" + ", ".join(NAMES[int(c)] for c in row) + ")" for row in self.modes]


def interior_least(v: np.ndarray) -> int | None:
    """The index of the least interior local minimum of the grid values v (their ends left
    out), or None when v has none."""
    inner = np.flatnonzero((v[1:-1] <= v[:-2]) & (v[1:-1] <= v[2:])) + 1
    return None if inner.size == 0 else int(inner[np.argmin(v[inner])])


def step_modes(U: np.ndarray, alpha: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(M, n) modes of the steps of one period of the scheme (U: M + 1 rows), read periodically
    by the resolvent's rule (:func:`dmi._resolvent.friction_mode`, :func:`~dmi._resolvent.box_mode`):
    a friction component is stuck where U_i = 0 exactly for 2 steps or more (the resolvent's dead
    zone), else slips with the sign of U_i (a lone zero, a transversal reversal, takes the next
    step's sign); a box component is on a face where U_i equals it exactly (the clip), else free."""
    U = np.asarray(U, dtype=float)[1:]
    M, n = U.shape
    modes = np.zeros((M, n), dtype=int)
    for i in range(n):
        u = U[:, i]
        if alpha[i] > 0:
            nxt = np.roll(u, -1)
            m = rule.friction_mode(np.roll(u, 1), u, nxt)
            lone = (m == rule.REVERSAL) | (m == rule.TOUCH)
            modes[:, i] = np.where(lone, np.where(nxt > 0, SLIP_POS, SLIP_NEG), m)
        elif np.isfinite(lo[i]) or np.isfinite(hi[i]):
            modes[:, i] = rule.box_mode(u, lo[i], hi[i])
    return modes


def read_signature(U: np.ndarray, h: float, alpha: np.ndarray, lo: np.ndarray, hi: np.ndarray
                   ) -> tuple[Signature, np.ndarray]:
    """The signature of a scheme's orbit (U: M + 1 rows at the step h) and its switching times'
    guesses (halfway between the steps whose modes differ), in (0, T).

    Raises
    ------
    ValueError
        Two components change their modes at the same step (a switch of two constraints at
        once is not a codimension-0 signature here).
    """
    modes = step_modes(U, alpha, lo, hi)
    change = np.flatnonzero(np.any(modes != np.roll(modes, 1, axis=0), axis=1))  # k: k-1 -> k
    if change.size == 0:
        return Signature(modes[:1].copy()), np.empty(0)
    for k in change:
        if np.count_nonzero(modes[k] != modes[k - 1]) > 1:
            raise ValueError(f"the scheme's orbit changes two components' modes at once at step "
                             f"{k} (t = {(k + 1) * h:.6g}): collocation takes one switch at a "
                             "time; refine the scheme's orbit (smaller h)")
    # segment j holds the steps from change[j - 1] on (segment 0: t = 0, the last step's run);
    # b_k = (change[k - 1] + 1/2) h separates segment k - 1 from segment k (mod S)
    seg = np.array([modes[change[j - 1]] for j in range(change.size)])
    return Signature(seg), (change + 0.5) * h


def violations(pieces: list[np.ndarray], grid: list[np.ndarray], u: list[np.ndarray],
               force: list[np.ndarray], alpha: np.ndarray, lo: np.ndarray, hi: np.ndarray,
               tol: float) -> list[str]:
    """The inequalities broken on a fine grid of each piece: the slip sign on slip pieces, |net
    force| <= alpha on stuck ones, the net force pushing outward on a face, lo <= u <= hi on free
    box components (tolerance ``tol``, state or force units), each as a sentence."""
    out = []
    for j, (mode, t, uu, F) in enumerate(zip(pieces, grid, u, force)):
        inner = slice(1, -1)
        for i, c in enumerate(mode):
            if c in (SLIP_POS, SLIP_NEG):
                bad = c * uu[inner, i] < -tol
                what = f"u_{i} changes sign on a slip {'+' if c > 0 else '-'} piece"
            elif c == STUCK:
                bad = np.abs(F[inner, i]) > alpha[i] + tol
                what = f"|net force_{i}| > alpha_{i} = {alpha[i]:.6g} on a stuck piece"
            elif c == LO:
                bad = F[inner, i] > tol
                what = f"the net force_{i} leaves the face lo on a face piece"
            elif c == HI:
                bad = F[inner, i] < -tol
                what = f"the net force_{i} leaves the face hi on a face piece"
            elif np.isfinite(lo[i]) or np.isfinite(hi[i]):
                bad = (uu[inner, i] < lo[i] - tol) | (uu[inner, i] > hi[i] + tol)
                what = f"u_{i} leaves the box on a free piece"
            else:
                continue
            if np.any(bad):
                k = int(np.flatnonzero(bad)[0]) + 1
                out.append(f"{what} (piece {j}, t = {t[k]:.6g})")
    return out
