# The graph of imports between the modules of a Python package (every import statement, at module
# level or inside a function, relative or absolute), read from the sources: the import-graph test
# and the structure test of dmi.analysis.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ast
import os
from pathlib import Path

PYTHON = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[3])) / "python"


def graph(package: Path) -> dict[str, set[str]]:
    """module name -> the package's modules it imports (a package's __init__ is its name)."""
    root = package.parent
    mods = {}
    for f in package.rglob("*.py"):
        parts = list(f.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        mods[".".join(parts)] = f
    edges: dict[str, set[str]] = {m: set() for m in mods}
    for m, f in mods.items():
        is_pkg = f.name == "__init__.py"
        for node in ast.walk(ast.parse(f.read_text())):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = m.split(".") if is_pkg else m.split(".")[:-1]
                    base = base[:len(base) - node.level + 1]
                    mod = ".".join(base + ([node.module] if node.module else []))
                else:
                    mod = node.module or ""
                names = [mod] + [f"{mod}.{a.name}" for a in node.names]
            for name in names:
                # the longest module of the package the name starts with
                while name and name not in mods:
                    name = name.rpartition(".")[0]
                if name and name != m:
                    edges[m].add(name)
    return edges
