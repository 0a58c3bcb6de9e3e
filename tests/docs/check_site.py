#!/usr/bin/env python3
# Checks the built documentation site (scripts/docs.sh builds it into BUILD/docs/html):
#   check_site.py SOURCE_DIR BUILD_DIR
# - the C API reference (c-api.html) has an entry (an element with the name's id) for every DMI_API
#   function, typedef, #define macro and enum constant of include/*.h, found here by regular
#   expressions independently of the generator;
# - the FMU variable reference (fmu-variables.html) has, for every FMU the build produced, a table row
#   with each variable's name, causality, start value and unit (or "dimensionless"), read here from
#   the FMU's own modelDescription.xml;
# - the dmi-sweep page (sweep.html) names every subcommand and option of dmi_sweep.cli's argparse
#   parser and every key of the spec (the *KEYS sets of dmi_sweep.spec);
# - every name of __all__ of every Python package under python/ appears in code in the site;
# - every internal link and image of every page resolves (file and #fragment);
# - headless Chromium renders index.html and c-api.html: the title it reports is the page's, the
#   page has text, and a screenshot is not one colour.
# Prints what it checked; exit status 1 with every failure listed.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import argparse
import ast
import os
import re
import signal
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from collections import Counter
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlparse

FAILURES: list[str] = []


def fail(msg: str) -> None:
    FAILURES.append(msg)
    print("FAIL:", msg)


class Page(HTMLParser):
    """ids, links, images, title, text and table rows of one HTML page."""

    def __init__(self, path: Path):
        super().__init__()
        self.ids, self.links, self.images, self.rows = set(), [], [], []
        self.title, self.text, self.code = "", [], []
        self._in_title = self._skip = self._in_code = 0
        self._row, self._cell = None, None
        self.feed(path.read_text())

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and a.get("href"):
            self.links.append(a["href"])
        if tag == "link" and a.get("href"):
            self.links.append(a["href"])
        if tag in ("img", "script") and a.get("src"):
            (self.images if tag == "img" else self.links).append(a["src"])
        if tag == "title":
            self._in_title = 1
        if tag in ("script", "style"):
            self._skip += 1
        if tag in ("code", "pre"):
            self._in_code += 1
        if tag == "tr":
            self._row = []
        if tag in ("td", "th") and self._row is not None:
            self._cell = []

    def handle_endtag(self, tag):
        if tag == "title":
            self._in_title = 0
        if tag in ("script", "style"):
            self._skip -= 1
        if tag in ("code", "pre"):
            self._in_code -= 1
        if tag in ("td", "th") and self._cell is not None:
            self._row.append(" ".join("".join(self._cell).split()))
            self._cell = None
        if tag == "tr" and self._row is not None:
            self.rows.append(self._row)
            self._row = None

    def handle_data(self, data):
        if self._in_title:
            self.title += data
        if not self._skip:
            self.text.append(data)
            if self._in_code:
                self.code.append(data)
            if self._cell is not None:
                self._cell.append(data)

    def words(self) -> str:
        return " ".join(" ".join(self.text).split())


def header_names(include: Path) -> list[str]:
    names = []
    for h in sorted(include.glob("*.h")):
        text = re.sub(r"/\*.*?\*/", "", h.read_text(), flags=re.S)
        guard = re.search(r"#ifndef\s+(\w+)\s*\n\s*#define\s+\1\b", text)
        names += re.findall(r"(?m)^\s*DMI_API\b[^;(]*?\b(\w+)\s*\(", text)
        names += re.findall(r"typedef[^;]*?\(\s*\*\s*(\w+)\s*\)", text)
        names += re.findall(r"typedef\s+(?:struct|union|enum)\s+\w+\s+(\w+)\s*;", text)
        names += [m for m in re.findall(r"#\s*define\s+(\w+)", text) if not (guard and m == guard.group(1))]
        for body in re.findall(r"enum\s*\w*\s*\{(.*?)\}", text, re.S):
            names += re.findall(r"\b([A-Za-z_]\w*)\s*(?:=[^,]*)?(?:,|$)", body.strip())
    return sorted(set(names))


