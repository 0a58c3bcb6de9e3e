# Mending a nonsmooth orbit's signature: a vanishing segment removed, a breached inequality's
# stretch made a segment of its own, the orbit laid out again on the new segments.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The signature changes for :mod:`dmi.analysis.collocation.collocate` (a result that breaks an
inequality: :func:`~.system.check_inequalities`) and :mod:`dmi.analysis.branches.discretisation`
(between steps); private to the package.

The segments around the circle are (modes, start) pairs, segment 0 the one holding t = 0.  A
segment shorter than VANISH of the period is removed (its neighbours meet at its middle, or merge
when their modes agree); else the first breached stretch on a fine grid (a slip of the wrong sign,
a stuck force above alpha, a free box component beyond a face, a net force that pulls a component
off its face) becomes a segment of its own (stuck, slipping with the force's sign, on the face
passed, free); a breach from a piece's start takes that start over (no sliver of the old mode
before it).
"""
from __future__ import annotations

import numpy as np

from .signature import FREE, HI, LO, SLIP_NEG, SLIP_POS, STUCK, Signature
from .system import (Layout, Terms, carried, evaluate, node_times,
                                 uniform_fractions)

#: A segment shorter than this fraction of the period is removed.
VANISH = 1e-7


def mend(lay: Layout, terms: Terms, x: np.ndarray) -> tuple[Layout, np.ndarray] | None:
    """The orbit x laid out on its mended signature (same L), or None when nothing is to mend.

    Raises
    ------
    ValueError
        The mended signature would switch two components at once.
    """
    segs, T = circle(lay, x)
    lengths = [(segs[(j + 1) % len(segs)][1] - s[1]) % T for j, s in enumerate(segs)]
    if len(segs) > 1 and min(lengths) < VANISH * T:
        return relaid(lay, terms, x, removed(segs, int(np.argmin(lengths)), T), T)
    grown = breached(lay, terms, x, segs, T)
    return None if grown is None else relaid(lay, terms, x, grown, T)


def circle(lay: Layout, x: np.ndarray) -> tuple[list[tuple[np.ndarray, float]], float]:
    """The segments around the circle as (modes, start), segment 0 holding t = 0."""
    _, b, T = lay.split(x)
    modes = lay.signature.modes
    if lay.S == 0:
        return [(modes[0], 0.0)], T
    return [(modes[0], float(b[-1] - T))] + [(modes[k], float(b[k - 1]))
                                             for k in range(1, lay.S)], T


def removed(segs: list, j: int, T: float) -> list:
    """Segment j removed: its neighbours meet at its middle, or merge when their modes agree."""
    S = len(segs)
    start = segs[j][1]
    end = segs[(j + 1) % S][1] + (T if j == S - 1 else 0.0)
    prev, nxt = segs[(j - 1) % S], segs[(j + 1) % S]
    rest = [s for k, s in enumerate(segs) if k not in (j, (j + 1) % S)]
    if np.array_equal(prev[0], nxt[0]):
        out = rest or [prev]                  # two segments: the other one is all that is left
    else:
        out = rest + [(nxt[0], 0.5 * (start + end))]
    return sorted(out, key=lambda s: s[1] % T)


def wrapping(lay: Layout, x: np.ndarray) -> tuple[int, float]:
    """(k, d): the switch of a forced orbit nearest the period's ends, k = 1 (b_1, next to
    t = 0) or S (b_S, next to T), and its distance d to that end.  ValueError for an
    autonomous or smooth orbit (no switch, or a time origin of its own)."""
    if lay.autonomous or lay.S == 0:
        raise ValueError("only a forced orbit's switch wraps around t = 0 (= T): "
                         f"{'autonomous' if lay.autonomous else 'no switch'}")
    _, b, T = lay.split(x)
    return (1, float(b[0])) if b[0] <= T - b[-1] else (lay.S, float(T - b[-1]))


def rotated(lay: Layout, terms: Terms, x: np.ndarray, gap: float
            ) -> tuple[Layout, np.ndarray, int]:
    """A forced orbit whose switch b_1 (b_S) nears t = 0 (T) laid out with that switch moved
    across the period's end to T - gap (gap): the same segments around the circle, the one
    holding t = 0 now the next (the previous) one, its signature rotated (the phase origin is
    the forcing's, so a switch that leaves the period at 0 re-enters at T), on another number
    of intervals than lay's (no unknown of the new layout means what one of the old meant: a
    continuation restarts its tangent and locates no event across).  Returns (the new layout,
    x on it, the moved switch's index in the new b: S - 1 or 0).

    Raises
    ------
    ValueError
        An autonomous or smooth orbit, or a gap outside (0, the next switch's distance).
    """
    k, _ = wrapping(lay, x)
    segs, T = circle(lay, x)
    _, b, _ = lay.split(x)
    room = T - b[-1] if k == 1 else b[0]     # the moved switch stays clear of the others
    if not 0 < gap < room:
        raise ValueError(f"gap = {gap!r}: the moved switch must land within (0, {room!r}) of "
                         "the period's end, short of the switch there")
    j = 1 if k == 1 else 0                 # the segment that starts at the moving switch
    segs = list(segs)
    segs[j] = (segs[j][0], -gap if k == 1 else gap)
    for more in range(4):   # other unknowns (their number changes): none shared with the old
        new, xn = relaid(lay, terms, x, segs, T, lay.L + more)
        if new.L != lay.L:
            break
    return new, xn, (lay.S - 1 if k == 1 else 0)


def breached(lay: Layout, terms: Terms, x: np.ndarray, segs: list, T: float) -> list | None:
    """The segments with the first breached stretch (a slip component of the wrong sign, a
    stuck one whose force exceeds alpha, a free box component beyond a face, one on a face whose
    net force pulls it off) made a segment of its own (stuck, slipping with the force's sign, on
    the face passed, free), or None when nothing is breached."""
    _, b, _ = lay.split(x)
    pieces = lay.piece_modes(b, T)
    e = lay.bounds(b, T)
    for j, mode in enumerate(pieces):
        t = np.linspace(e[j], e[j + 1], 64 * (len(lay.fractions[j]) - 1) + 1)[1:-1]
        u = evaluate(lay, x, t)
        for i, c in enumerate(mode):
            if c in (SLIP_POS, SLIP_NEG):
                bad, new = c * u[:, i] < 0, STUCK
            elif c == STUCK:
                force = -terms.f(t, u)[:, i] - memory(lay, terms, x, t)[:, i]
                over = np.abs(force) > terms.alpha[i]
                bad = over
                new = SLIP_POS if np.any(force[over] > 0) else SLIP_NEG
            elif c == FREE and (np.isfinite(terms.lo[i]) or np.isfinite(terms.hi[i])):
                above, below = u[:, i] > terms.hi[i], u[:, i] < terms.lo[i]
                bad = above | below
                new = HI if np.any(bad) and above[int(np.argmax(bad))] else LO
            elif c in (LO, HI):
                force = -terms.f(t, u)[:, i] - memory(lay, terms, x, t)[:, i]
                bad, new = (force > 0 if c == LO else force < 0), FREE
            else:
                continue
            if np.any(bad):
                k0, k1 = _run(bad)
                inner = mode.copy()
                inner[i] = new
                if lay.S == 0 and k0 == 0 and bad[-1] and not np.all(bad):
                    # a smooth orbit breached across t = 0 (= T): the run at the end of the
                    # period and the run at its start are one stretch
                    first = t.size - 1 - _run(bad[::-1])[1]   # the trailing run's first index
                    return [(inner, float(t[first])), (mode, float(t[k1]))]
                # the breach from the piece's start (a switch that should have been another):
                # the new mode takes the piece's start over, no sliver of the old mode before it
                at_start = k0 == 0 and j > 0
                out = [sg for sg in segs
                       if not (at_start and abs((sg[1] - e[j] + 0.5 * T) % T - 0.5 * T)
                               <= 1e-12 * T)]
                out.append((inner, float(e[j] if at_start else t[k0])))
                if k1 < t.size - 1:
                    out.append((mode, float(t[k1])))
                return sorted(out, key=lambda s: s[1] % T)
    return None


def _run(bad: np.ndarray) -> tuple[int, int]:
    """(first, last) index of the first run of True in ``bad`` (which holds one)."""
    k0 = int(np.argmax(bad))
    rest = np.flatnonzero(~bad[k0:])
    return k0, (k0 + int(rest[0]) - 1 if rest.size else bad.size - 1)


def memory(lay: Layout, terms: Terms, x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """int_0^tau H(s) u(t - s) ds at the times t (len(t), n) of the orbit x."""
    if not terms.has_kernel:
        return np.zeros((t.size, lay.n))
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    G = terms.periodic_delay(t, mesh, T, lay.basis, lay.rows)[0]
    return (G @ V.ravel()).reshape(-1, lay.n)


def relaid(lay: Layout, terms: Terms, x: np.ndarray, segs: list, T: float,
           intervals: int | None = None) -> tuple[Layout, np.ndarray]:
    """The layout of the segments ``segs`` (about ``intervals`` intervals, default the same L;
    uniform in each piece) and x on it; an autonomous orbit's time origin moved to the middle
    of its longest segment (no switch at 0)."""
    shift = 0.0
    segs = sorted(segs, key=lambda s: s[1] % T)
    # neighbours (around the circle) with the same modes are one segment: a smooth orbit's only
    # segment, split by a breach, is the stretch before and after it
    kept = [s for k, s in enumerate(segs) if not np.array_equal(s[0], segs[k - 1][0])]
    segs = kept or segs[:1]
    if lay.autonomous and len(segs) > 1:
        segs = sorted(segs, key=lambda s: s[1] % T)
        starts = np.array([s[1] % T for s in segs])
        lengths = np.diff(np.append(starts, starts[0] + T))
        j = int(np.argmax(lengths))
        shift = float(starts[j] + 0.5 * lengths[j])
        segs = [(md, (st - shift) % T) for md, st in segs]
    segs = sorted(segs, key=lambda s: s[1] % T)
    # segment 0 holds t = 0: the last to start (mod T); b: every start, ascending
    modes = np.array([segs[-1][0]] + [s[0] for s in segs[:-1]])
    b = np.array([s[1] % T for s in segs]) if len(segs) > 1 else np.empty(0)
    sig = Signature(modes if len(segs) > 1 else modes[:1])
    for k in range(1, sig.switches + 1):
        i = np.flatnonzero(sig.modes[k - 1] != sig.modes[k % len(sig.modes)])
        if i.size != 1:
            raise ValueError(f"the mended signature changes {i.size} components at once at "
                             f"t = {b[k - 1]:.6g}: not continued")
    new = Layout(lay.m, lay.n, sig, [], lay.autonomous, lay.period, carried(terms, sig))
    new = new.with_fractions(uniform_fractions(new.bounds(b, T),
                                               lay.L if intervals is None else intervals))
    V = evaluate(lay, x, node_times(new, b, T) + shift)
    return new, np.concatenate([V.ravel(), b, [T] if lay.autonomous else []])
