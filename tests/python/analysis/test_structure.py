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
        "collocation": 5, "plane": 6}


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


# ---- caches, found by what they are -------------------------------------------------------------

IDENTIFY = PYTHON / "dmi" / "identify"
#: Callables that make a dict a memo may live in.
DICT_MAKERS = {"dict", "OrderedDict", "defaultdict"}
#: Decorators that memoise a function.
MEMO_DECORATORS = {"lru_cache", "cache"}
#: Memoising tables of pure constants, the same for every problem (by (module, name)), allowed
#: with the reason.
CONSTANT_CACHES = {
    ("analysis.collocation.mesh", "_monomials"): "the Lagrange basis' coefficients by its degree",
    ("analysis.collocation.mesh", "_jacobi"): "Gauss-Jacobi nodes and weights by (q, beta)",
    ("analysis.collocation.mesh", "_legendre"): "Gauss-Legendre nodes and weights by q",
}
#: Memos kept inside an object that the problem's cache itself holds (the collocation's Terms of
#: one p, cached by CollocationDiscretisation's Problem): per problem already, by way of it;
#: folding them into Problem.cached is the collocation room's change.
INSIDE_CACHED = {
    ("analysis.collocation.system", "_delays"): "the delay integral's matrices by mesh",
    ("analysis.collocation.system", "_kept"): "f and its Jacobian at the last iterate",
}


def _target(node: ast.AST) -> str | None:
    """The name a dict is kept under: an attribute (on self or any object) or a plain name."""
    if isinstance(node, ast.Attribute):
        return node.attr
    if isinstance(node, ast.Name):
        return node.id
    return None


def _new_dict(value: ast.AST | None) -> bool:
    if isinstance(value, (ast.Dict, ast.DictComp)):
        return True
    if isinstance(value, ast.Call):
        f = value.func
        return (f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute)
                else "") in DICT_MAKERS
    return False


def _memo_uses(fn: ast.AST, name: str) -> tuple[bool, bool]:
    """(looked up, stored into) by key inside fn: d.get(k), k in d, d[k]; d[k] = v, d.setdefault."""
    look = store = False
    for n in ast.walk(fn):
        if isinstance(n, ast.Subscript) and _target(n.value) == name:
            store |= isinstance(n.ctx, ast.Store)
            look |= isinstance(n.ctx, ast.Load)
        elif isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) \
                and _target(n.func.value) == name:
            look |= n.func.attr in ("get", "setdefault")
            store |= n.func.attr == "setdefault"
        elif isinstance(n, ast.Compare) and any(isinstance(o, (ast.In, ast.NotIn)) for o in n.ops) \
                and any(_target(c) == name for c in n.comparators):
            look = True
    return look, store


def caches(tree: ast.Module) -> set[str]:
    """The caches of a module: functions under an lru_cache / cache decorator, and dicts kept on
    an object (``self.x = {}``) or at module level that one function both looks up and stores
    into by key (a memo).  A dict local to a function is not kept beyond its call."""
    out = set()
    for fn in functions(tree):
        for d in fn.decorator_list:
            f = d.func if isinstance(d, ast.Call) else d
            if _target(f) in MEMO_DECORATORS:
                out.add(fn.name)
    kept = set()
    for n in ast.walk(tree):
        if isinstance(n, (ast.Assign, ast.AnnAssign)) and _new_dict(n.value):
            for t in (n.targets if isinstance(n, ast.Assign) else [n.target]):
                if isinstance(t, ast.Attribute):
                    kept.add(t.attr)
    for n in tree.body:     # module level
        if isinstance(n, (ast.Assign, ast.AnnAssign)) and _new_dict(n.value):
            kept |= {t.id for t in (n.targets if isinstance(n, ast.Assign) else [n.target])
                     if isinstance(t, ast.Name)}
    for name in kept:
        if any(all(_memo_uses(fn, name)) for fn in functions(tree)):
            out.add(name)
    return out


def package_caches() -> dict[tuple[str, str], None]:
    found = {}
    for root in (ANALYSIS, IDENTIFY):
        for f in sorted(root.rglob("*.py")):
            mod = ".".join(f.relative_to(root.parent).with_suffix("").parts)
            for name in caches(ast.parse(f.read_text())):
                found[(mod, name)] = None
    return found


def test_caches_are_found_by_what_they_are():
    found = set(package_caches())
    allowed = set(CONSTANT_CACHES) | set(INSIDE_CACHED)
    assert found - allowed == set(), (
        f"memoising tables besides the problem's cache (Problem.cached, dmi._cache.Cache): "
        f"{sorted(found - allowed)}")
    # the problems keep one dmi._cache.Cache each: scheme.problem's and identify's fit
    made = {mod for mod, tree in [(".".join(f.relative_to(r.parent).with_suffix("").parts),
                                   ast.parse(f.read_text()))
                                  for r in (ANALYSIS, IDENTIFY) for f in r.rglob("*.py")]
            if calls(tree, "Cache")}
    assert made == {"analysis.scheme.problem", "identify.fitting"}, made
    # the check sees each kind of cache
    src = """
import functools
from collections import OrderedDict
TABLE = {}

@functools.lru_cache(maxsize=8)
def nodes(q): return q

@cache
def other(q): return q

def lookup(k):
    if k not in TABLE:
        TABLE[k] = k
    return TABLE[k]

class Holder:
    def __init__(self):
        self._memo = OrderedDict()
        self.data = {}
    def get(self, k):
        got = self._memo.get(k)
        if got is None:
            got = self._memo[k] = k
        return got
    def fill(self, k):
        self.data[k] = k          # stored, never looked up: data, not a memo

def local(k):
    seen = {}
    seen[k] = seen.get(k, 0) + 1  # local to the call
    return seen
"""
    assert caches(ast.parse(src)) == {"nodes", "other", "TABLE", "_memo"}


def test_scheme_and_shooting_rooms_are_shallow():
    # the step map and the multipliers import nothing of dmi.analysis (the model's construction is
    # dmi._make's, floquet reads its map through a Protocol): an orbit's record is two modules
    # deep; the forced and autonomous shootings sit side by side under shoot and refine
    edges = graph(PYTHON / "dmi")
    assert depth(edges, "dmi.analysis.scheme.") <= 2
    assert depth(edges, "dmi.analysis.shooting.") <= 2
    for leaf in ("scheme.stepmap", "scheme.floquet"):
        assert not {n for n in edges[f"dmi.analysis.{leaf}"] if n.startswith("dmi.analysis")}, leaf
