# The margins of a collocated orbit's inequalities that break towards another signature (its
# stick onsets, grazings and contacts) and their least values on the orbit.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The margins of the inequalities of a collocated orbit (:mod:`dmi.analysis.collocation.system`)
that break towards another signature (:func:`margins`, each a :class:`Margin`), and their least
values on the orbit (:class:`MarginValues`), zero where the orbit starts to stick, grazes or
touches a face:

* a friction component that slips throughout: its least s u_i(t) (s the slip's sign), 0 where
  the velocity touches 0 (a stick begins, or a grazing);
* a box component free throughout: its least distance to the face the other side reaches;
* a run of slip (a friction component) or of free motion (a box component) between two switches
  of that component, where the other side holds more stuck (face) segments of it: the least
  interior local minimum of s u_i (of the distance to the face) on the run, 0 where a second
  stick (contact) begins inside it (the run's ends, where u_i is 0 or on a face, left out);
* a stretch on a face (a box component) between two of its switches, where the other side holds
  more free segments of it: the least interior local minimum of s net force_i on the stretch (s
  = -1 on lo, +1 on hi), 0 where a lift-off begins inside it (the stretch's ends, lift-offs
  where the force is 0, left out);
* a reversal of a slip (u_i through 0 without a stick): |net force_i(b_k)| - alpha_i at the
  reversal b_k, 0 where the stick begins;
* a stuck stretch that leaves into slip s: alpha_i + min s net force_i on it, 0 where the force
  reaches the other bound.

A least value is taken at its minimiser t* (a grid of GRID points an interval, then bounded
Brent).  The net force is -f_i(t, u) - (int H u)_i.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.optimize as so

from .mesh import periodic_locator, point_matrix
from .mend import memory
from .signature import FREE, HI, LO, SLIP_NEG, SLIP_POS, STUCK, Signature, interior_least
from .system import Layout, Terms, evaluate

#: Grid points an interval on which a least value is bracketed before Brent.
GRID = 64


@dataclass(frozen=True)
class Margin:
    """The inequality whose margin is held at 0 (see the module).

    Attributes
    ----------
    kind : str
        ``"slip"`` (a friction component slipping throughout, or, with ``switch``, a run of
        slip), ``"box"`` (a box component free throughout, or a run of free motion),
        ``"face"`` (a stretch on a face), ``"reversal"`` (a slip's reversal) or ``"stuck"`` (a
        stuck stretch).
    component : int
        The component i.
    sign : int
        The slip's sign (slip, stuck: the slip it leaves into), +1 towards hi or -1 towards lo
        (box), +1 on hi or -1 on lo (face); 0 for a reversal.
    switch : int
        The switch b_k (1-based) of a reversal, of the stuck stretch's end, or that starts the
        run of slip or free motion or the face stretch (its interior least value the margin); 0
        otherwise.
    """
    kind: str
    component: int
    sign: int = 0
    switch: int = 0

    def describe(self) -> str:
        """The margin in words."""
        i = self.component
        where = f"inside the run from b_{self.switch}" if self.switch else "throughout"
        return {"slip": f"the least {'+' if self.sign > 0 else '-'}u_{i} of a slip {where}",
                "box": f"the least distance of u_{i} to its {'hi' if self.sign > 0 else 'lo'} "
                       f"face, free {where}",
                "face": f"the least {'+' if self.sign > 0 else '-'}net force_{i} on the "
                        f"{'hi' if self.sign > 0 else 'lo'} face {where}",
                "reversal": f"|net force_{i}| - alpha_{i} at the reversal b_{self.switch}",
                "stuck": f"alpha_{i} + min {'+' if self.sign > 0 else '-'}net force_{i} on "
                         f"the stuck stretch ending at b_{self.switch}"}[self.kind]


def margins(lay: Layout, terms: Terms, other: Signature) -> list[Margin]:
    """The margins of the orbit on ``lay`` whose inequalities break towards the signature
    ``other``: for each component whose modes differ between the two (see the module)."""
    mine, theirs = np.asarray(lay.signature.modes), np.asarray(other.modes)
    out: list[Margin] = []
    for i in range(lay.n):
        if sorted(mine[:, i]) == sorted(theirs[:, i]):
            continue
        col = mine[:, i]
        if np.all(col == col[0]):
            if terms.alpha[i] > 0 and col[0] in (SLIP_POS, SLIP_NEG):
                out.append(Margin("slip", i, int(col[0])))
            elif terms.alpha[i] <= 0:
                for face, s in ((LO, -1), (HI, 1)):
                    if np.any(theirs[:, i] == face):
                        out.append(Margin("box", i, s))
            continue
        held = [c for c in (STUCK, LO, HI) if np.sum(theirs[:, i] == c) > np.sum(col == c)]
        for k in range(1, lay.S + 1):
            j, before, after = lay.signature.switch(k)
            if j != i:
                continue
            if terms.alpha[i] <= 0:   # a box component: a run of free motion between contacts
                out += [Margin("box", i, s, k) for face, s in ((LO, -1), (HI, 1))
                        if after == FREE and face in held]
                if after in (LO, HI) and np.sum(theirs[:, i] == FREE) > np.sum(col == FREE):
                    out.append(Margin("face", i, -1 if after == LO else 1, k))  # a lift-off
                continue
            if {before, after} == {SLIP_POS, SLIP_NEG}:
                out.append(Margin("reversal", i, 0, k))
            elif before == STUCK and after in (SLIP_POS, SLIP_NEG):
                out.append(Margin("stuck", i, int(after), k))
            if after in (SLIP_POS, SLIP_NEG) and STUCK in held:
                out.append(Margin("slip", i, int(after), k))
    return out


class MarginValues:
    """A margin's least value on the orbit x of the layout ``lay`` (:meth:`least`), its value
    at a fixed time (the minimiser held, or the reversal b_k read from x) and its gradient in
    the node values (exact).

    Parameters
    ----------
    lay : Layout
        The orbit's layout.
    margin : Margin
        The margin.
    """

    def __init__(self, lay: Layout, margin: Margin):
        self.lay, self.m = lay, margin

    def time(self, x: np.ndarray, t_star: float) -> float:
        """The time the value is taken at (a reversal's: its switching time in x)."""
        if self.m.kind == "reversal":
            return float(self.lay.split(x)[1][self.m.switch - 1])
        return t_star

    def force(self, terms: Terms, x: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The net force on component i at the times t (mod T)."""
        lay, i = self.lay, self.m.component
        t = np.mod(np.asarray(t, dtype=float), lay.split(x)[2])
        return -terms.f(t, evaluate(lay, x, t))[:, i] - memory(lay, terms, x, t)[:, i]

    def along(self, terms: Terms, x: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The function whose least value is the margin (slip, box, face, stuck), at the times
        t."""
        m, i = self.m, self.m.component
        if m.kind == "slip":
            return m.sign * evaluate(self.lay, x, np.mod(t, self.lay.split(x)[2]))[:, i]
        if m.kind == "box":
            u = evaluate(self.lay, x, np.mod(t, self.lay.split(x)[2]))[:, i]
            return terms.hi[i] - u if m.sign > 0 else u - terms.lo[i]
        if m.kind == "face":
            return m.sign * self.force(terms, x, t)
        return terms.alpha[i] + m.sign * self.force(terms, x, t)

    def value(self, terms: Terms, x: np.ndarray, t_star: float) -> float:
        """The margin at the time held."""
        t = np.array([self.time(x, t_star)])
        if self.m.kind == "reversal":
            return float(abs(self.force(terms, x, t)[0]) - terms.alpha[self.m.component])
        return float(self.along(terms, x, t)[0])

    def span(self, x: np.ndarray) -> tuple[float, float]:
        """The stretch of time the least value is sought on."""
        _, b, T = self.lay.split(x)
        k = self.m.switch
        if self.m.kind == "stuck":
            return (float(b[k - 2]) if k >= 2 else float(b[-1] - T)), float(b[k - 1])
        if k:   # a run from b_k to the component's next switch (past T: + T)
            end = self.lay.signature.run_end(k)
            return float(b[k - 1]), float(b[end - 1]) + (T if end <= k else 0.0)
        return 0.0, T

    def least(self, terms: Terms, x: np.ndarray) -> tuple[float, float]:
        """(the margin, t*): the least value on the span, at its minimiser (a reversal: at
        b_k; a run or a face stretch: its least interior local minimum)."""
        if self.m.kind == "reversal":
            return self.value(terms, x, 0.0), self.time(x, 0.0)
        t0, t1 = self.span(x)
        grid = np.linspace(t0, t1, GRID * self.lay.L + 1)
        v = self.along(terms, x, grid)
        run = self.m.switch and self.m.kind in ("slip", "box", "face")
        k = interior_least(v) if run else int(np.argmin(v))
        if k is None:   # no interior minimum on the run: no margin there
            return math.inf, 0.5 * (t0 + t1)
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        T = self.lay.split(x)[2]
        r = so.minimize_scalar(lambda s: float(self.along(terms, x, np.array([s]))[0]),
                               bounds=(lo, hi), method="bounded",
                               options={"xatol": 1e-13 * max(1.0, T)})
        if float(r.fun) <= float(v[k]):
            return float(r.fun), float(r.x)
        return float(v[k]), float(grid[k])

    def node_row(self, terms: Terms, x: np.ndarray, t_star: float) -> np.ndarray:
        """d margin / d node values at the time held (exact)."""
        lay, i = self.lay, self.m.component
        V, b, T = lay.split(x)
        mesh = lay.mesh(b, T)
        loc = periodic_locator(mesh, lay.m)
        t = np.array([np.mod(self.time(x, t_star), T)])
        E = point_matrix(t, loc, lay.basis, mesh, lay.n, lay.rows)
        if self.m.kind == "slip":
            return self.m.sign * E[i].toarray().ravel()
        if self.m.kind == "box":
            return -np.sign(self.m.sign) * E[i].toarray().ravel()
        u = (E @ V.ravel())[None, :]
        row = -(terms.fu(t, u)[0][i:i + 1] @ E.toarray().reshape(lay.n, -1))[0] \
            if terms.has_rhs else np.zeros(E.shape[1])
        if terms.has_kernel:
            G = terms.periodic_delay(t, mesh, T, lay.basis, lay.rows)[0]
            row = row - G[i].toarray().ravel()
        s = self.m.sign if self.m.kind in ("stuck", "face") else np.sign(self.force(terms, x, t)[0])
        return s * row


__all__ = ["GRID", "Margin", "MarginValues", "margins"]
