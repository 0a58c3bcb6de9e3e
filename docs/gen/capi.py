#!/usr/bin/env python3
# Writes the C API reference (MyST Markdown) from the comments of public headers:
#   capi.py include/*.h > c-api.md
# Every comment that stands right before declarations documents them: DMI_API functions,
# typedefs, #define macros and enum constants (each constant's own trailing comment too).
# A comment "---- title ----" opens a section; other comments followed by no declaration
# are section text.  The comment text is shown as written: paragraphs, "- " lists and
# indented lines (formulas, tables) as literal blocks.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import re
import sys
from pathlib import Path

TOKEN = re.compile(r"/\*.*?\*/"                                  # a comment
                   r"|enum\s*\{.*?\}\s*;"                        # an enum block (with its comments)
                   r"|#[ \t]*\w+[^\n]*(?:\\\n[^\n]*)*"           # a preprocessor line
                   r"|typedef[^;]*;"                             # a typedef
                   r"|DMI_API[^;]*;", re.S)                      # an exported function
SECTION = re.compile(r"^-{3,}\s*(.*?)\s*-{3,}\s*$")


def comment_text(c: str) -> str:
    """The text of a /* */ comment without its frame and leading stars, dedented."""
    body = c[2:-2]
    lines = body.split("\n")     # the first line's text follows "/*"; the others may start with " * "
    lines = lines[:1] + [re.sub(r"^\s*\* ?", "", ln) if re.match(r"^\s*\*(?!/)", ln) else ln for ln in lines[1:]]
    while lines and not lines[0].strip():
        lines.pop(0)
    while lines and not lines[-1].strip():
        lines.pop()
    indent = min((len(ln) - len(ln.lstrip()) for ln in lines if ln.strip()), default=0)
    return "\n".join(ln[indent:] if ln.strip() else "" for ln in lines)


def escape(s: str) -> str:
    """Markdown-inert text."""
    return re.sub(r"([\\`*_\[\]<>#|{}~])", r"\\\1", s)


def render(text: str) -> str:
    """A comment's text as Markdown: paragraphs, lists, literal blocks for indented lines."""
    out, para, lit, item = [], [], [], []

    def flush():
        if para:
            out.append(escape(" ".join(para)) + "\n")
            para.clear()
        if item:
            out.append("- " + escape(" ".join(item[0])) + "\n")
            item.clear()
        if lit:
            out.append("```text\n" + "\n".join(lit) + "\n```\n")
            lit.clear()

    lines = text.split("\n")
    for i, ln in enumerate(lines):
        if not ln.strip():
            flush()
            continue
        if re.match(r"^-{3,}$", ln.strip()):          # an underline: the paragraph above is a title
            title = " ".join(para)
            para.clear()
            flush()
            out.append(f"**{escape(title)}**\n")
            continue
        if ln.startswith("- "):
            flush()
            item.append([ln[2:].strip()])
            continue
        if item and ln.startswith("  ") and not ln.startswith("    "):
            item[0].append(ln.strip())
            continue
        if ln.startswith("  ") or (para == [] and not item and re.match(r"^[A-Z_]+\s{2,}", ln)):
            if para or item:
                flush()
            lit.append(ln)
            continue
        if lit:
            flush()
        if item:
            flush()
        para.append(ln.strip())
    flush()
    return "\n".join(out)


def names(code: str) -> list[tuple[str, str]]:
    """(kind, name) of each declaration in a stretch of code."""
    found = []
    for m in TOKEN.finditer(code):
        t = m.group(0)
        if t.startswith("DMI_API"):
            found.append(("function", re.search(r"(\w+)\s*\(", t).group(1)))
        elif t.startswith("typedef"):
            fn = re.search(r"\(\s*\*\s*(\w+)\s*\)", t)
            found.append(("type", fn.group(1) if fn else re.search(r"(\w+)\s*;$", t).group(1)))
        elif t.startswith("enum"):
            for c in re.finditer(r"\b([A-Z][A-Z0-9_]*)\s*=", t):
                found.append(("constant", c.group(1)))
        elif re.match(r"#\s*define\s+(\w+)", t):
            found.append(("macro", re.match(r"#\s*define\s+(\w+)", t).group(1)))
    seen, unique = set(), []
    for kind, name in found:
        if name not in seen:
            seen.add(name)
            unique.append((kind, name))
    return unique


