# The shared fixtures of tests/python (the paper's reference folder; libbinding_test.so, the C
# callbacks of binding/meet.c and examples/paper.c) and the layout of its tests, which mirrors the
# package: analysis/<room>/ holds the tests of dmi.analysis.<room> (core, scheme, continuation,
# equilibria, shooting, collocation, plot) and analysis/ those of its structure; identify/,
# kernels/ (with dmi._transform) and binding/ (dmi.Solver, jit=True, the package as pip builds
# it) those of the rest of dmi; hygiene/ those of the source tree as a whole (import circles,
# docstrings, the manual's bytes, issue numbers, test modules importing test modules).  The models,
# references and helpers that several test modules use live in the package models/ (``from
# models.orbit_models import DenHartog``): a test module never imports another test module or this
# file.  Each folder is a package (an __init__.py), so that test modules of one name in two folders
# (identify/test_refusals.py, binding/test_refusals.py) import under distinct names in pytest's
# default import mode (prepend): this folder, which is no package, is the one put on sys.path,
# which makes ``models`` importable.  ctest runs the files as tests/python/CMakeLists.txt groups
# them.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ctypes
import os
from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def reference() -> Path:
    path = Path(os.environ.get("DMI_REFERENCE_DIR", Path(__file__).parents[3] / "shared" / "reference"))
    assert (path / "ex43_N9991.csv").is_file(), f"no reference values in {path}"
    return path


@pytest.fixture(scope="session")
def testlib() -> ctypes.CDLL:
    """libbinding_test.so: the paper's C callbacks (examples/paper.c) and meet_rhs (meet.c)."""
    path = os.environ.get("DMI_BINDING_TESTLIB")
    if not path:
        pytest.skip("DMI_BINDING_TESTLIB not set (ctest sets it)")
    return ctypes.CDLL(path)
