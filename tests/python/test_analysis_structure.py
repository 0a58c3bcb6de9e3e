# dmi.analysis has one continuation driver, one cache of what it builds from a model, and two
# Newton loops (newton.bordered_newton on maps, matrix-free, of which newton.newton is a case;
# the driver's corrector on residuals with their Jacobians), besides shooting's Newton-Picard;
# its import chain is at most 8 modules deep (it was 9 with two drivers).
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


def test_one_cache_and_two_newton_loops():
    t = trees()
    caches = {mod for mod, tree in t.items() for n in ast.walk(tree)
              if isinstance(n, ast.Attribute) and n.attr == "_cache"
              and isinstance(n.ctx, ast.Store)}
    assert caches == {"problem"}
    # Newton's residual bookkeeping (newton.judge) is called by the Newton loops only
    loops = {(mod, fn.name) for mod, tree in t.items() for fn in functions(tree)
             if calls(fn, "judge")}
    assert loops == {("newton", "bordered_newton"), ("driver", "newton_corrector")}, loops


def test_import_chain_is_shallower():
    assert depth(graph(PYTHON / "dmi"), "dmi.analysis.") <= 8
    assert depth({"a": {"b"}, "b": {"c"}, "c": set()}, "") == 3