def constants_table(code: str) -> str:
    rows = ["| constant | value | meaning |", "|---|---|---|"]
    for m in re.finditer(r"\b([A-Z][A-Z0-9_]*)\s*=\s*([^,/}\n]+?)\s*,?\s*(/\*.*?\*/)?\s*(?=\n|\})", code, re.S):
        meaning = " ".join(comment_text(m.group(3)).split()) if m.group(3) else ""
        rows.append(f"| `{m.group(1)}` | `{m.group(2).strip()}` | {escape(meaning)} |")
    return "\n".join(rows) + "\n"


def declarations(code: str) -> str:
    """The declarations as written (blank lines dropped; #if/#else kept around macros only)."""
    keep = [m.group(0) for m in TOKEN.finditer(code) if not m.group(0).startswith("/*")]
    if not any(re.match(r"#\s*define", k) for k in keep):    # conditionals only around macros
        keep = [k for k in keep if not k.startswith("#")]
    keep = [re.sub(r"/\*.*?\*/", "", k, flags=re.S) if k.startswith("enum") else k for k in keep]
    keep = [re.sub(r"\n\s*\n", "\n", k) for k in keep]
    keep = ["\n".join(ln.rstrip() for ln in k.split("\n")) for k in keep]
    return "```c\n" + "\n".join(keep) + "\n```\n"


def target(name: str, taken: set[str]) -> str:
    """The anchor of a name: the name itself, or NAME-macro when another name differs from it only in
    case (HTML ids are lower case: the macro DMI_FMU_VARIABLE beside the type dmi_fmu_variable)."""
    key = name.lower()
    if key in taken:
        name, key = name + "-macro", key + "-macro"
    taken.add(key)
    return name


def header(path: Path, root: Path, taken: set[str]) -> str:
    text = path.read_text()
    guard = re.search(r"#ifndef\s+(\w+)\s*\n\s*#define\s+\1\b", text)
    # pieces: (comment, the code after it up to the next comment); enum blocks stay whole
    pieces, last, pending = [], 0, None
    for m in TOKEN.finditer(text):
        if m.group(0).startswith("/*"):
            if pending is not None:
                pieces.append((pending, text[last:m.start()]))
            pending, last = m.group(0), m.end()
    if pending is not None:
        pieces.append((pending, text[last:]))
    rel = path.relative_to(root) if path.is_relative_to(root) else path
    out = [f"## {path.name}\n", f"`{rel}`: `#include <{path.name}>`\n"]
    in_section = False      # entries before the first section are one heading level higher
    for i, (c, code) in enumerate(pieces):
        decl = [(k, n) for k, n in names(code) if not (guard and n == guard.group(1))]
        body = comment_text(c)
        first = body.split("\n", 1)[0].strip()
        sec = SECTION.match(first)
        if sec:
            in_section = True
            out.append(f"### {sec.group(1).capitalize()}\n")
            rest = body.split("\n", 1)[1] if "\n" in body else ""
            if rest.strip():
                out.append(render(comment_text("/*" + rest + "*/")))
        if not decl:
            if not sec and (i == 0 or len(body.split()) > 3):
                out.append(render(body))
            continue
        if sec:  # a section comment directly before declarations documents only the section
            body = ""
        listed = [n for k, n in decl if k != "constant"]
        title = ", ".join(listed) if listed else first.rstrip(".")
        for _, n in decl:
            out.append(f"({target(n, taken)})=")
        out.append(f"{'####' if in_section else '###'} {escape(title)}\n")
        out.append(declarations(code))
        if body and (listed or body != first):      # a one-line group title is not repeated
            out.append(render(body))
        if any(k == "constant" for k, _ in decl):
            out.append(constants_table(code))
    return "\n".join(out)


def main(argv: list[str]) -> int:
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print("usage: capi.py HEADER.h... > c-api.md", file=sys.stderr)
        return 2
    paths = [Path(a).resolve() for a in argv[1:]]
    root = Path(__file__).resolve().parents[2]
    print("<!-- Generated by docs/gen/capi.py from the headers' comments; do not edit. -->")
    print("# C API reference\n")
    print("Generated from the comments of the public headers, "
          + ", ".join(f"`include/{p.name}`" for p in paths)
          + ": every exported function (`DMI_API`), type, macro and constant, with the text its header gives "
          "(units, ownership, error codes).\n")
    taken: set[str] = set()
    for p in paths:
        print(header(p, root, taken))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
