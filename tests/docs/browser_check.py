#!/usr/bin/env python3
# Checks the built documentation site (scripts/docs.sh builds it into BUILD/docs/html) as a reader's
# browser shows it: Debian's headless Chromium, driven through its DevTools protocol, with no network
# (every request to a host goes to a closed port on 127.0.0.1) and the page's requests logged.
#   browser_check.py SOURCE_DIR BUILD_DIR CHECK...
# CHECK is one or more of
#   maths    every page of the site: once MathJax has typeset it, every maths element holds its
#            rendering, none is a TeX error, and the text the reader sees has no TeX left (no
#            \( \) \[ \] $$, no \command); the pages of MATH_PAGES have at least 5 maths elements;
#   capi     c-api.html has an entry (the C domain's id c.NAME) with its name shown for every symbol
#            that libdmi exports (the global: names of src/libdmi.map) and every type that a public
#            header declares (typedef and struct names of include/*.h, read here by regex);
#   python   reference.html has an entry (id dmi.NAME, dmi.analysis.NAME) shown for every name of
#            dmi.__all__ and dmi.analysis.__all__ (imported from the build, BUILD/python);
#   offline  every page of the site loads nothing from outside the site folder: the network log of
#            each page has only file: URLs inside BUILD/docs/html (and data:/blob:/about: ones),
#            and no request failed;
#   figures  dmi.analysis's interactive HTML figures, written here (into a temporary folder) from
#            the small model of tests/python/models/interactive_models.py, no site needed: hovering a
#            point of the orbit branch shows its p and period, clicking it makes the orbit panel's
#            lines draw that point's BranchPoint.t and .u; hovering a point of the branch of
#            equilibria and a cell of the chart shows its rightmost root; a branch of equilibria
#            has no orbit panel; nothing loads from outside the folder (the network log).
# The browser is started by this script and stopped (its process group killed) before it exits.
# Prints what it checked; exit status 1 with every failure listed, 2 for bad usage.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ctypes
import importlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np
import websocket

FAILURES: list[str] = []
MATH_PAGES = ("mathematics.html", "paper.html", "stability.html", "orbits.html", "python.html",
              "analysis-method-equilibria.html", "analysis-method-shooting.html",
              "analysis-method-continuation.html", "identify-method.html", "tutorial-simulate.html")


def fail(msg: str) -> None:
    FAILURES.append(msg)
    print("FAIL:", msg)


def die_with_parent() -> None:
    """In a child before it runs its program: SIGKILL it when the process that started it dies
    (Linux's PR_SET_PDEATHSIG), so that a check killed from outside (a test's timeout, a kill -9)
    leaves no browser behind; its own children follow it."""
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)     # 1: PR_SET_PDEATHSIG


