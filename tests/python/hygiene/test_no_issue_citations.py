# Comments, docstrings, tests and pages say what the code does, not which issue brought it: no
# "issue N" in the project's sources (a reader of the repository cannot follow the number).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[3]))
CITATION = re.compile(r"\bissues? [0-9]+\b", re.IGNORECASE)
SKIP_DIRS = {".git", ".venv", "out", "node_modules", "__pycache__"}
TEXT = {".c", ".h", ".py", ".f90", ".md", ".rst", ".txt", ".sh", ".toml", ".cmake", ".map", ".in",
        ".json", ".xml"}


def citations(root: Path) -> list[str]:
    found = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in SKIP_DIRS and not d.startswith("build")]
        for name in filenames:
            path = Path(dirpath, name)
            if path.suffix not in TEXT and name not in ("CMakeLists.txt", "run"):
                continue
            try:
                text = path.read_text(encoding="utf-8")
            except (UnicodeDecodeError, OSError):
                continue
            for i, line in enumerate(text.splitlines(), 1):
                if CITATION.search(line):
                    found.append(f"{path.relative_to(root)}:{i}: {line.strip()[:100]}")
    return found


def test_the_scan_finds_a_citation(tmp_path):
    cited = "x = 1  # fixed in " + "Issue" + " 12"      # (not a citation of this file's own)
    (tmp_path / "a.py").write_text(cited + "\n")
    (tmp_path / "b.c").write_text("/* no number here: an issue of rounding */\n")
    assert citations(tmp_path) == ["a.py:1: " + cited]


def test_no_issue_numbers_in_the_sources():
    assert citations(ROOT) == []
