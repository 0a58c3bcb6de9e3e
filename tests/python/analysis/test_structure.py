# dmi.analysis has one continuation driver (its contract typed, its options a value), one cache
# of what it builds from a model, one Newton loop (newton.newton_loop, its linear solve given by
# the caller: the maps' matrix-free bordered_newton, of which newton.newton is a case,
# collocation's sparse LU, the driver's corrector and its strategies, of which shooting's
# Newton-Picard is one; no discretisation has a corrector of its own), one bordered solve
# (newton.bordered_solve), one locator of events along a branch (the driver's), one hold rule
# (dmi._resolvent) and one cache per problem; its rooms import only rooms below them, with import
# chains of at most 4 modules inside a room and 7 across dmi.analysis; no function of analysis or
# identify has more than 80 lines of code.
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
    # every function with a step policy (min_step) is the driver or hands it to the driver: it
    # calls it, or maps its keywords onto the driver's options (a value: ContinuationOptions)
    t = trees()
    with_steps = {(mod, fn.name) for mod, tree in t.items() for fn in functions(tree)
                  if "min_step" in [a.arg for a in fn.args.args + fn.args.kwonlyargs]}
    policy = next(n for n in ast.walk(t["continuation.driver"])
                  if isinstance(n, ast.ClassDef) and n.name == "ContinuationOptions")
    assert "min_step" in {a.target.id for a in policy.body if isinstance(a, ast.AnnAssign)}
    assert ("orbits", "continue_orbit") in with_steps
    assert ("equilibria.equilibrium", "continue_equilibrium") in with_steps
    for mod, name in with_steps:
        fn = next(f for f in functions(t[mod]) if f.name == name)
        assert calls(fn, "continuation") or calls(fn, "ContinuationOptions"), \
            f"{mod}.{name} has a step policy of its own"


#: Linear solves a Newton iteration calls (by name or attribute).
LINEAR_SOLVES = {"splu", "spsolve", "bordered_solve", "bordered_step", "gmres", "lu_solve",
                 "lstsq"}
#: Loops around a linear solve that are not Newton loops on a residual of their own: none
#: (shooting's Newton-Picard is a linear solve of newton_loop).
OTHER_LOOPS: set[tuple[str, str]] = set()


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
    # the collocation solves, the driver's corrector (through its loop over strategies, each
    # run by newton_loop) and the maps' Newton (a strategy) call it
    for mod, name, callee in (("collocation.system", "solve", "newton_loop"),
                              ("continuation.driver", "newton_corrector", "corrected"),
                              ("continuation.driver", "corrected", "run"),
                              ("core.newton", "run", "newton_loop"),
                              ("branches.discretisation", "equation_hopf_orbit", "newton_loop"),
                              ("core.newton", "bordered_newton", "map_strategy")):
        fn = next(f for f in functions(t[mod]) if f.name == name)
        assert calls(fn, callee), f"{mod}.{name} does not use {callee}"


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