def c_entries(ids: set[str]) -> set[str]:
    """The names of the C domain's entries among a page's ids: c.NAME, and c.@anonymous_HASH.NAME for
    the constants of an unnamed enum."""
    return {i.rsplit(".", 1)[-1] for i in ids if i.startswith("c.")}


def check_c_api(src: Path, html: Path) -> None:
    page = Page(html / "c-api.html")
    names = header_names(src / "include")
    functions = [n for n in names if n.startswith("dmi_")]
    if len(functions) < 20:
        fail(f"only {len(functions)} names found in include/ (the header parser is broken)")
    words = set(re.findall(r"\w+", page.words()))
    missing = [n for n in names if n not in c_entries(page.ids) or n not in words]
    if missing:
        fail(f"c-api.html has no entry for {', '.join(missing)}")
    print(f"C API: checked the {len(names)} names of include/*.h against c-api.html")


def fmu_rows(md: ET.Element) -> list[tuple[str, str, str, str]]:
    units = {t.get("name"): (t.get("unit") or next((c.get("unit") for c in t if c.get("unit")), None))
             for t in md.iter() if t.tag in ("SimpleType",) or (t.tag.endswith("Type") and t.get("name"))}
    rows = []
    for v in md.find("ModelVariables"):
        attrs = dict(v.attrib)
        if v.tag == "ScalarVariable":
            attrs.update(next(iter(v)).attrib)
        unit = attrs.get("unit") or units.get(attrs.get("declaredType")) or "dimensionless"
        rows.append((attrs["name"], attrs.get("causality", "local"), attrs.get("start", "—"), unit))
    return rows


def check_fmus(build: Path, html: Path) -> None:
    page = Page(html / "fmu-variables.html")
    have = Counter((r[0], r[1], r[4], r[5]) for r in page.rows if len(r) >= 7)
    fmus = sorted(p for p in build.rglob("*.fmu") if "docs" not in p.relative_to(build).parts[:1]
                  and "Testing" not in p.parts)
    if not fmus:
        fail(f"no FMU in {build}")
    want: Counter = Counter()
    for f in fmus:
        with zipfile.ZipFile(f) as z:
            want.update(fmu_rows(ET.fromstring(z.read("modelDescription.xml"))))
    missing = want - have
    if missing:
        fail(f"fmu-variables.html lacks rows (name, causality, start, unit): {sorted(missing)}")
    if not page.words().count("dimensionless"):
        fail("fmu-variables.html says no unit anywhere")
    print(f"FMUs: checked the {sum(want.values())} variables of {len(fmus)} FMUs against fmu-variables.html")


def check_sweep(src: Path, html: Path) -> None:
    sys.path.insert(0, str(src / "python"))
    from dmi_sweep import cli, spec
    words = Page(html / "sweep.html").words()
    wanted = set()

    def walk(p: argparse.ArgumentParser):
        for a in p._actions:
            if isinstance(a, argparse._SubParsersAction):
                for name, sub in a.choices.items():
                    wanted.add(name)
                    walk(sub)
            else:
                wanted.update(o for o in a.option_strings if o.startswith("--") and o != "--help")
    walk(cli.parser())
    for name, value in vars(spec).items():
        if name.endswith("KEYS") and isinstance(value, (set, frozenset, tuple, list)):
            wanted.update(v for v in value if isinstance(v, str))
    missing = sorted(w for w in wanted if not re.search(rf"(?<![\w-]){re.escape(w)}(?![\w-])", words))
    if missing:
        fail(f"sweep.html does not mention {', '.join(missing)}")
    print(f"dmi-sweep: checked {len(wanted)} subcommands, options and spec keys against sweep.html")