class Browser:
    """Headless Chromium with one page, through the DevTools protocol (a websocket)."""

    def __init__(self, timeout: float = 60.0):
        exe = shutil.which("chromium")
        if exe is None:
            raise SystemExit("no chromium on PATH (scripts/docs.sh --install installs it)")
        self.profile = tempfile.TemporaryDirectory()
        # no network: every host is mapped to a closed port of the loopback, and a proxy that does
        # not exist stands before everything else; file: URLs are not affected
        cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
               "--no-first-run", "--no-default-browser-check", "--disable-extensions",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--proxy-server=http://127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
               "--host-resolver-rules=MAP * 127.0.0.1:9", "--remote-debugging-port=0",
               f"--user-data-dir={self.profile.name}", "about:blank"]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                     text=True, start_new_session=True,
                                     preexec_fn=die_with_parent)
        url, t0 = None, time.monotonic()
        while url is None and time.monotonic() - t0 < timeout:
            line = self.proc.stderr.readline()
            if not line and self.proc.poll() is not None:
                break
            m = re.search(r"DevTools listening on (ws://\S+)", line)
            url = m.group(1) if m else None
        if url is None:
            self.close()
            raise SystemExit("chromium did not start its DevTools endpoint")
        self.ws = websocket.create_connection(url, timeout=timeout)
        self.timeout, self.next_id, self.events = timeout, 0, []
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Page", "Network", "Runtime"):
            self.call(f"{domain}.enable", session=True)

    def call(self, method: str, session: bool = False, **params) -> dict:
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params}
        if session:
            msg["sessionId"] = self.session
        self.ws.send(json.dumps(msg))
        t0 = time.monotonic()
        while time.monotonic() - t0 < self.timeout:
            reply = json.loads(self.ws.recv())
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)
        raise TimeoutError(method)

    def wait_event(self, method: str) -> dict:
        t0 = time.monotonic()
        while time.monotonic() - t0 < self.timeout:
            for k, e in enumerate(self.events):
                if e.get("method") == method:
                    return self.events.pop(k)
            self.events.append(json.loads(self.ws.recv()))
        raise TimeoutError(method)

    def open(self, url: str) -> list[dict]:
        """Loads url and waits for its load event; returns the network events of the load."""
        self.events.clear()
        self.call("Page.navigate", session=True, url=url)
        self.wait_event("Page.loadEventFired")
        return [e for e in self.events if e.get("method", "").startswith("Network.")]

    def eval(self, js: str):
        """The value of a JavaScript expression in the page (a promise is awaited)."""
        r = self.call("Runtime.evaluate", session=True, expression=js, awaitPromise=True,
                      returnByValue=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{js[:60]}...: {r['exceptionDetails'].get('text')}: "
                               f"{r['exceptionDetails'].get('exception', {}).get('description')}")
        return r["result"].get("value")

    def mouse(self, kind: str, x: float, y: float) -> None:
        """A real mouse event at page coordinates (x, y) (CSS pixels of the viewport): "move" (a
        hover), or "click" (press and release of the left button)."""
        if kind == "move":
            self.call("Input.dispatchMouseEvent", session=True, type="mouseMoved", x=x, y=y)
        elif kind == "click":
            for t in ("mousePressed", "mouseReleased"):
                self.call("Input.dispatchMouseEvent", session=True, type=t, x=x, y=y,
                          button="left", clickCount=1)
        else:
            raise ValueError(f"mouse event {kind!r}: 'move' or 'click'")

    def close(self) -> None:
        try:
            if getattr(self, "ws", None) is not None:
                self.ws.close()
        finally:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            self.proc.wait()
            self.proc.stderr.close()
            self.profile.cleanup()


# the text the reader sees outside code, once MathJax has run, and the state of the maths elements
MATHS_JS = """(async () => {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) await MathJax.startup.promise;
  if (window.MathJax && MathJax.typesetPromise) await MathJax.typesetPromise();
  const maths = [...document.querySelectorAll('.math')];
  const body = document.querySelector('div.body') || document.body;
  const copy = body.cloneNode(true);
  copy.querySelectorAll('pre, code, .highlight, mjx-container, script, style').forEach(e => e.remove());
  return {mathjax: !!(window.MathJax && MathJax.version), version: window.MathJax ? MathJax.version : null,
          maths: maths.length,
          rendered: maths.filter(e => e.querySelector('mjx-container')).length,
          errors: [...document.querySelectorAll('mjx-merror')].map(e => e.getAttribute('data-mjx-error') || e.textContent),
          text: copy.innerText};
})()"""

RAW_TEX = re.compile(r"\\[()\[\]]|\$\$|\\(?:[a-zA-Z]+)\b|\$[^$\s][^$]*\$")


def site_pages(html: Path) -> list[str]:
    """Every page of the site (its HTML files but Sphinx's index, search and module pages and the
    static files), relative to html."""
    skip = {"genindex.html", "search.html", "py-modindex.html"}
    return sorted(str(p.relative_to(html)) for p in html.rglob("*.html")
                  if p.name not in skip and not any(part.startswith("_") for part in
                                                    p.relative_to(html).parts))


def check_maths(b: Browser, html: Path) -> None:
    pages = site_pages(html)
    missing = [name for name in MATH_PAGES if name not in pages]
    if missing:
        fail(f"pages with maths missing from the site: {missing}")
    for name in pages:
        b.open((html / name).as_uri())
        r = b.eval(MATHS_JS)
        if r["maths"] and not r["mathjax"]:
            fail(f"{name}: MathJax did not load")
        if name in MATH_PAGES and r["maths"] < 5:
            fail(f"{name}: only {r['maths']} maths elements (the page's maths is not written as maths)")
        if r["rendered"] != r["maths"]:
            fail(f"{name}: {r['maths'] - r['rendered']} of {r['maths']} maths elements not typeset")
        if r["errors"]:
            fail(f"{name}: TeX errors: {r['errors'][:5]}")
        raw = sorted({m.group(0) for m in RAW_TEX.finditer(r["text"])})
        if raw:
            fail(f"{name}: raw TeX in the text the reader sees: {raw[:10]}")
        print(f"maths: {name}: MathJax {r['version']}, {r['rendered']}/{r['maths']} maths elements "
              f"typeset, {len(r['errors'])} errors, {len(raw)} raw TeX pieces")