#: The rooms of dmi.analysis, lowest first: a room imports only rooms of a lower rank; the
#: modules at the top (dmi.analysis itself, orbits, hopf_orbits) may import any room, and no room
#: imports them.
RANK = {"core": 0, "plot": 0, "scheme": 1, "continuation": 2, "equilibria": 3, "shooting": 4,
        "collocation": 5, "branches": 6, "plane": 7}


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
    assert top == {"dmi.analysis.orbits", "dmi.analysis.hopf_orbits", "dmi.analysis.curves"} | {
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
    ("analysis.collocation.mesh", "_legendre_form"): "the Lagrange basis' Legendre coefficients",
    ("analysis.collocation.mesh", "_jacobi"): "Gauss-Jacobi nodes and weights by (q, beta)",
    ("analysis.collocation.mesh", "_legendre"): "Gauss-Legendre nodes and weights by q",
    ("analysis.collocation.system", "_collocation_pattern"): "the collocation matrices' pattern "
    "by basis and mesh size (E read-only)",
}
#: Memos kept inside an object that the problem's cache itself holds (the collocation's Terms of
#: one p, cached by CollocationDiscretisation's Problem): per problem already, by way of it;
#: folding them into Problem.cached is the collocation room's change.
INSIDE_CACHED = {
    ("analysis.collocation.system", "_delays"): "the delay integral's matrices by mesh",
    ("analysis.collocation.system", "_kept"): "f and its Jacobian at the last iterate",
    ("analysis.collocation.system", "_plans"): "the delay matrix's plans by count of times, "
    "mesh size and basis",
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


def _called(n: ast.Call) -> str:
    """The name a call calls (``f`` of ``f(...)`` or ``a.b.f(...)``)."""
    f = n.func
    return f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""


def owners(tree: ast.Module) -> dict[ast.AST, str]:
    """Every node of a module -> the name of the innermost function (or ``Class.method``) that
    holds it ("" at the module's level)."""
    out: dict[ast.AST, str] = {}

    def walk(node: ast.AST, name: str, cls: str) -> None:
        for child in ast.iter_child_nodes(node):
            here, inner = name, cls
            if isinstance(child, ast.ClassDef):
                inner = child.name
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                here = f"{cls}.{child.name}" if cls and not name else child.name if not name \
                    else name
            out[child] = here
            walk(child, here, inner)
    walk(tree, "", "")
    return out


def callers(names: set[str], t: dict[str, ast.Module] | None = None) -> set[tuple[str, str]]:
    """(module, function) of every call in dmi.analysis to one of ``names``."""
    t = trees() if t is None else t
    out = set()
    for mod, tree in t.items():
        where = owners(tree)
        for n in ast.walk(tree):
            if isinstance(n, ast.Call) and _called(n) in names:
                out.add((mod, where[n]))
    return out


#: Root finders of a scalar function: along a branch only the driver's locator calls them.
ROOT_FINDERS = {"brentq", "brenth", "ridder", "bisect", "root_scalar", "toms748"}
#: Scalar roots of a defined function, not events along a branch: the Hopf crossing of the
#: rightmost root between two parameters (stability.hopf), a Hopf curve's crossing on its first
#: row (chart._trace).
SCALAR_ROOTS = {("equilibria.crossing", "hopf"), ("equilibria.chart", "_trace")}


def test_one_event_locator():
    # Brent's method along a branch: the driver's locator (Along.root, locate) and landing only
    found = callers(ROOT_FINDERS)
    assert found - SCALAR_ROOTS == {("continuation.driver", "Along.root"),
                                    ("continuation.driver", "locate"),
                                    ("continuation.driver", "_Run.land")}, found
    # a bisection along the branch (a loop around a corrected middle) is the driver's too
    for mod, tree in trees().items():
        if mod == "continuation.driver":
            continue
        for loop in ast.walk(tree):
            if isinstance(loop, (ast.For, ast.While)):
                inner = {_called(n) for n in ast.walk(loop) if isinstance(n, ast.Call)}
                assert not inner & {"middle", "mid", "across"}, f"{mod} bisects a branch"
    # the shooting's stick events and the collocation's signature changes use it
    t = trees()
    assert callers({"bisect_along"}, t) >= {("branches.shooting", "Shooting.between")}
    assert ("branches.collocated", "EquationBranch._locate") in callers({"locate"}, t)


#: Functions of dmi.analysis that call a dense, sparse or Krylov solver, and what they solve;
#: the one bordered solve is core.newton.bordered_system (bordered_solve), the other entries are
#: systems without a border.  A new caller fails the test: a bordered system goes through
#: bordered_solve.
RAW_SOLVES = {
    ("core.newton", "bordered_system"): "the one bordered solve",
    ("continuation.driver", "bordered_det"): "the branch-point test function's determinant",
    ("collocation.system", "factored"): "the collocation system's Jacobian",
    ("collocation.floquet", "monodromy"): "the monodromy's sensitivities",
    ("collocation.floquet", "operator"): "the monodromy operator's period block, factored",
    ("equilibria.normal_form", "_corrected"): "the equilibrium's Jacobian",
    ("equilibria.root_verdict", "_eval"): "the characteristic matrix's trace",
    ("equilibria.equation", "Characteristic.newton_step"): "the characteristic matrix's trace",
    ("scheme.floquet", "growth_rate"): "a least-squares fit",
    ("branches.shooting", "_Picard.solve"): "Newton-Picard's reduced system (b + k unknowns)",
    # a bordered system solved on its own, to go through bordered_solve (its owner's change)
    ("equilibria.curves", "_Extended._null"): "the bordered left null vector of a fold curve",
}
SOLVERS = {"gmres", "splu", "spsolve", "lu_solve", "lstsq", "cho_solve", "bicgstab"}


def raw_solves(t: dict[str, ast.Module]) -> set[tuple[str, str]]:
    """(module, function) of the calls to a solver, or to ``linalg.solve``."""
    out = callers(SOLVERS, t)
    for mod, tree in t.items():
        where = owners(tree)
        for n in ast.walk(tree):
            if isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and \
                    n.func.attr == "solve" and isinstance(n.func.value, ast.Attribute) and \
                    n.func.value.attr == "linalg":
                out.add((mod, where[n]))
    return out


def test_one_bordered_solve():
    t = trees()
    got = raw_solves(t)
    assert got == set(RAW_SOLVES), (got - set(RAW_SOLVES), set(RAW_SOLVES) - got)
    # the driver's corrector and tangent, the maps' Newton step and the collocation's Newton
    # with a held length border through bordered_solve
    users = callers({"bordered_solve", "bordered_system"}, t)
    assert {("continuation.driver", "tangent"), ("core.newton", "bordered_step"),
            ("core.newton", "bordered_solve")} <= users, users
    assert not [m for m, _ in users if m.startswith(("shooting", "collocation"))
                and m != "branches.discretisation"], users
    # no bordered solve of its own: none defines one
    defined = {(mod, fn.name) for mod, tree in t.items() for fn in functions(tree)
               if "bordered" in fn.name and mod != "core.newton"}
    assert defined == {("continuation.driver", "bordered_det")}, defined
    # the collocated branch's Newton with a held length is the driver's corrector
    held = next(f for f in functions(t["branches.collocated"]) if f.name == "_held")
    assert calls(held, "newton_corrector")


def test_raw_solves_finds_a_solve():
    src = """
def f(A, b):
    return np.linalg.solve(A, b)

class C:
    def g(self, A, b):
        return sla.splu(A).solve(b)
"""
    assert raw_solves({"m": ast.parse(src)}) == {("m", "f"), ("m", "C.g")}


def test_newton_picard_is_a_strategy_of_the_one_loop():
    t = trees()
    fn = next(f for f in functions(t["branches.shooting"]) if f.name == "_newton_picard")
    # a strategy the driver's corrector runs, not a Newton loop of its own
    assert calls(fn, "Strategy") and not calls(fn, "newton_loop")
    assert not [(mod, f.name) for mod, tree in t.items() for f in functions(tree)
                if mod.startswith(("branches", "shooting")) and calls(f, "newton_loop")
                and f.name != "equation_hopf_orbit"]
    assert ("branches.shooting", "_newton_picard") not in {
        (mod, name) for mod, tree in t.items() for name in solving_loops(tree)}


def test_driver_contract_is_typed():
    import dmi.analysis.continuation.driver as driver
    # no hook found by getattr / hasattr on the discretisation: its protocols say them
    tree = trees()["continuation.driver"]
    for n in ast.walk(tree):
        if isinstance(n, ast.Call) and _called(n) in ("getattr", "hasattr") and n.args:
            a = n.args[0]
            name = a.id if isinstance(a, ast.Name) else a.attr if isinstance(
                a, ast.Attribute) else ""
            assert name != "disc" or (isinstance(n.args[1], ast.Name)), ast.unparse(n)
    for hook in ("HasEvents", "Describes", "Corners", "Accepts", "Recovers", "Adapts",
                 "Carries", "Orients", "Weighted", "StartsTangent", "Between", "OnCurrent",
                 "HasStrategies"):
        assert getattr(driver, hook)._is_protocol, hook
    # one corrector: no hook hands the driver a corrector of the discretisation's own
    assert not hasattr(driver, "OwnCorrector")
    assert "correct" not in driver.HOOKS
    assert not [name for proto in driver.HOOKS.values() for name in vars(proto)
                if name == "correct"]
    # the driver's corrector asks the discretisation for its strategies, accept and recover
    # only
    run = next(n for n in ast.walk(tree) if isinstance(n, ast.ClassDef) and n.name == "_Run")
    method = next(f for f in run.body if isinstance(f, ast.FunctionDef) and f.name == "correct")
    asked = {n.func.attr for n in ast.walk(method) if isinstance(n, ast.Call)
             and isinstance(n.func, ast.Attribute) and isinstance(n.func.value, ast.Name)
             and n.func.value.id == "disc"}
    assert asked == {"strategies", "accept", "recover"}, asked
    # no discretisation of dmi.analysis defines a corrector
    own = [(mod, c.name) for mod, t in trees().items() for c in ast.walk(t)
           if isinstance(c, ast.ClassDef)
           and {"residual", "jacobian", "correct"} <= {f.name for f in c.body
                                                       if isinstance(f, ast.FunctionDef)}]
    assert own == [], own
    from dmi.analysis.branches.shooting import Shooting
    assert not hasattr(Shooting, "correct") and isinstance(Shooting, type)
    assert issubclass(Shooting, driver.HasStrategies) and issubclass(Shooting, driver.Accepts)
    # the collocated branch gets its mends through accept / recover, not an own corrector
    from dmi.analysis.branches.collocated import EquationBranch
    assert not hasattr(EquationBranch, "correct")
    assert issubclass(EquationBranch, (driver.Accepts,)) or all(
        callable(getattr(EquationBranch, m)) for m in ("accept", "recover"))


def test_a_corrector_of_the_discretisation_is_not_called():
    # x - p = 0 from (0, 0) to p = 1: a method named correct (the hook that left the contract)
    # is never called; the points are the exact x = p, found by the driver's Newton
    import numpy as np

    from dmi.analysis.continuation.driver import continuation

    class Line:
        def residual(self, x, p):
            return x - p

        def jacobian(self, x, p):
            return np.eye(1), -np.ones(1)

        def point(self, x, p):
            return type("P", (), {"p": p, "x": x.copy(), "stable": None})()

        def correct(self, x, p, row, target, far):
            raise AssertionError("the driver called a discretisation's own corrector")

    b = continuation(Line(), np.zeros(1), 0.0, 1.0, step=0.25)
    assert len(b.points) >= 4
    for pt in b.points:
        assert abs(pt.x[0] - pt.p) <= 1e-12


def test_dispatch_on_the_orbit_class():
    # no "of" attribute read to tell a scheme's orbit from the equation's: the class says which
    t = trees()
    for mod in t:
        for n in ast.walk(t[mod]):
            if isinstance(n, ast.Call) and _called(n) == "getattr" and len(n.args) >= 2:
                a = n.args[1]
                assert not (isinstance(a, ast.Constant) and a.value == "of"), (mod,
                                                                               ast.unparse(n))


def chain(edges: dict[str, set[str]], start: str, within: str) -> list[str]:
    """The longest import chain from ``start`` through modules whose names start with ``within``
    (a package's import of its own submodules counts, as Python runs them)."""
    @functools.lru_cache(None)
    def longest(m: str) -> tuple[str, ...]:
        nxt = [longest(n) for n in edges.get(m, ()) if n.startswith(within)]
        return (m,) + max(nxt, key=len, default=())
    return list(longest(start))


def test_import_chains_are_short():
    edges = graph(PYTHON / "dmi")
    # across dmi.analysis, from the package itself: at most 7 modules
    top = chain(edges, "dmi.analysis", "dmi.analysis")
    assert len(top) <= 7, top
    # inside each room: at most 4
    for room in RANK:
        prefix = f"dmi.analysis.{room}."
        worst = max((chain(edges, m, prefix) for m in edges if m.startswith(prefix)), key=len)
        assert len(worst) <= 4, worst
    assert chain({"a": {"b", "c"}, "b": {"c"}, "c": set()}, "a", "") == ["a", "b", "c"]


def test_no_function_over_80_lines():
    long = []
    for root in (ANALYSIS, PYTHON / "dmi" / "identify"):
        for f in sorted(root.rglob("*.py")):
            lines = f.read_text().splitlines()
            for fn in functions(ast.parse(f.read_text())):
                if code_lines(fn, lines) > 80:
                    long.append(f"{f.relative_to(PYTHON)}:{fn.lineno} {fn.name}")
    assert long == []


def code_lines(fn: ast.FunctionDef, lines: list[str]) -> int:
    """A function's lines of code: not its docstring, blank lines or comment lines."""
    doc = range(0)
    first = fn.body[0]
    if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) \
            and isinstance(first.value.value, str):
        doc = range(first.lineno, first.end_lineno + 1)
    return sum(1 for i in range(fn.lineno, fn.end_lineno + 1)
               if i not in doc and lines[i - 1].strip() and not lines[i - 1].strip().startswith("#"))