def check_python(src: Path, html: Path) -> None:
    site = " ".join(" ".join(Page(p).code) for p in html.rglob("*.html"))     # code spans and blocks
    checked = 0
    for init in sorted((src / "python").rglob("__init__.py")):
        if "tests" in init.parts or init.parent.name.startswith(("_", ".")):
            continue
        tree = ast.parse(init.read_text())
        # __all__ = [...], __all__: list[str] = [...] and __all__ += [...], in the order written
        parts = [node.value for node in tree.body
                 if (isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)) and node.value is not None
                     and any(getattr(t, "id", "") == "__all__"
                             for t in (node.targets if isinstance(node, ast.Assign) else [node.target])))]
        if not parts:
            continue
        try:
            names = [n for part in parts for n in ast.literal_eval(part)]
        except ValueError:      # computed: import the package (from python/ or as installed)
            import importlib
            sys.path.insert(0, str(src / "python"))
            dotted = ".".join(init.parent.relative_to(src / "python").parts)
            names = importlib.import_module(dotted).__all__
        missing = [n for n in names if not re.search(rf"\b{re.escape(n)}\b", site)]
        if missing:
            fail(f"the site does not document {init.parent.name}.{', '.join(missing)}")
        checked += len(names)
    print(f"Python: checked {checked} public names (__all__ of the packages under python/) against the site")


def check_links(html: Path) -> None:
    pages = {p: Page(p) for p in html.rglob("*.html")}
    n = 0
    for p, page in pages.items():
        for ref in page.links + page.images:
            u = urlparse(ref)
            if u.scheme or ref.startswith("//"):
                continue
            target = (p.parent / unquote(u.path)).resolve() if u.path else p
            n += 1
            if not target.exists():
                fail(f"{p.relative_to(html)}: {ref} does not exist")
            elif u.fragment and target.suffix == ".html":
                ids = pages[target].ids if target in pages else Page(target).ids
                if u.fragment not in ids:
                    fail(f"{p.relative_to(html)}: {ref}: no id {u.fragment!r} there")
    print(f"links: checked {n} internal links and images of {len(pages)} pages")


def chromium(args: list[str], timeout: float = 120) -> str:
    cmd = ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
           "--no-first-run", "--hide-scrollbars", *args]
    with tempfile.TemporaryDirectory() as profile:
        p = subprocess.Popen(cmd + [f"--user-data-dir={profile}"], stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL, text=True, start_new_session=True)
        try:
            out, _ = p.communicate(timeout=timeout)
        finally:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
    return out


def check_render(html: Path) -> None:
    import matplotlib.image
    for name, title in (("index.html", "dmi: nonsmooth dynamics with memory — dmi documentation"),
                        ("c-api.html", "C API reference — dmi documentation")):
        url = (html / name).as_uri()
        dom = chromium(["--dump-dom", url])
        m = re.search(r"<title>(.*?)</title>", dom, re.S)
        got = " ".join(m.group(1).split()) if m else None
        if got != title:
            fail(f"chromium: {name} has the title {got!r}, not {title!r}")
        body = re.sub(r"<[^>]+>", " ", re.sub(r"<(script|style)\b.*?</\1>", "", dom, flags=re.S))
        if len(body.split()) < 200:
            fail(f"chromium: {name} shows only {len(body.split())} words")
        with tempfile.TemporaryDirectory() as d:
            shot = Path(d) / "shot.png"
            chromium([f"--screenshot={shot}", "--window-size=1200,900", url])
            if not shot.exists():
                fail(f"chromium: no screenshot of {name}")
                continue
            px = matplotlib.image.imread(shot)
            colours = len({tuple(c) for c in px.reshape(-1, px.shape[-1])[::7].round(3)})
            if colours < 10:
                fail(f"chromium: the screenshot of {name} has {colours} colours")
        print(f"chromium: rendered {name}: title {got!r}, {len(body.split())} words")


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print("usage: check_site.py SOURCE_DIR BUILD_DIR", file=sys.stderr)
        return 2
    src, build = Path(argv[1]).resolve(), Path(argv[2]).resolve()
    html = build / "docs" / "html"
    if not (html / "index.html").exists():
        print(f"no site in {html} (scripts/docs.sh builds it)")
        return 1
    for check in (lambda: check_c_api(src, html), lambda: check_fmus(build, html),
                  lambda: check_sweep(src, html), lambda: check_python(src, html),
                  lambda: check_links(html), lambda: check_render(html)):
        check()
    print(f"{len(FAILURES)} failures")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