def exported_symbols(map_file: Path) -> list[str]:
    """The names of the global: parts of the linker version script."""
    text = re.sub(r"/\*.*?\*/", "", map_file.read_text(), flags=re.S)
    names = []
    for block in re.findall(r"global:(.*?)(?:local:|\})", text, flags=re.S):
        names += re.findall(r"([A-Za-z_]\w*)\s*;", block)
    return names


def header_types(include: Path) -> list[str]:
    names = set()
    for h in include.glob("*.h"):
        text = re.sub(r"/\*.*?\*/", "", h.read_text(), flags=re.S)
        names.update(re.findall(r"typedef[^;]*?\(\s*\*\s*(\w+)\s*\)", text))          # function types
        names.update(re.findall(r"typedef\s+(?:struct|union|enum)\s+\w+\s+(\w+)\s*;", text))
        names.update(re.findall(r"typedef\s+[\w\s*]+?\b(\w+)\s*;", text))
        names.update(re.findall(r"^\s*struct\s+(\w+)\s*\{", text, flags=re.M))
    return sorted(names)


ENTRIES_JS = """(() => {
  const ids = {};
  document.querySelectorAll('dt[id]').forEach(e => { ids[e.id] = e.innerText; });
  return ids;
})()"""


def check_capi(b: Browser, src: Path, html: Path) -> None:
    symbols = exported_symbols(src / "src" / "libdmi.map")
    types = header_types(src / "include")
    if len(symbols) < 20 or len(types) < 5:
        fail(f"only {len(symbols)} exported symbols and {len(types)} types found (the parsers are broken)")
    b.open((html / "c-api.html").as_uri())
    entries = b.eval(ENTRIES_JS)
    shown = {}
    for i, text in entries.items():
        if i.startswith("c."):
            shown[i.rsplit(".", 1)[-1]] = text
    missing = [n for n in symbols + types
               if n not in shown or not re.search(rf"\b{re.escape(n)}\b", shown[n])]
    if missing:
        fail(f"c-api.html has no entry for {', '.join(missing)}")
    print(f"capi: c-api.html shows the {len(symbols)} symbols of src/libdmi.map and the "
          f"{len(types)} types of include/*.h ({len(shown)} C entries on the page)")


def check_python(b: Browser, build: Path, html: Path) -> None:
    sys.path.insert(0, str(build / "python"))
    b.open((html / "reference.html").as_uri())
    entries = b.eval(ENTRIES_JS)
    total = 0
    for module in ("dmi", "dmi.analysis"):
        names = importlib.import_module(module).__all__
        missing = [n for n in names if f"{module}.{n}" not in entries
                   or not re.search(rf"\b{re.escape(n)}\b", entries[f"{module}.{n}"])]
        if missing:
            fail(f"reference.html has no entry for {', '.join(f'{module}.{n}' for n in missing)}")
        total += len(names)
    print(f"python: reference.html shows the {total} names of dmi.__all__ and dmi.analysis.__all__")


def outside(events: list[dict], root: Path) -> list[str]:
    """What a page's network log shows besides its own folder: the URLs it requested outside `root`
    (not file:, or a file elsewhere; data:, blob: and about: URLs are inside anything) and the
    requests that failed."""
    bad = []
    root = root.resolve()
    for e in events:
        if e["method"] == "Network.requestWillBeSent":
            url = e["params"]["request"]["url"]
            u = urlparse(url)
            if u.scheme in ("data", "blob", "about"):
                continue
            if u.scheme != "file" or not Path(unquote(u.path)).resolve().is_relative_to(root):
                bad.append(f"loads {url[:120]} from outside {root}")
        elif e["method"] == "Network.loadingFailed":
            bad.append(f"a request failed: {e['params'].get('errorText')}")
    return bad


def check_offline(b: Browser, html: Path) -> None:
    pages = sorted(html.rglob("*.html"))
    requests = 0
    for page in pages:
        events = b.open(page.as_uri())
        if page.name in MATH_PAGES:        # let MathJax load its fonts and components
            b.eval(MATHS_JS)
            events += [e for e in b.events if e.get("method", "").startswith("Network.")]
        requests += sum(e["method"] == "Network.requestWillBeSent" for e in events)
        for msg in outside(events, html):
            fail(f"{page.relative_to(html)} {msg}")
    print(f"offline: {len(pages)} pages made {requests} requests, all inside {html}")


