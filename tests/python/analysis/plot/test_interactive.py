# The interactive HTML figures of dmi.analysis (Branch.to_html, StabilityChart.to_html and the html=
# of plot_branch and plot_stability_chart) read back from the file: the data they carry against
# the branch's and the chart's own records, standalone (no script or style from elsewhere), the
# size of a 100-point branch's file; and the _repr_html_ summaries against values known here.
# What the browser shows of them (hover, click) is checked by tests/docs/browser_check.py figures.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import base64
import gzip
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from dmi import analysis as da
from dmi.analysis.continuation.branch import BranchPoint
from dmi.analysis.equilibria.chart import HopfCurve
from dmi.analysis.scheme.orbit import Orbit

from models import interactive_models as im

NUM = r"(-?\d+(?:\.\d*)?(?:e[-+]?\d+)?)"


@pytest.fixture(scope="module")
def branches():
    return im.branches()


@pytest.fixture(scope="module")
def chart():
    return im.chart()


# ---- reading a Bokeh standalone file back -------------------------------------------------------
def _value(v):
    """A serialised Bokeh value as numpy / Python (ndarrays: base64 bytes, maybe gzipped)."""
    if isinstance(v, dict) and v.get("type") == "ndarray":
        raw = base64.b64decode(v["array"]["data"])
        if raw[:2] == b"\x1f\x8b":
            raw = gzip.decompress(raw)
        return np.frombuffer(raw, dtype=v["dtype"]).reshape(v["shape"])
    return v


def sources(text: str) -> dict[str, dict[str, object]]:
    """The named ColumnDataSources of the document embedded in a standalone file: name -> data."""
    m = re.search(r'<script type="application/json" id="[^"]+">\s*(.*?)\s*</script>', text, re.S)
    assert m, "no Bokeh document in the file"
    found: dict[str, dict[str, object]] = {}

    def walk(o):
        if isinstance(o, dict):
            a = o.get("attributes", {})
            if o.get("name") == "ColumnDataSource" and "name" in a:
                found[a["name"]] = {k: _value(v) for k, v in a["data"]["entries"]}
            for v in o.values():
                walk(v)
        elif isinstance(o, list):
            for v in o:
                walk(v)
    walk(json.loads(m.group(1)))
    return found


def model_names(text: str) -> set[str]:
    """The names given to the embedded document's models."""
    return set(re.findall(r'"name":\s*"([^"]+)"', text.split('type="application/json"', 1)[1]))


def standalone(text: str) -> None:
    """Nothing to fetch: no <script src>, <link href>, @import or url(http...) in the file, and
    the library's JavaScript inlined (its bokeh.min.js is in the file)."""
    assert not re.search(r"<script[^>]*\bsrc=", text)
    assert not re.search(r"<link[^>]*\bhref=", text)
    assert not re.search(r"@import|url\(\s*['\"]?https?:", text)
    import bokeh
    js = (Path(bokeh.__file__).parent / "server" / "static" / "js" / "bokeh.min.js").read_text()
    assert js[-2000:].strip() in text


def complex_of(s: str) -> complex:
    m = re.fullmatch(NUM + r" ([-+]) " + NUM + "i", s)
    assert m, s
    return complex(float(m.group(1)), float(m.group(2) + m.group(3)))


# ---- the figures --------------------------------------------------------------------------------
def test_orbit_branch_file_carries_every_orbit_and_the_hover_values(branches, tmp_path):
    _, orbits = branches
    path = tmp_path / "orbits.html"
    orbits.to_html(path)
    text = path.read_text()
    standalone(text)
    src = sources(text)
    pts, store, points = orbits.points, src["orbits"], src["points"]
    assert len(pts) == 5 and len(points["p"]) == 5
    for k, q in enumerate(pts):
        a, b = int(points["start"][k]), int(points["stop"][k])
        assert np.array_equal(store["t"][a:b], q.t)
        for j in range(q.u.shape[1]):
            assert np.array_equal(store[f"u{j}"][a:b], q.u[:, j])
        # the hover texts: p, period, amplitude per component, multipliers, stability
        assert float(points["p_text"][k]) == pytest.approx(q.p, rel=1e-5)
        assert float(points["period_text"][k]) == pytest.approx(q.period, rel=1e-5)
        amp = [float(x) for x in points["amplitude_text"][k].split(", ")]
        assert amp == pytest.approx(q.amplitude, rel=1e-5)
        shown = [complex_of(m.split(" (")[0]) for m in points["multipliers_text"][k].split("; ")]
        assert shown == pytest.approx(list(q.multipliers[:3]), abs=1e-5)
        assert points["stable_text"][k] == ("stable" if q.stable else "unstable")
        # what the branch panel draws: an autonomous branch's amplitude of u_0
        assert points["y"][k] == q.amplitude[0]
    # the orbit panel starts with the first point's orbit
    assert np.array_equal(src["orbit"]["u1"], pts[0].u[:, 1])
    # the periods differ along this branch, so a hover showing another point's would be seen
    assert np.ptp([q.period for q in pts]) > 0.1


