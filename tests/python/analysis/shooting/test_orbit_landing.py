# Branches of periodic orbits on the one driver: the autonomous branch of van der Pol with a
# distributed delay lands on p_end exactly, a branch pickles, a branch whose stability is not
# verified (no multipliers) draws dotted with None in its column, and messages that name the
# cause: a NaN in the guess, an orbit on a vertical branch given to refine_orbit.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import pickle

import matplotlib
import numpy as np
import pytest

import dmi
import dmi.analysis as da
from models.delay_models import vdp

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

@pytest.fixture(scope="module")
def vdp_branch():
    M = 300
    P = 5.5
    s = vdp(0.5, h=P / M)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(round(60 / s.h))
    o = da.periodic_orbit(vdp, 0.5, guess=s, guess_period=P, steps=M, multipliers=2)
    return o, da.continue_orbit(o, 0.2, step=0.05, multipliers=2, at=[0.35])


def test_autonomous_branch_lands_on_p_end(vdp_branch):
    o, b = vdp_branch
    assert b.kind == "autonomous" and b.status.startswith("reached p_end"), b.status
    assert abs(b.points[-1].p - 0.2) <= 1e-12, b.points[-1].p
    user = [e for e in b.events if e.kind == "user"]
    assert len(user) == 1 and abs(b.points[user[0].index].p - 0.35) <= 1e-12
    # the last point is an orbit of the scheme at p = 0.2: a plain run from its state, at its
    # step, comes back to it after one period
    q = b.points[-1]
    h = q.period / b.steps
    s = vdp(0.2, h=h)
    s.init()
    rows = q.state.reshape(-1, 2)
    s.set_window(rows[-(s.N + 1):])
    U = s.run(b.steps)[1]
    assert np.max(np.abs(U[-1] - rows[-1])) <= 1e-8


def test_an_orbit_branch_pickles(vdp_branch):
    _, b = vdp_branch
    back = pickle.loads(pickle.dumps(b))
    assert np.array_equal(back.p, b.p) and back.status == b.status
    assert back.make(0.3, h=0.05).h == 0.05          # the model came along


def forced(a: float) -> dmi.Solver:
    # u' + u = a cos t at the step 2 pi / 200: an orbit a (cos t + sin t) / 2 (O(h))
    s = dmi.Solver(1, 2 * np.pi / 200, 1)
    s.set_rhs(lambda t, u: np.array([u[0] - a * np.cos(t)]))
    return s


def test_unverified_stability_is_none_and_dotted(tmp_path):
    o = da.periodic_orbit(forced, 1.0, 2 * math.pi, [0.5], multipliers=0)
    assert o.multipliers.size == 0
    b = da.continue_orbit(o, 1.2, step=0.05, multipliers=0)
    assert b.status.startswith("reached p_end") and b.points[-1].p == 1.2
    col = b.column("stable")
    assert col.dtype == object and all(v is None for v in col)
    assert all(v is None for v in b.stable)
    fig, ax = plt.subplots()
    da.plot_branch(b, ax)
    styles = {ln.get_linestyle() for ln in ax.lines if len(ln.get_xdata()) > 1}
    assert styles == {":"}, styles
    plt.close(fig)
    assert "not verified" in b._repr_html_()
    path = tmp_path / "branch.html"
    b.to_html(path)                       # the interactive figure: dotted grey, "not verified"
    html = path.read_text()
    # Bokeh writes a dotted line as line_dash [2, 4], a dashed one as [6]
    assert '"line_dash":[2,4]' in html and '"line_dash":[6]' not in html
    assert "#7f7f7f" in html and "not verified" in html


def test_nan_in_the_guess_is_named():
    with pytest.raises(ValueError, match=r"non-finite.*row 0 component 0 = nan"):
        da.periodic_orbit(forced, 1.0, 2 * math.pi, [math.nan])


def test_refine_of_an_orbit_on_a_vertical_branch_says_it_is_not_isolated():
    # the belt of models/damped_belt.py: the orbits born at its Hopf point form a centre
    # (sliding, linear) up to grazing: at fixed p they are not isolated
    from models.damped_belt import belt
    eq = da.equilibrium(belt, 1.0, [0.2, -0.2])
    br = da.continue_equilibrium(eq, -0.5, step=0.2)
    hopf = [e for e in br.events if e.kind == "hopf"][0]
    o = da.hopf_orbit(belt, hopf.hopf, hopf.u, amplitude=0.1, steps=200)
    with pytest.raises(da.ShootingError, match="not isolated at fixed p"):
        da.refine_orbit(o)
