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

from test_import_graph import PYTHON, graph

ANALYSIS = PYTHON / "dmi" / "analysis"


def trees() -> dict[str, ast.Module]:
    return {f.stem: ast.parse(f.read_text()) for f in sorted(ANALYSIS.glob("*.py"))}


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
    assert ("driver", "continuation") in with_steps
    assert ("continuation", "continue_orbit") in with_steps
    assert ("equilibria", "continue_equilibrium") in with_steps
    for mod, name in with_steps - {("driver", "continuation")}:
        fn = next(f for f in functions(t[mod]) if f.name == name)
        assert calls(fn, "continuation"), f"{mod}.{name} has a step policy of its own"


#: Linear solves a Newton iteration calls (by name or attribute).
LINEAR_SOLVES = {"splu", "spsolve", "bordered_solve", "bordered_step", "gmres", "lu_solve",
                 "lstsq"}
#: Loops around a linear solve that are not Newton loops on a residual of their own: shooting's
#: Newton-Picard (its own method).
OTHER_LOOPS = {("periodic", "_newton_picard")}


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
    assert caches == {"problem"}
    # Newton's residual bookkeeping (newton.judge) is called by the Newton loop only
    loops = {(mod, fn.name) for mod, tree in t.items() for fn in functions(tree)
             if calls(fn, "judge")}
    assert loops == {("newton", "newton_loop")}, loops
    # and no other function iterates around a linear solve
    written = {(mod, name) for mod, tree in t.items() for name in solving_loops(tree)}
    assert written - OTHER_LOOPS == set(), written - OTHER_LOOPS
    # the collocation solves, the driver's corrector and the maps' Newton call it
    for mod, name in (("collocation_system", "solve"), ("driver", "newton_corrector"),
                      ("collocation_continuation", "equation_hopf_orbit"),
                      ("newton", "bordered_newton")):
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