def test_equilibrium_branch_file_shows_the_rightmost_roots_and_no_orbit_panel(branches, tmp_path):
    equilibria, _ = branches
    path = tmp_path / "eq.html"
    da.plot_branch(equilibria, html=path)           # no Axes: only the HTML
    text = path.read_text()
    standalone(text)
    src = sources(text)
    assert "orbits" not in src and "orbit_panel" not in model_names(text)
    points = src["points"]
    for k, q in enumerate(equilibria.points):
        assert complex_of(points["root_text"][k]) == pytest.approx(q.roots[0], rel=1e-5)
        assert float(points["p_text"][k]) == pytest.approx(q.p, abs=1e-12, rel=1e-5)
        assert points["y"][k] == q.u[0]
    with pytest.raises(ValueError, match="Axes"):
        da.plot_branch(equilibria)


def test_chart_file_shows_the_rightmost_root_of_each_grid_point(chart, tmp_path):
    path = tmp_path / "chart.html"
    chart.to_html(path)
    text = path.read_text()
    standalone(text)
    cells = sources(text)["cells"]
    assert len(cells["p"]) == chart.re.size == 12
    seen = set()
    for p, q, root in zip(cells["p"], cells["q"], cells["root_text"]):
        i = int(np.nonzero(chart.p_values == p)[0][0])
        j = int(np.nonzero(chart.q_values == q)[0][0])
        seen.add((i, j))
        assert complex_of(root) == pytest.approx(complex(chart.re[j, i], chart.im[j, i]),
                                                 rel=1e-5)
    assert len(seen) == 12
    # plot_stability_chart(html=) writes the same figure beside the matplotlib one
    path2 = tmp_path / "chart2.html"
    da.plot_stability_chart(chart, html=path2, p_label="mu", q_label="gain k")
    assert sources(path2.read_text())["cells"]["root_text"] == cells["root_text"]


def _synthetic_branch(points: int, n: int) -> da.Branch:
    """points orbits of 200 samples of n random components, 8 multipliers each."""
    rng = np.random.default_rng(1)
    pts = []
    for k in range(points):
        u = rng.standard_normal((200, n))
        pts.append(BranchPoint(p=0.01 * k, period=5 + 0.01 * k, amplitude=np.ptp(u, 0) / 2,
                               multipliers=rng.standard_normal(8) + 1j * rng.standard_normal(8),
                               stable=bool(k % 2), stick_steps=np.zeros(n, int),
                               stick_phases=np.zeros(n, int), margin=np.zeros(n),
                               section=u[:1], state=u[-1], t=np.linspace(0, 5, 200), u=u))
    return da.Branch(pts, [], "synthetic", make=None, kind="orbits")


@pytest.mark.parametrize("n", [2, 4])
def test_a_100_point_branch_file_stays_small(n, tmp_path):
    # random data (it does not compress): the orbits travel once, as binary (base64: 4 / 3 of
    # their bytes), beside BokehJS itself; and the whole file stays under 5 MB
    import bokeh
    branch = _synthetic_branch(100, n)
    path = tmp_path / "big.html"
    branch.to_html(path)
    size = path.stat().st_size
    js = (Path(bokeh.__file__).parent / "server" / "static" / "js" / "bokeh.min.js").stat().st_size
    data = 100 * 200 * (n + 1) * 8
    print(f"100 points, n = {n}: {size / 1e6:.2f} MB (BokehJS {js / 1e6:.2f} MB, "
          f"orbits {data / 1e6:.2f} MB raw)")
    assert size < 5e6
    assert size < js + 4 / 3 * data + 0.4e6
    # a forced branch draws u_0 at the section t = 0 of each orbit
    y = sources(path.read_text())["points"]["y"]
    assert np.array_equal(y, [q.section[0, 0] for q in branch.points])


