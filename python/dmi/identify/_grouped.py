# dmi.identify._grouped: the perturbed models of several parameters built as one model.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Perturbed models shared by parameters that move disjoint parts of the model.

The tangent loop needs, per parameter j, what the model at p + delta_j e_j changes: its f (or
resolvent), its friction or box, its kernel's exponential terms, its history.  Where parameters
move disjoint parts (one f, one friction coefficient, one kernel term, the history), one model at
p + sum_{j in g} delta_j e_j carries the perturbations of a whole group g, and each part is
attributed to the member that moves it: one ``make`` call per group instead of one per
parameter (the idea of Curtis, Powell and Reid's grouped differences).

Which part each parameter moves is learned from a full build (:func:`plan` on the models of
:func:`dmi.identify.sensitivity._build`, one per parameter); each grouped build then checks that
the group's model moves nothing outside the parts of its members (its structure, callbacks
compared with :meth:`dmi.Solver.same_callback`, values bit for bit) and returns None where it
does, so that the caller builds all models again (and learns anew).
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from .._solver import Solver
from .sensitivity import _call_make, _Perturbed, _structure, perturbed_step

#: The callback parts a grouped parameter may not move (its model is then built on its own).
_OWN_PARTS = ("kernel", "kernel_near", "resolvent")


@dataclasses.dataclass
class Plan:
    """How the perturbed models are built: the parameters with a model of their own, the groups
    sharing one, and per parameter the value slots (:func:`values`) it moves."""

    own: list                   # parameters with a model of their own
    groups: list                # lists of parameters sharing one model
    reads: list                 # per group: the member whose model the loop reads (f, A), or None
    history: list               # per group: the member moving the history, or None
    slots: list                 # per parameter: the indices into values() it moves
    rhs: list                   # per parameter: whether it moves f
    union: list = dataclasses.field(default_factory=list)   # per group: the slots it moves
    structure: list = dataclasses.field(default_factory=list)   # the model's, as learned


def values(s: Solver) -> np.ndarray:
    """The model's values a parameter may move: the friction coefficients (n) or the box's
    faces (2 n), then the exponential kernel's a, b, C, D (raveled)."""
    parts = []
    if s.resolvent_kind == "friction":
        parts.append(s.friction)
    elif s.resolvent_kind == "box":
        parts += list(s.box)
    terms = s.kernel_terms
    if terms is not None:
        parts += [np.ravel(x) for x in terms]
    return np.concatenate(parts) if parts else np.zeros(0)


def _resolvent_slots(s: Solver) -> int:
    """How many of values() belong to the resolvent (the tangent loop reads them per model)."""
    return {"friction": 1, "box": 2}.get(s.resolvent_kind, 0) * s.n


def _groupable(s: Solver) -> bool:
    """Whether the model's parts are all values or f and history callbacks (no kernel callback,
    near cells, kernel fit or resolvent callback, whose perturbations are not attributed)."""
    return (s.kernel_kind in ("", "exp") and s.kernel_fit is None and not s.has("kernel_near")
            and s.resolvent_kind in ("", "friction", "box"))


def plan(mod: _Perturbed) -> Plan | None:
    """The groups of parameters of the full build ``mod`` that can share a perturbed model:
    disjoint value slots, at most one member moving f or the resolvent (the part the tangent
    loop reads from a member's model) and at most one moving the history; None where no two
    parameters can share one (or the model has parts that are not attributed)."""
    s = mod.base
    if not _groupable(s):
        return None
    v0, R = values(s), _resolvent_slots(s)
    P = len(mod.others)
    slots, rhs, own = [], [], []
    members: list = []          # (parameter, reads, history)
    for j, o in enumerate(mod.others):
        moved = np.flatnonzero(values(o) != v0)
        slots.append(moved)
        f = not s.same_callback(o, "rhs")
        z = not s.same_callback(o, "history")
        rhs.append(f)
        if not (len(moved) or f or z) or any(not s.same_callback(o, part) for part in _OWN_PARTS):
            own.append(j)
        else:
            members.append((j, f or bool(np.any(moved < R)), z))
    groups: list = []
    reads: list = []
    history: list = []
    taken: list = []            # per group: the slots its members move
    for j, r, z in members:
        mine = set(slots[j].tolist())
        for g, group in enumerate(groups):
            if (not taken[g] & mine and not (r and reads[g] is not None)
                    and not (z and history[g] is not None)):
                group.append(j)
                taken[g] |= mine
                reads[g] = j if r else reads[g]
                history[g] = j if z else history[g]
                break
        else:
            groups.append([j])
            taken.append(mine)
            reads.append(j if r else None)
            history.append(j if z else None)
    if len(groups) + len(own) == P:
        return None
    union = [frozenset(t) for t in taken]
    return Plan(own, groups, reads, history, slots, rhs, union, _structure(s))


def build(make: Callable[[np.ndarray], Solver], p: np.ndarray, plan: Plan,
          base: Solver | None = None) -> _Perturbed | None:
    """The models at p (``base``, else made here) and, per ``plan``, one model per group and one
    per own parameter; None where the model's structure is not the plan's or a group's model
    moves anything its members did not move in the plan's build (its structure, a callback, a
    value slot): the plan no longer holds."""
    base = _call_make(make, p, "p") if base is None else base
    structure, v0 = _structure(base), values(base)
    if structure != plan.structure:
        return None
    P = len(p)
    others: list = [base] * P
    sources: list = [base] * P
    delta = np.empty(P)
    for j in plan.own:
        q = p.copy()
        q[j] = perturbed_step(p, j)
        delta[j] = q[j] - p[j]
        others[j] = sources[j] = _call_make(make, q, f"p + delta e_{j}")
        if _structure(others[j]) != structure:
            return None
    base_terms = base.kernel_terms
    terms = [] if base_terms is None else [base_terms] * P
    for g, group in enumerate(plan.groups):
        q = p.copy()
        for j in group:
            q[j] = perturbed_step(p, j)
            delta[j] = q[j] - p[j]
        comb = _call_make(make, q, "p + " + " + ".join(f"delta e_{j}" for j in group))
        reader, mover = plan.reads[g], plan.history[g]
        if (_structure(comb) != structure
                or any(not base.same_callback(comb, part) for part in _OWN_PARTS)
                or (not base.same_callback(comb, "rhs") and not (reader is not None
                                                                 and plan.rhs[reader]))
                or (not base.same_callback(comb, "history") and mover is None)):
            return None
        vc = values(comb)
        if not set(np.flatnonzero(vc != v0).tolist()) <= plan.union[g]:
            return None
        for j in group:
            sources[j] = comb
            others[j] = comb if j == reader else base
            if terms:
                vj = v0.copy()
                vj[plan.slots[j]] = vc[plan.slots[j]]
                terms[j] = _terms(vj, base_terms, _resolvent_slots(base))
    hist = ([m for m in plan.history if m is not None]
            + [j for j in plan.own if not base.same_callback(others[j], "history")])
    return _Perturbed(base, others, delta, sources, terms or None, sorted(hist))


def _terms(v: np.ndarray, like: tuple, off: int) -> tuple:
    """The exponential kernel's (a, b, C, D) from values() v (the kernel's from index ``off``),
    shaped as the terms ``like``."""
    a, _, C, D = like
    K, nn = len(a), C.size
    return (v[off:off + K], v[off + K:off + 2 * K], v[off + 2 * K:off + 2 * K + nn].reshape(C.shape),
            v[off + 2 * K + nn:off + 2 * K + 2 * nn].reshape(D.shape))
