# Sphinx configuration of dmi's documentation site.  scripts/docs.sh copies docs/ into a staging
# folder, generates there the FMU variable tables from the built FMUs' model descriptions and
# builds the HTML with warnings as errors, with
# - the C API (c-api.md) from the comments of include/*.h by hawkmoth (libclang);
# - the Python reference (reference.md) from the docstrings by autodoc and napoleon;
# - the gallery from examples/python/plot_*.py by sphinx-gallery, which runs every example (a
#   failing example fails the build) and keeps its figures and printed output;
# - the maths written as $...$ and $$...$$ (myst's dollarmath and amsmath), typeset in the reader's
#   browser by the MathJax that the package sphinx-mathjax-offline ships and copies into the site.
# The environment variable DMI_SOURCE_DIR names the checkout (default: the folder above this file).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import re
from pathlib import Path

SOURCE = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[1])).resolve()

project = "dmi"
author = "the dmi authors"
copyright = "2026, the dmi authors (GPL-3.0-or-later)"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "hawkmoth",
              "sphinx_gallery.gen_gallery", "sphinx-mathjax-offline"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["gen", "requirements.txt", "README.md"]
myst_enable_extensions = ["deflist", "dollarmath", "amsmath"]
myst_heading_anchors = 3
html_theme = "alabaster"
html_title = "dmi documentation"
html_theme_options = {"page_width": "1100px", "body_max_width": "none"}
html_show_sourcelink = False
html_static_path = ["_static"]
html_css_files = ["custom.css"]
# an unknown TeX command is an error (MathJax marks it, tests/docs/browser_check.py finds it), not red text
mathjax3_config = {"tex": {"packages": {"[-]": ["noundefined"]}}}

# ---- the C API: hawkmoth ------------------------------------------------------------------------
hawkmoth_root = str(SOURCE / "include")
hawkmoth_clang = [f"-I{SOURCE / 'include'}", "-DDMI_BUILDING_SHARED"]
hawkmoth_compiler = "clang"     # its standard include path (stddef.h, stdint.h); scripts/deps.sh installs it


def header_text(app, lines: list[str], transform, options) -> None:
    """The headers' comments are plain text: paragraphs, "- " list items (continued by lines
    indented by 2), other indented lines (formulas, tables) and "---- title ----" section lines.
    Turns them into reStructuredText: indented runs become literal blocks, titles rubrics, and in
    the rest the characters reST would read as markup are escaped."""
    if len(lines) > 1:      # hawkmoth leaves the " * " of a last line that also holds the "*/"
        lines[-1] = re.sub(r"^\s*\* ?", "", lines[-1])
    out: list[str] = []
    literal = item = False
    for line in lines:
        title = re.fullmatch(r"\s*-{3,}\s*(.*?)\s*-{3,}\s*", line)
        if re.fullmatch(r"-{3,}", line.strip()) and out and out[-1].strip():   # "Title" over "-----"
            out[-1:] = ["", f".. rubric:: {out[-1]}", ""]
        elif title:
            out += ["", f".. rubric:: {title.group(1).capitalize()}", ""]
            literal = item = False
        elif not line.strip():
            out.append("")
            item = False
        elif line.startswith("  ") and not (item and not line.startswith("    ")):
            if not literal:
                out += ["", ".. code-block:: text", ""]
                literal = True
            out.append("    " + line)
        else:
            if literal:
                out.append("")
            literal = False
            item = item or line.startswith("- ")
            out.append(re.sub(r"([\\`*_|<>\[\]])", r"\\\1", line))
    lines[:] = out


def plain_bars(app, what, name, obj, options, lines: list[str]) -> None:
    """The docstrings write absolute values as |x| (as the C headers do), which reST would read
    as substitutions: a | outside ``literals`` and `roles` is escaped."""
    for i, line in enumerate(lines):
        parts = re.split(r"(``.*?``|`[^`]*`)", line)
        lines[i] = "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(parts))


def setup(app) -> None:
    app.connect("hawkmoth-process-docstring", header_text)
    app.connect("autodoc-process-docstring", plain_bars)


# ---- the Python reference: autodoc + napoleon ----------------------------------------------------
autodoc_default_options = {"members": True, "undoc-members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
napoleon_google_docstring = False
napoleon_numpy_docstring = True

# ---- the gallery: sphinx-gallery -----------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(SOURCE / "examples" / "python"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",          # run every gallery example
    "ignore_pattern": r"^(?!plot_)",        # the programs beside them (orbit_tau.py, ...) are not in it
    "abort_on_example_error": True,         # a failing example fails the build
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "show_memory": False,
    "show_signature": False,
    "min_reported_time": 0,
    "write_computation_times": False,     # its pages load jQuery and DataTables from CDNs
}
