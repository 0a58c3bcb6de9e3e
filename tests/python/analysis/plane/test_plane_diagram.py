# The two-parameter diagram (dmi.analysis.plot_curves, and its Bokeh page with html=): the Hopf
# curve of the rotationally symmetric oscillator with a memory (continue_curve, subcritical all
# along: drawn dashed) against its closed form, rows whose regions are known by construction
# (the closed-form Hopf point and fold of circles as their events) drawn as bands of those
# regions; the page standalone, and in headless Chromium (tests/docs/browser_check.py's browser,
# no network): hovering a grid's Hopf point shows its p, q and criticality, a region its name, a
# curve point its omega.  A few seconds (Chromium skipped where it is not installed).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import importlib.util
import re
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize as so

from dmi import analysis as da
from dmi.analysis.plane.grid import GridEvent, GridRow, Trace

from models import hopf_models

W0, TAU, C1, C2 = 1.0, 2.0, 1.0, -1.0
QS = (0.3, 0.45, 0.6)


def make2(mu: float, G: float):
    return hopf_models.circle_solver(complex(mu, W0), C1, C2, G, TAU, 100, False)


def hopf_of(G: float) -> tuple[float, float]:
    """(Om, mu_H): Om + Im g(i Om) = W0, mu_H = Re g(i Om)."""
    om = so.brentq(lambda w: w + hopf_models.ghat(1j * w, G, TAU).imag - W0, 0.1, 3.0,
                   xtol=1e-15, rtol=1e-15)
    return om, hopf_models.ghat(1j * om, G, TAU).real


@pytest.fixture(scope="module")
def curve():
    _, mu_h = hopf_of(QS[0])
    hp = da.hopf(lambda mu: make2(mu, QS[0]), mu_h - 0.2, mu_h + 0.2, [0.0, 0.0],
                 of="equation")
    return da.continue_curve(hp, make2, QS[0], QS[-1], u_eq=[0.0, 0.0])


def row(G: float) -> GridRow:
    """A row as the grid gives it, its verdicts and events from the closed form: the rest
    stable below mu_H, the circles unstable below their fold mu_F on the small side, stable on
    the large."""
    om, mu_h = hopf_of(G)
    mu_f = mu_h - C1 ** 2 / (4 * abs(C2))
    rest = Trace("rest", "equilibria", np.array([mu_h - 0.6, mu_h - 0.1, mu_h + 0.1]),
                 np.array([True, True, False], dtype=object), np.zeros((3, 2)),
                 np.array([None] * 3, dtype=object), [GridEvent(
                     "hopf", mu_h, G, "rest", "equilibria", 2, "subcritical", 0.5, 1e-12, om)],
                 "")
    fold = GridEvent("fold", mu_f, G, "orbits", "orbits", 2)
    orbits = Trace("orbits", "orbits", np.array([mu_h - 0.01, mu_f + 0.05, mu_f + 0.1, mu_h + 0.2]),
                   np.array([False, False, True, True], dtype=object), np.ones((4, 2)),
                   np.array([False] * 4, dtype=object), [fold], "")
    return GridRow(G, {"rest": rest, "orbits": orbits})


@pytest.fixture(scope="module")
def grid():
    return da.Grid(np.array(QS), [row(G) for G in QS])


def test_the_curve_is_the_closed_form_and_drawn_dashed(curve, grid):
    for pt in curve.points:
        assert abs(pt.p - hopf_of(pt.q)[1]) <= 1e-8 and pt.criticality == "subcritical"
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ax = da.plot_curves([curve], grid, p_label="mu", q_label="G")
    dashed = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"]
    assert len(dashed) == 1 and np.array_equal(dashed[0].get_xdata(), curve.p)
    boxes = [r for r in ax.patches if isinstance(r, Rectangle)]
    # each row: stable rest, bistable [mu_F, mu_H], oscillation; its band half-way to the next
    assert len(boxes) == 3 * len(QS)
    for G, lo_q, hi_q in zip(QS, (0.225, 0.375, 0.525), (0.375, 0.525, 0.675)):
        _, mu_h = hopf_of(G)
        (bi,) = [r for r in boxes if abs(r.get_y() - lo_q) < 1e-12 and
                 abs(r.get_facecolor()[0] - 0xda / 255) < 1e-9]
        assert abs(bi.get_x() - (mu_h - 0.25)) < 1e-12
        assert abs(bi.get_x() + bi.get_width() - mu_h) < 1e-12
        assert abs(bi.get_height() - (hi_q - lo_q)) < 1e-12
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"stable rest", "bistable", "oscillation", "Hopf curve (subcritical)",
            "Hopf point of the grid (subcritical)", "fold of orbits (grid)"} <= set(labels)
    plt.close("all")


def test_the_page_is_standalone_and_carries_the_diagram(curve, grid, tmp_path):
    pytest.importorskip("bokeh")
    path = tmp_path / "diagram.html"
    ax = da.plot_curves([curve], grid, html=path, p_label="mu", q_label="G")
    assert ax is not None
    text = path.read_text()
    assert not re.search(r"<script[^>]*\bsrc=", text) and not re.search(r"<link[^>]*\bhref=", text)
    for name in ("diagram", "regions", "grid_hopf", "grid_fold", "curve0"):
        assert f'"{name}"' in text, name


def browser_module():
    path = Path(__file__).resolve().parents[3] / "docs" / "browser_check.py"
    spec = importlib.util.spec_from_file_location("browser_check", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_hovering_the_page_in_chromium(curve, grid, tmp_path):
    pytest.importorskip("bokeh")
    pytest.importorskip("websocket")
    if shutil.which("chromium") is None:
        pytest.skip("no chromium on PATH (scripts/docs.sh --install installs it)")
    bc = browser_module()
    path = tmp_path / "diagram.html"
    da.plot_curves([curve], grid, html=path, p_label="mu", q_label="G")
    b = bc.Browser()
    try:
        b.open(path.as_uri())
        assert b.eval(bc.BOKEH_READY_JS) is not None, "BokehJS did not draw the page"
        e = grid.events("hopf")[1]
        text = bc.hover_text(b, "diagram", e.p, e.q)
        assert "subcritical" in text, text
        p = bc.read_field(text, "p")
        assert p is not None and abs(float(p.group(1)) - e.p) <= 1e-5 * abs(e.p), text
        # a region: between the fold and the Hopf point of the middle row
        _, mu_h = hopf_of(QS[1])
        text = bc.hover_text(b, "diagram", mu_h - 0.12, QS[1] + 0.05)
        assert "bistable" in text, text
        k = len(curve.points) // 2
        pt = curve.points[k]
        text = bc.hover_text(b, "diagram", pt.p, pt.q)
        om = bc.read_field(text, "omega")
        assert om is not None and abs(float(om.group(1)) - pt.omega) <= 1e-5 * pt.omega, text
        log = [x for x in b.events if x.get("method", "").startswith("Network.")]
        assert bc.outside(log, tmp_path) == []
    finally:
        b.close()
