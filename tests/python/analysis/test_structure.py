# dmi.analysis has one continuation driver, one cache of what it builds from a model, and one
# Newton loop (newton.newton_loop, its linear solve given by the caller: the maps' matrix-free
# bordered_newton, of which newton.newton is a case, collocation's sparse LU, the driver's
# corrector), besides shooting's Newton-Picard; its import chain is at most 8 modules deep (it
# was 9 with two drivers).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ast
import functools
from pathlib import Path

from models.imports import PYTHON, graph

ANALYSIS = PYTHON / "dmi" / "analysis"


def trees() -> dict[str, ast.Module]:
    return {".".join(f.relative_to(ANALYSIS).with_suffix("").parts): ast.parse(f.read_text())
            for f in sorted(ANALYSIS.rglob("*.py"))}


def functions(tree: ast.Module) -> list[ast.FunctionDef]:
    return [n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)]


def calls(fn: ast.AST, name: str) -> bool:
    for n in ast.walk(fn):
        if isinstance(n, ast.Call):
            f = n.func
            if (isinstance(f, ast.Name) and f.id == name) or \
                    (isinstance(f, ast.Attribute) and f.attr == name):
                return True
    return False


def depth(edges: dict[str, set[str]], prefix: str) -> int:
    inner = {m: {n for n in e if n.startswith(prefix)} for m, e in edges.items()
             if m.startswith(prefix)}

    @functools.lru_cache(None)
    def d(m: str) -> int:
        return 1 + max((d(n) for n in inner[m]), default=0)
    return max(d(m) for m in inner)


def test_one_driver():
    # every function with a step policy (min_step) is the driver or hands it to the driver
    t = trees()
    with_steps = {(mod, fn.name) for mod, tree in t.items() for fn in functions(tree)
                  if "min_step" in [a.arg for a in fn.args.args + fn.args.kwonlyargs]}
    assert ("continuation.driver", "continuation") in with_steps
    assert ("orbits", "continue_orbit") in with_steps
    assert ("equilibria.equilibrium", "continue_equilibrium") in with_steps
    for mod, name in with_steps - {("continuation.driver", "continuation")}:
        fn = next(f for f in functions(t[mod]) if f.name == name)
        assert calls(fn, "continuation"), f"{mod}.{name} has a step policy of its own"


#: Linear solves a Newton iteration calls (by name or attribute).
LINEAR_SOLVES = {"splu", "spsolve", "bordered_solve", "bordered_step", "gmres", "lu_solve",
                 "lstsq"}
#: Loops around a linear solve that are not Newton loops on a residual of their own: shooting's
#: Newton-Picard (its own method).
OTHER_LOOPS = {("shooting.branch", "_newton_picard")}


def solving_loops(tree: ast.Module) -> set[str]:
    """The functions of a module with a for or while loop whose body calls a linear solve (a
    Newton loop written out) or solves with a factored matrix (``lu.solve``)."""
    out = set()
    for fn in functions(tree):
        for loop in ast.walk(fn):
            if not isinstance(loop, (ast.For, ast.While)):
                continue
            for n in ast.walk(loop):
                if not isinstance(n, ast.Call):
                    continue
                f = n.func
                name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(
                    f, ast.Attribute) else ""
                factored = (isinstance(f, ast.Attribute) and f.attr == "solve"
                            and isinstance(f.value, ast.Name) and f.value.id in ("lu", "LU"))
                if name in LINEAR_SOLVES or factored:
                    out.add(fn.name)
    return out