# ---- the interactive figures of dmi.analysis (written here from small models, no site needed) ----
BOKEH_READY_JS = """(async () => {
  for (let k = 0; k < 200; k++) {
    if (window.Bokeh && Bokeh.documents && Bokeh.documents.length && Bokeh.index
        && [...Bokeh.index.roots].length) return Bokeh.version;
    await new Promise(r => setTimeout(r, 50));
  }
  return null;
})()"""

# page coordinates (CSS pixels) of the data point (x, y) in the Bokeh figure of the given name
POINT_JS = """(() => {
  const plot = Bokeh.documents[0].get_model_by_name(%s);
  const view = Bokeh.index.find_one(plot);
  const box = view.canvas_view.el.getBoundingClientRect();
  return [box.left + view.frame.x_scale.compute(%r), box.top + view.frame.y_scale.compute(%r)];
})()"""

# the texts of the visible tooltips (Bokeh draws them inside shadow roots), after waiting for one
TOOLTIP_JS = """(async () => {
  const texts = () => {
    const found = [];
    const walk = root => {
      for (const e of root.querySelectorAll('*')) {
        if (e.classList.contains('bk-tooltip-content') && e.getClientRects().length
            && e.innerText.trim()) found.push(e.innerText);
        if (e.shadowRoot) walk(e.shadowRoot);
      }
    };
    walk(document);
    return found;
  };
  for (let k = 0; k < 40 && !texts().length; k++) await new Promise(r => setTimeout(r, 50));
  return texts().join('\\n');
})()"""

# the data that the orbit panel's lines draw, by the name of the line: [x values, y values]
PLOTTED_JS = """(async () => {
  await new Promise(r => setTimeout(r, 200));
  const plot = Bokeh.documents[0].get_model_by_name('orbit_panel');
  if (!plot) return null;
  const out = {};
  for (const r of plot.renderers) {
    const d = r.data_source.data;
    out[r.name] = [Array.from(d[r.glyph.x.field]), Array.from(d[r.glyph.y.field])];
  }
  return out;
})()"""

NUMBER = r"(-?\d+(?:\.\d*)?(?:e[-+]?\d+)?)"


def hover_text(b: Browser, figure: str, x: float, y: float) -> str:
    """The tooltip shown with the mouse over the data point (x, y) of the named figure (moved
    away first, so the tooltip is the new point's; then onto the point in two moves, the first
    entering the figure's canvas)."""
    b.mouse("move", 1, 1)
    px, py = b.eval(POINT_JS % (json.dumps(figure), float(x), float(y)))
    b.mouse("move", px - 2, py - 2)
    b.mouse("move", px, py)
    return b.eval(TOOLTIP_JS)


def read_field(text: str, name: str, pattern: str = NUMBER) -> re.Match | None:
    """The value shown after "name:" in a tooltip's text."""
    return re.search(rf"{name}\s*:?\s*{pattern}", text)


def shown_root(text: str) -> complex | None:
    """The rightmost root a tooltip shows ("rightmost root: a + bi"), or None."""
    m = read_field(text, "rightmost root", NUMBER + " ([-+]) " + NUMBER + "i")
    return complex(float(m.group(1)), float(m.group(2) + m.group(3))) if m else None


def figure_page(b: Browser, page: Path) -> bool:
    """Opens a figure and waits until BokehJS has drawn it (False, a failure, if it did not)."""
    b.open(page.as_uri())
    if b.eval(BOKEH_READY_JS) is None:
        fail(f"{page.name}: BokehJS did not draw the figure")
        return False
    return True


