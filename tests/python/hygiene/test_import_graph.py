# The Python packages have no import circles: the graph of imports between their modules (every
# import statement, at module level or inside a function, relative or absolute) is acyclic.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import pytest

from models.imports import PYTHON, graph


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The cycles found by depth-first search (one per back edge)."""
    found, state = [], {}

    def visit(m: str, path: list[str]) -> None:
        state[m] = 1
        for n in sorted(edges[m]):
            # a package importing its own submodule, or a submodule its package: not a circle
            if n.startswith(m + ".") or m.startswith(n + "."):
                continue
            if state.get(n) == 1:
                found.append(path[path.index(n):] + [n])
            elif n not in state:
                visit(n, path + [n])
        state[m] = 2

    for m in sorted(edges):
        if m not in state:
            visit(m, [m])
    return found


def test_graph_sees_a_circle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c", "a"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


@pytest.mark.parametrize("package", ["dmi", "dmi_sweep"])
def test_no_import_circles(package):
    edges = graph(PYTHON / package)
    assert len(edges) > 3
    assert cycles(edges) == []