def test_one_cache_and_one_newton_loop():
    t = trees()
    caches = {mod for mod, tree in t.items() for n in ast.walk(tree)
              if isinstance(n, ast.Attribute) and n.attr == "_cache"
              and isinstance(n.ctx, ast.Store)}
    assert caches == {"scheme.problem"}
    # Newton's residual bookkeeping (newton.judge) is called by the Newton loop only
    loops = {(mod, fn.name) for mod, tree in t.items() for fn in functions(tree)
             if calls(fn, "judge")}
    assert loops == {("core.newton", "newton_loop")}, loops
    # and no other function iterates around a linear solve
    written = {(mod, name) for mod, tree in t.items() for name in solving_loops(tree)}
    assert written - OTHER_LOOPS == set(), written - OTHER_LOOPS
    # the collocation solves, the driver's corrector and the maps' Newton call it
    for mod, name in (("collocation.system", "solve"), ("continuation.driver", "newton_corrector"),
                      ("collocation.discretisation", "equation_hopf_orbit"),
                      ("core.newton", "bordered_newton")):
        fn = next(f for f in functions(t[mod]) if f.name == name)
        assert calls(fn, "newton_loop"), f"{mod}.{name} does not use newton_loop"


def test_solving_loops_finds_a_newton_loop_written_out():
    # the check above sees the loop the collocation had before it used newton_loop
    src = """
def solve(x, r):
    for _ in range(25):
        lu = sla.splu(J(x))
        dx = lu.solve(-r(x))
        x = x + dx
    return x

def chord(x, r, lu):
    while True:
        x = x + lu.solve(-r(x))
"""
    assert solving_loops(ast.parse(src)) == {"solve", "chord"}


def test_import_chain_is_shallower():
    assert depth(graph(PYTHON / "dmi"), "dmi.analysis.") <= 8
    assert depth({"a": {"b"}, "b": {"c"}, "c": set()}, "") == 3


#: The rooms of dmi.analysis, lowest first: a room imports only rooms of a lower rank; the
#: modules at the top (dmi.analysis itself, orbits, hopf_orbits) may import any room, and no room
#: imports them.
RANK = {"core": 0, "plot": 0, "scheme": 1, "continuation": 2, "equilibria": 3, "shooting": 4,
        "collocation": 5}


def room_of(module: str) -> str | None:
    """The room of a module of dmi.analysis (None for a module at the top)."""
    parts = module.split(".")
    return parts[0] if len(parts) > 1 and parts[0] in RANK else None


def climbs(edges: dict[str, set[str]]) -> list[tuple[str, str]]:
    """The imports of dmi.analysis that break the rooms' order: (importer, imported)."""
    out = []
    prefix = "dmi.analysis."
    for m, targets in edges.items():
        if not m.startswith(prefix):
            continue
        here = room_of(m[len(prefix):])
        for n in targets:
            if not n.startswith(prefix):
                continue
            there = room_of(n[len(prefix):])
            if here is None or there == here:
                continue
            if there is None or RANK[there] >= RANK[here]:
                out.append((m, n))
    return sorted(out)


def test_rooms_import_only_lower_rooms():
    edges = graph(PYTHON / "dmi")
    rooms = {room_of(m[len("dmi.analysis."):]) for m in edges if m.startswith("dmi.analysis.")}
    assert rooms - {None} == set(RANK), rooms
    assert climbs(edges) == []
    # every module of dmi.analysis sits in a room but the package's own and the two at the top
    top = {m for m in edges if m.startswith("dmi.analysis.") and room_of(m[13:]) is None}
    assert top == {"dmi.analysis.orbits", "dmi.analysis.hopf_orbits"} | {
        f"dmi.analysis.{r}" for r in RANK}, top


def test_climbs_sees_an_import_back_up():
    edges = {"dmi.analysis.core.model": {"dmi.analysis.scheme.stepmap"},
             "dmi.analysis.scheme.stepmap": {"dmi.analysis.core.model"},
             "dmi.analysis.shooting.shoot": {"dmi.analysis.orbits", "dmi.analysis.shooting.x"},
             "dmi.analysis.plot.branch": {"dmi.analysis.plot.interactive"}}
    assert climbs(edges) == [("dmi.analysis.core.model", "dmi.analysis.scheme.stepmap"),
                             ("dmi.analysis.shooting.shoot", "dmi.analysis.orbits")]
