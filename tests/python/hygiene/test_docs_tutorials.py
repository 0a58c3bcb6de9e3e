# The manual's tutorials run, and the analysis and identify pages stay short:
# - every ```python block of each tutorial page (docs/tutorial-*.md), taken in the page's order and
#   run as one script in a fresh Python process (MPLBACKEND=Agg, one BLAS thread, a scratch folder
#   as its working directory) with a time limit, exits with status 0;
# - the tutorials are the pages listed in TUTORIALS, in the order docs/index.md lists them;
# - no page of dmi.analysis and dmi.identify (the tutorials, the analysis-*.md and identify-*.md
#   pages of the method, checks, limits and cost, and the entry pages orbits.md, stability.md,
#   identify.md) is longer than 400 lines, no tutorial longer than 250.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[3]))
DOCS = ROOT / "docs"
# the order a newcomer reads them in (docs/index.md lists them so)
TUTORIALS = ("tutorial-simulate.md", "tutorial-equilibria.md", "tutorial-orbits.md",
             "tutorial-collocation.md", "tutorial-continuation.md", "tutorial-identify.md")
ENTRY_PAGES = ("orbits.md", "stability.md", "identify.md")
MAX_TUTORIAL, MAX_PAGE = 250, 400
TIME_LIMIT = 180.0          # seconds a tutorial may take (each takes well under a minute)
FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)


def python_blocks(text: str) -> list[str]:
    """The bodies of the ```python blocks of a Markdown text, in order."""
    return [m.group(1) for m in FENCE.finditer(text)]


def run_blocks(blocks: list[str], folder: Path, limit: float = TIME_LIMIT) -> subprocess.CompletedProcess:
    """Runs the blocks as one script in a fresh process in folder; kills its process group and
    fails the test when it exceeds limit seconds."""
    script = folder / "tutorial.py"
    script.write_text("\n".join(blocks), encoding="utf-8")
    env = dict(os.environ, MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
    proc = subprocess.Popen([sys.executable, str(script)], cwd=folder, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=limit)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        pytest.fail(f"{script} did not finish within {limit} s")
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def analysis_pages() -> list[Path]:
    """The pages of dmi.analysis and dmi.identify."""
    pages = {DOCS / name for name in ENTRY_PAGES}
    for pattern in ("tutorial-*.md", "analysis-*.md", "identify-*.md"):
        pages.update(DOCS.glob(pattern))
    return sorted(pages)


def test_the_extraction_runs_blocks_in_order_and_a_broken_block_fails(tmp_path):
    text = ("intro\n```python\nx = 2\n```\ntext\n```sh\nexit 1\n```\n"
            "```python\nassert x == 2\nprint('ran', x)\n```\n")
    blocks = python_blocks(text)
    assert blocks == ["x = 2\n", "assert x == 2\nprint('ran', x)\n"]
    ok = run_blocks(blocks, tmp_path)
    assert ok.returncode == 0 and ok.stdout == "ran 2\n"
    broken = run_blocks(blocks + ["raise ValueError('a broken block')\n"], tmp_path)
    assert broken.returncode != 0 and "a broken block" in broken.stderr


def test_the_tutorials_are_the_pages_named_and_the_index_lists_them_in_order():
    found = sorted(p.name for p in DOCS.glob("tutorial-*.md"))
    assert found == sorted(TUTORIALS)
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    where = [index.find("\n" + name[:-3] + "\n") for name in TUTORIALS]
    assert all(w >= 0 for w in where), dict(zip(TUTORIALS, where))
    assert where == sorted(where)


@pytest.mark.parametrize("name", TUTORIALS)
def test_every_python_block_of_a_tutorial_runs(name, tmp_path):
    blocks = python_blocks((DOCS / name).read_text(encoding="utf-8"))
    assert blocks, f"{name} has no python block"
    done = run_blocks(blocks, tmp_path)
    assert done.returncode == 0, f"{name}: exit status {done.returncode}\n{done.stderr[-3000:]}"


def test_no_analysis_or_identify_page_is_too_long():
    pages = analysis_pages()
    assert len(pages) > len(ENTRY_PAGES) + len(TUTORIALS)        # the method, checks, limits pages
    long = []
    for page in pages:
        lines = page.read_text(encoding="utf-8").count("\n")
        limit = MAX_TUTORIAL if page.name in TUTORIALS else MAX_PAGE
        if lines > limit:
            long.append(f"{page.name}: {lines} lines (at most {limit})")
    assert not long, "\n".join(long)