def test_bad_branches_get_a_clear_error(tmp_path):
    empty = da.Branch([], [], "nothing", make=None)
    with pytest.raises(ValueError, match="no points"):
        empty.to_html(tmp_path / "empty.html")
    old = _synthetic_branch(3, 2)
    old.points[1].t, old.points[1].u = np.empty(0), np.empty((0, 0))   # a point without its orbit
    with pytest.raises(ValueError, match="keep no orbit"):
        old.to_html(tmp_path / "old.html")
    assert not (tmp_path / "old.html").exists()


# ---- the Jupyter summaries ----------------------------------------------------------------------
def rows(html: str) -> dict[str, str]:
    """The table's rows, header -> cell (HTML entities left as written)."""
    return dict(re.findall(r"<th[^>]*>(.*?)</th><td[^>]*>(.*?)</td>", html))


def test_orbit_summary():
    t = np.linspace(0, 2 * np.pi, 101)
    u = np.stack([0.3 * np.sin(t), 2.0 + 0.1 * np.cos(t)], axis=1)
    o = Orbit(p=0.25, period=2 * np.pi, steps=100, h=2 * np.pi / 100, t=t, u=u, state=u[-1],
              multipliers=np.array([1.0, 0.5 + 0.25j, 0.5 - 0.25j, 0.01]), stable=True,
              stick_fraction=np.zeros(2), iterations=3, residual=1e-12, make=None,
              autonomous=True)
    html = o._repr_html_()
    r = rows(html)
    assert "Orbit (autonomous)" in html
    assert r["p"] == "0.25"
    assert r["period"].startswith("6.28319 (100 steps of h = 0.0628319)")
    assert [float(x) for x in r["amplitude"].split(", ")] == pytest.approx([0.3, 0.1], rel=1e-5)
    assert r["multipliers"] == "1 + 0i; 0.5 + 0.25i; 0.5 - 0.25i"     # the leading three
    assert r["stability"] == "stable"


def test_branch_summary(branches):
    equilibria, _ = branches
    r = rows(equilibria._repr_html_())
    hopf = [e for e in equilibria.events if e.kind == "hopf"]
    assert r["points"] == "5"
    assert r["p"] == "0 .. 0.6"                    # continued from 0 to 0.6
    assert r["stable points"] == f"{sum(q.stable for q in equilibria.points)} of 5"
    assert r["events"] == f"hopf at p = {hopf[0].p:.6g}"
    synthetic = _synthetic_branch(4, 2)
    synthetic.status = "stopped: p < 0"
    html = synthetic._repr_html_()
    assert "Branch of forced orbits" in html and rows(html)["stable points"] == "2 of 4"
    assert rows(html)["status"] == "stopped: p &lt; 0" and "p < 0" not in html


def test_chart_summary():
    c = da.StabilityChart(np.array([0.0, 1.0, 2.0]), np.array([5.0, 6.0]),
                          np.array([[-1.0, 2.5, np.nan], [-3.0, -0.5, 0.0]]), np.zeros((2, 3)),
                          [HopfCurve(np.ones(3), np.ones(3), np.full(3, 2.0)),
                           HopfCurve(np.ones(3), np.ones(3), np.zeros(3))])
    r = rows(c._repr_html_())
    assert r["grid"] == "3 p x 2 q"
    assert r["p"] == "0 .. 2" and r["q"] == "5 .. 6"
    # a chart built by hand has no verdicts: no point is called stable from the sign of re alone
    assert r["stable points"] == "0 of 6 (6 not verified)"
    d = da.StabilityChart(c.p_values, c.q_values, c.re, c.im, c.curves,
                          verdict=np.array([[True, False, None], [True, True, None]], dtype=object))
    assert rows(d._repr_html_())["stable points"] == "3 of 6 (2 not verified)"
    assert r["largest Re"] == "2.5"
    assert r["curves"] == "1 Hopf, 1 fold"


def test_without_bokeh_the_figures_say_what_to_install(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "bokeh", None)          # import bokeh raises ImportError
    c = da.StabilityChart(np.array([0.0, 1.0]), np.array([0.0]), np.zeros((1, 2)), np.zeros((1, 2)))
    with pytest.raises(ImportError, match="pip install bokeh"):
        c.to_html(tmp_path / "c.html")
    with pytest.raises(ImportError, match="pip install bokeh"):
        _synthetic_branch(2, 2).to_html(tmp_path / "b.html")


def test_summaries_and_import_do_not_need_bokeh():
    # the package and the Jupyter summaries load no plotting library; only the figures do
    code = ("import sys, numpy as np; import dmi.analysis as da;"
            "c = da.StabilityChart(np.array([0., 1.]), np.array([0.]), np.zeros((1, 2)),"
            " np.zeros((1, 2))); c._repr_html_();"
            "print('bokeh' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
