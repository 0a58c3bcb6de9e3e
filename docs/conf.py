# Sphinx configuration of dmi's documentation site.  scripts/docs.sh copies docs/ into a staging
# folder, generates the reference pages (c-api.md from include/, fmu-variables.md from the built
# FMUs' model descriptions) and builds the HTML from there with warnings as errors.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
project = "dmi"
author = "the dmi authors"
copyright = "2026, the dmi authors (GPL-3.0-or-later)"
extensions = ["myst_parser"]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["gen", "requirements.txt", "README.md"]
myst_enable_extensions = ["deflist"]
myst_heading_anchors = 3
html_theme = "alabaster"
html_title = "dmi documentation"
html_theme_options = {"page_width": "1100px", "body_max_width": "none"}
html_show_sourcelink = False
html_static_path = ["_static"]
html_css_files = ["custom.css"]
