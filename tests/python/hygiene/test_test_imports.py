# The tests' own layout: no test module imports another test module or conftest.py (what several
# tests share lives in the package tests/python/models), read from every import statement of every
# test_*.py under tests/python (at module level or inside a function, relative or absolute); and no
# test module lies at the top of tests/python, outside the folders that mirror the package.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]


def imports_of_tests(root: Path) -> list[str]:
    """Each import of a test module (by its name, test_x, or its dotted path, a.b.test_x, or of
    a name in it) or of conftest by a test module under ``root``, as 'file:line: name' (file
    relative to ``root``)."""
    tests = {f.stem for f in root.rglob("test_*.py")} | {"conftest"}
    found = []
    for f in sorted(root.rglob("test_*.py")):
        for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                module = node.module or ""
                names = [module] + [f"{module}.{a.name}" if module else a.name for a in node.names]
            hit = next((n for n in names if tests & set(n.split("."))), None)
            if hit:
                found.append((f.relative_to(root).as_posix(), node.lineno, hit))
    return [f"{f}:{line}: {name}" for f, line, name in sorted(found)]


def test_the_scan_sees_a_test_importing_a_test(tmp_path):
    (tmp_path / "room").mkdir()
    (tmp_path / "room" / "test_a.py").write_text("import numpy\nfrom models.shared import helper\n")
    (tmp_path / "room" / "test_b.py").write_text(
        "import os\n\n\ndef test_x():\n    from room.test_a import helper\n")
    (tmp_path / "test_c.py").write_text("import test_a as ta\nfrom . import test_b\nfrom conftest import f\n")
    (tmp_path / "models.py").write_text("import test_a\n")      # not a test module: not scanned
    assert imports_of_tests(tmp_path) == ["room/test_b.py:5: room.test_a",
                                          "test_c.py:1: test_a", "test_c.py:2: test_b",
                                          "test_c.py:3: conftest"]


def test_no_test_module_imports_another():
    assert len(list(TESTS.rglob("test_*.py"))) > 60
    assert imports_of_tests(TESTS) == []


def test_every_test_module_is_in_a_folder_of_the_package():
    assert sorted(f.name for f in TESTS.glob("test_*.py")) == []
