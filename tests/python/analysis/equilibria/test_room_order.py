# The room dmi.analysis.equilibria in order: no import chain inside it longer than four modules,
# no function of it longer than 80 lines of code (docstrings, blanks and comments not counted).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ast
import functools
from pathlib import Path

ROOM = Path(__file__).resolve().parents[4] / "python" / "dmi" / "analysis" / "equilibria"


def modules() -> dict[str, ast.Module]:
    return {f.stem: ast.parse(f.read_text()) for f in sorted(ROOM.glob("*.py"))
            if f.stem != "__init__"}


def edges(trees: dict[str, ast.Module]) -> dict[str, set[str]]:
    """The room's imports of its own modules (``from .x import ...``, ``from . import x``)."""
    out = {}
    for name, tree in trees.items():
        got = set()
        for n in ast.walk(tree):
            if isinstance(n, ast.ImportFrom) and n.level == 1:
                got |= {n.module} if n.module else {a.name for a in n.names}
        out[name] = got & set(trees)
    return out


def longest(graph: dict[str, set[str]]) -> tuple[str, ...]:
    @functools.lru_cache(None)
    def chain(m: str) -> tuple[str, ...]:
        return (m,) + max((chain(n) for n in graph[m]), key=len, default=())
    return max((chain(m) for m in graph), key=len)


def code_lines(fn: ast.AST, lines: list[str]) -> int:
    body = fn.body
    doc = None
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        doc = (body[0].lineno, body[0].end_lineno)
    return sum(1 for i in range(fn.lineno, fn.end_lineno + 1)
               if not (doc and doc[0] <= i <= doc[1])
               and lines[i - 1].strip() and not lines[i - 1].strip().startswith("#"))


def test_import_chains_are_at_most_four_modules():
    trees = modules()
    assert {"equation", "stability", "normal_form", "curves", "chart"} <= set(trees)
    chain = longest(edges(trees))
    assert len(chain) <= 4, " -> ".join(chain)
    # the checker sees a chain: chart reaches the characteristic matrix through others
    assert len(chain) >= 3


def test_functions_are_at_most_80_lines():
    long = []
    for f in sorted(ROOM.glob("*.py")):
        lines = f.read_text().splitlines()
        for n in ast.walk(ast.parse("\n".join(lines))):
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and code_lines(n, lines) > 80:
                long.append(f"{f.name}:{n.lineno} {n.name}")
    assert long == []


def test_the_checkers_see_a_long_chain_and_a_long_function():
    assert longest({"a": {"b"}, "b": {"c"}, "c": {"d"}, "d": {"e"}, "e": set()}) == \
        ("a", "b", "c", "d", "e")
    src = "def f():\n    '''doc'''\n" + "".join(f"    x{i} = {i}\n" for i in range(81))
    tree = ast.parse(src)
    assert code_lines(tree.body[0], src.splitlines()) == 82   # the def line and 81