def test_code_lines_skips_the_docstring_and_comments():
    src = 'def f(x):\n    """doc\n    more"""\n    # a comment\n\n    return x\n'
    fn = functions(ast.parse(src))[0]
    assert code_lines(fn, src.splitlines()) == 2


#: The functions that read a friction or box component's hold or mode, each through the one rule
#: (dmi._resolvent, checked against libdmi's C rule in binding/test_resolvent_rule.py).
RULE_USERS = {("analysis.core.model", "_resolvent_derivative"),
              ("analysis.scheme.orbit", "stuck_mask"),
              ("analysis.collocation.signature", "step_modes"),
              ("analysis.branches.events", "stick_profile"),
              ("identify.sensitivity", "_python_loop"),
              ("identify._saltation", "reversal")}


def rule_names(tree: ast.Module) -> set[str]:
    """The names under which a module reaches dmi._resolvent: its alias, or names imported from
    it."""
    out = set()
    for n in ast.walk(tree):
        if isinstance(n, ast.ImportFrom):
            if (n.module or "").endswith("_resolvent"):
                out |= {a.asname or a.name for a in n.names}
            else:
                out |= {a.asname or a.name for a in n.names if a.name == "_resolvent"}
    return out


def threshold_tests(tree: ast.Module) -> list[str]:
    """Comparisons with the friction's threshold h alpha (both names in one comparison)."""
    out = []
    for n in ast.walk(tree):
        if isinstance(n, ast.Compare):
            names = {x.id if isinstance(x, ast.Name) else x.attr for x in ast.walk(n)
                     if isinstance(x, (ast.Name, ast.Attribute))}
            if {"h", "alpha"} <= names:
                out.append(ast.unparse(n))
    return out


def test_one_hold_rule():
    mods = {}
    for root in (ANALYSIS, PYTHON / "dmi" / "identify"):
        for f in sorted(root.rglob("*.py")):
            mods[".".join(f.relative_to(root.parent).with_suffix("").parts)] = ast.parse(
                f.read_text())
    for mod, name in RULE_USERS:
        fn = next(f for f in functions(mods[mod]) if f.name == name)
        used = {x.id for x in ast.walk(fn) if isinstance(x, ast.Name)}
        assert used & rule_names(mods[mod]), f"{mod}.{name} does not read dmi._resolvent"
    # nobody else compares with the friction's threshold
    found = {mod: threshold_tests(tree) for mod, tree in mods.items() if threshold_tests(tree)}
    assert found == {}, found
    rule = ast.parse((PYTHON / "dmi" / "_resolvent.py").read_text())
    assert threshold_tests(ast.parse("held = abs(x) <= h * alpha")) == ["abs(x) <= h * alpha"]
    assert rule_names(ast.parse("from .. import _resolvent as rule")) == {"rule"}
    assert {fn.name for fn in functions(rule)} >= {"friction_held", "box_held", "friction_mode",
                                                     "saltation_factor", "reaches_zero"}