def check_orbit_branch(b: Browser, branch, page: Path) -> None:
    if not figure_page(b, page):
        return
    pts = branch.points
    y = [q.amplitude[0] for q in pts]      # what an autonomous branch draws against p
    for k in (len(pts) - 1, len(pts) // 2):
        q = pts[k]
        text = hover_text(b, "branch", q.p, y[k])
        period, p = read_field(text, "period"), read_field(text, "p")
        if (period is None or p is None or abs(float(period.group(1)) - q.period) > 1e-5 * q.period
                or abs(float(p.group(1)) - q.p) > 1e-5 * abs(q.p)):
            fail(f"{page.name}: hovering point {k} (p = {q.p:.6g}, period {q.period:.6g}) shows "
                 f"{text!r}")
        mu = read_field(text, "multipliers", NUMBER + " [-+] " + NUMBER + "i")
        if mu is None or abs(float(mu.group(1)) - q.multipliers[0].real) > 1e-5:
            fail(f"{page.name}: hovering point {k} does not show its leading multiplier "
                 f"{q.multipliers[0]:.6g}: {text!r}")
        px, py = b.eval(POINT_JS % ('"branch"', float(q.p), float(y[k])))
        time.sleep(0.5)     # apart from the gestures before (two quick taps: a double tap)
        b.mouse("click", px, py)
        lines = b.eval(PLOTTED_JS) or {}
        for j in range(q.u.shape[1]):
            t, u = (np.array(v) for v in lines.get(f"orbit_u{j}", ([], [])))
            if t.shape != q.t.shape or u.shape != q.u[:, j].shape or not (
                    np.array_equal(t, q.t) and np.array_equal(u, q.u[:, j])):
                fail(f"{page.name}: after a click on point {k} the orbit panel's line u_{j} does "
                     f"not draw BranchPoint.t, .u of that point ({t.shape} values)")
        print(f"figures: {page.name}: point {k} hovered (period {period and period.group(1)}) "
              f"and clicked (orbit panel: its {len(q.t)} samples)")


def check_equilibrium_branch(b: Browser, branch, page: Path) -> None:
    if not figure_page(b, page):
        return
    k = len(branch.points) - 2
    q = branch.points[k]
    text = hover_text(b, "branch", q.p, q.u[0])
    root, lam = shown_root(text), q.roots[0]
    if root is None or abs(root - lam) > 1e-5 * abs(lam):
        fail(f"{page.name}: hovering point {k} does not show its rightmost root {lam:.6g}: "
             f"{text!r}")
    if b.eval(PLOTTED_JS) is not None:
        fail(f"{page.name}: a branch of equilibria has an orbit panel")
    print(f"figures: {page.name}: point {k} hovered (rightmost root {root}), no orbit panel")


def check_chart(b: Browser, chart, page: Path) -> None:
    if not figure_page(b, page):
        return
    for j, i in ((1, 2), (2, 0)):
        lam = complex(chart.re[j, i], chart.im[j, i])
        text = hover_text(b, "chart", chart.p_values[i], chart.q_values[j])
        root = shown_root(text)
        if root is None or abs(root - lam) > 1e-5 * abs(lam):
            fail(f"{page.name}: hovering grid point ({i}, {j}) does not show its rightmost root "
                 f"{lam:.6g}: {text!r}")
        print(f"figures: {page.name}: grid point ({i}, {j}) hovered: rightmost root {root}")


def check_figures(b: Browser, src: Path, build: Path) -> None:
    """The HTML figures of a small model's branches and chart (tests/python/models/interactive_models.py)
    in the browser: hover and click on the data points, and the network log."""
    sys.path[:0] = [str(build / "python"), str(src / "tests" / "python")]
    from models import interactive_models as im
    equilibria, orbits = im.branches()
    chart = im.chart()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, obj, check in (("orbits.html", orbits, check_orbit_branch),
                                 ("equilibria.html", equilibria, check_equilibrium_branch),
                                 ("chart.html", chart, check_chart)):
            obj.to_html(folder / name)
            check(b, obj, folder / name)
            # every request since the page was opened (Browser.open keeps them in b.events)
            log = [e for e in b.events if e.get("method", "").startswith("Network.")]
            bad = outside(log, folder)
            for msg in bad:
                fail(f"{name} {msg}")
            print(f"figures: {name}: {len(bad)} requests outside its folder or failed")


# The checks by name: each takes the browser, the source folder, the build folder and the site.
# A new check is a function here and a name in tests/docs/CMakeLists.txt.
CHECKS = {
    "maths": lambda b, src, build, html: check_maths(b, html),
    "capi": lambda b, src, build, html: check_capi(b, src, html),
    "python": lambda b, src, build, html: check_python(b, build, html),
    "offline": lambda b, src, build, html: check_offline(b, html),
    "figures": lambda b, src, build, html: check_figures(b, src, build),
}
#: The checks that do not read the built site.
SITE_FREE = {"figures"}


def main(argv: list[str]) -> int:
    if len(argv) < 4 or any(c not in CHECKS for c in argv[3:]):
        print(f"usage: browser_check.py SOURCE_DIR BUILD_DIR {{{'|'.join(CHECKS)}}}...", file=sys.stderr)
        return 2
    src, build = Path(argv[1]).resolve(), Path(argv[2]).resolve()
    html = build / "docs" / "html"
    if not set(argv[3:]) <= SITE_FREE and not (html / "index.html").exists():
        print(f"no site in {html} (scripts/docs.sh builds it)")
        return 1
    b = Browser()
    try:
        for check in argv[3:]:
            CHECKS[check](b, src, build, html)
    finally:
        b.close()
    print(f"{len(FAILURES)} failures")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
