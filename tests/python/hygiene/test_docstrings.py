# The Python reference (docs/reference.md, autodoc + napoleon) is complete: every public function,
# method and class of the modules it lists (dmi, dmi.kernels, dmi.analysis, dmi_sweep and their
# documented submodules) has a NumPy-style docstring whose Parameters section names each of its
# parameters, a Returns (or Yields) section when it returns something, and, for a dataclass, an
# Attributes section naming each field.  The sections are read as napoleon reads them: a title
# line over a line of dashes.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dataclasses
import importlib
import inspect
import os
import re
import sys
from pathlib import Path
from typing import Any

import pytest

SOURCE = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[3]))
#: The modules of the Python reference: its automodule directives.
MODULES = re.findall(r"^\.\. automodule:: (\S+)", (SOURCE / "docs" / "reference.md").read_text(),
                     re.M)
#: Names whose docstring serves something else, with the reason.
EXEMPT = {"dmi.kernels.main": "its docstring is dmi-kernel-fit's argparse description (--help)"}


def sections(doc: str | None) -> dict[str, list[str]]:
    """Section title -> its lines, of a docstring in NumPy style (napoleon's headers: a title
    line followed by a line of as many dashes or more)."""
    lines = inspect.cleandoc(doc or "").splitlines()
    out: dict[str, list[str]] = {}
    title = None
    i = 0
    while i < len(lines):
        line = lines[i]
        under = lines[i + 1].strip() if i + 1 < len(lines) else ""
        if line.strip() and re.fullmatch(r"-{3,}", under) and len(under) >= len(line.strip()):
            title = line.strip()
            out[title] = []
            i += 2
            continue
        if title is not None:
            out[title].append(line)
        i += 1
    return out


def entries(lines: list[str]) -> set[str]:
    """The names an Attributes or Parameters section describes: the unindented lines
    ``name : type`` or ``a, b : type`` (or a bare ``name``); ``*args`` as ``args``."""
    names: set[str] = set()
    for line in lines:
        if line and not line[0].isspace():
            for name in line.split(" : ")[0].split(","):
                names.add(name.strip().lstrip("*").strip("`"))
    return names


def public(module: Any) -> list[tuple[str, Any]]:
    """The module's public functions and classes: its __all__, or the names not starting with _
    defined in it."""
    names = getattr(module, "__all__", None)
    if names is None:
        names = [k for k, v in vars(module).items() if not k.startswith("_")
                 and getattr(v, "__module__", None) == module.__name__]
    return [(f"{module.__name__}.{k}", getattr(module, k)) for k in names
            if inspect.isclass(getattr(module, k)) or inspect.isfunction(getattr(module, k))]


def signature_names(f: Any, skip_first: bool) -> list[str]:
    params = list(inspect.signature(f).parameters.values())
    return [p.name for p in params[1 if skip_first else 0:]]


def function_problems(name: str, f: Any, method: bool) -> list[str]:
    """What the docstring of the function or method f lacks."""
    doc = sections(f.__doc__)
    problems = []
    wanted = signature_names(f, method)
    if wanted:
        missing = set(wanted) - entries(doc.get("Parameters", []))
        if missing:
            problems.append(f"{name}: Parameters lacks {sorted(missing)}")
    ret = inspect.signature(f).return_annotation
    returns = ret not in (None, "None", inspect.Signature.empty)
    if returns and not ({"Returns", "Yields"} & set(doc)):
        problems.append(f"{name}: no Returns section")
    return problems


def class_problems(name: str, cls: type) -> list[str]:
    """What the docstrings of the class cls and of its public methods lack: the class's
    Parameters (its own __init__'s, in the class docstring or in __init__'s), a dataclass's
    Attributes."""
    doc = sections(cls.__doc__)
    problems = []
    if dataclasses.is_dataclass(cls):
        fields = {fl.name for fl in dataclasses.fields(cls) if not fl.name.startswith("_")}
        missing = fields - entries(doc.get("Attributes", []))
        if missing:
            problems.append(f"{name}: Attributes lacks {sorted(missing)}")
    elif "__init__" in vars(cls):
        wanted = signature_names(cls.__init__, True)
        missing = (set(wanted) - entries(doc.get("Parameters", []))
                   - entries(sections(cls.__init__.__doc__).get("Parameters", [])))
        if wanted and missing:
            problems.append(f"{name}: Parameters (of the class) lacks {sorted(missing)}")
    for key, value in vars(cls).items():
        if key.startswith("_"):
            continue
        if isinstance(value, (staticmethod, classmethod)):
            problems += function_problems(f"{name}.{key}", value.__func__,
                                          isinstance(value, classmethod))
        elif inspect.isfunction(value):
            problems += function_problems(f"{name}.{key}", value, True)
    return problems


def problems_of(module_name: str) -> list[str]:
    module = importlib.import_module(module_name)
    out = []
    for name, obj in public(module):
        if name in EXEMPT:
            continue
        if inspect.isclass(obj):
            out += class_problems(name, obj)
        else:
            out += function_problems(name, obj, False)
    return out


def test_the_reference_lists_the_packages() -> None:
    assert {"dmi", "dmi.kernels", "dmi.analysis", "dmi_sweep"} <= set(MODULES)


@pytest.mark.parametrize("module_name", MODULES)
def test_public_names_have_their_sections(module_name: str) -> None:
    if module_name.startswith("dmi_sweep"):
        pytest.importorskip("fmpy")
        pytest.importorskip("dask.distributed")
        if str(SOURCE / "python") not in sys.path:
            sys.path.append(str(SOURCE / "python"))   # after the build's dmi: dmi_sweep from it
    elif module_name.startswith("dmi.analysis"):
        pytest.importorskip("scipy")
        pytest.importorskip("bokeh")
    problems = problems_of(module_name)
    assert not problems, "\n".join(problems)


def test_the_check_sees_a_missing_parameter() -> None:
    def documented(a: int, b: float) -> float:
        """Sum.

        Parameters
        ----------
        a, b : float
            Terms.

        Returns
        -------
        float
        """
        return a + b

    def undocumented(a: int, b: float) -> float:
        """Sum.

        Parameters
        ----------
        a : int
            First term.
        """
        return a + b

    assert function_problems("documented", documented, False) == []
    assert function_problems("undocumented", undocumented, False) == [
        "undocumented: Parameters lacks ['b']", "undocumented: no Returns section"]
