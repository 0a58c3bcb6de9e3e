# The grid of one-parameter continuations over q (dmi.analysis.continue_over) and the regions it
# decides, on the rotationally symmetric oscillator with a distributed memory whose circles are
# exact: z' = (mu + i W0) z + c1 |z|^2 z + c2 |z|^4 z - int_0^2 G e^-s z(t - s) ds, real c1 > 0 >
# c2.  Its Hopf point solves Om + Im g(i Om) = W0, mu_H = Re g(i Om); its circles of radius r
# solve mu = mu_H - c1 r^2 - c2 r^4 at the same Om, so the circles fold at r^2 = c1 / (2 |c2|),
# mu_F = mu_H - c1^2 / (4 |c2|): between mu_F and mu_H the rest (stable below mu_H) and the large
# circle coexist (bistable).  Also: the same rows bitwise from a Dask LocalCluster of processes
# (stopped by the test), a failing q kept as a row with its error, the regions' logic on rows
# written here, and the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.optimize as so

from dmi import analysis as da
from dmi.analysis.plane.grid import (UNDECIDED, GridEvent, GridRow, Trace, facts_at, region_of,
                                     regions)

from models import hopf_models

W0, TAU = 1.0, 2.0
C1, C2 = 1.0, -1.0
G_VALUES = (0.3, 0.5)
FAILING = 0.4


def make2(mu: float, G: float):
    return hopf_models.circle_solver(complex(mu, W0), C1, C2, G, TAU, 100, False)


def closed_form(G: float) -> tuple[float, float, float, str]:
    """(Om, mu_H, mu_F, criticality): l1 = Re(2 c1 / d'(i Om)) / Om, d' = 1 + g'(i Om)."""
    om = so.brentq(lambda w: w + hopf_models.ghat(1j * w, G, TAU).imag - W0, 0.1, 3.0,
                   xtol=1e-15, rtol=1e-15)
    mu_h = hopf_models.ghat(1j * om, G, TAU).real
    d1 = 1 + hopf_models.dghat(1j * om, G, TAU)
    l1 = (2 * C1 / d1).real / om
    return om, mu_h, mu_h - C1 ** 2 / (4 * abs(C2)), "subcritical" if l1 > 0 else "supercritical"


def branches(G: float) -> dict:
    """The rest from below the Hopf point to above it, and the orbits born there continued down
    through their fold (the branch ends where it comes back past its start)."""
    if G == FAILING:
        raise RuntimeError(f"no branches at G = {G}")
    _, mu_h, _, _ = closed_form(G)
    lo, hi = mu_h - 0.6, mu_h + 0.3
    make = lambda mu: make2(mu, G)   # noqa: E731
    rest = da.continue_equilibrium(da.equilibrium(make, lo, [0.0, 0.0], of="equation"), hi,
                                   step=0.1)
    (h,) = [e for e in rest.events if e.kind == "hopf"]
    orbit = da.hopf_orbit(make, h.hopf, h.u, amplitude=0.01, of="equation")
    return {"rest": rest, "orbits": da.continue_orbit(orbit, lo, step=0.02)}


@pytest.fixture(scope="module")
def grid():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", da.GridWarning)
        return da.continue_over((G_VALUES[0], FAILING, G_VALUES[1]), branches)


def test_every_q_has_one_row_and_the_failure_its_error(grid):
    assert [r.q for r in grid.rows] == [G_VALUES[0], FAILING, G_VALUES[1]]
    (bad,) = grid.failed
    assert bad.q == FAILING and bad.branches == {}
    assert bad.error.startswith("RuntimeError: no branches at G = 0.4")
    with pytest.warns(da.GridWarning, match=r"1 of 2 values of q failed, at q = 0.4"):   # PL06
        da.continue_over((0.1, FAILING), lambda G: branches(FAILING) if G == FAILING else {})


def test_the_grids_hopf_points_against_the_closed_form(grid):
    hopfs = grid.events("hopf")
    assert [e.q for e in hopfs] == list(G_VALUES)
    for e in hopfs:
        om, mu_h, _, crit = closed_form(e.q)
        assert abs(e.p - mu_h) <= 1e-9 and abs(e.omega - om) <= 1e-9, (e, mu_h, om)
        assert e.criticality == crit == "subcritical"
        assert e.on == "equilibria" and e.branch == "rest"


def test_the_bistable_region_against_the_closed_form(grid):
    for row in grid.rows:
        if row.error:
            continue
        _, mu_h, mu_f, _ = closed_form(row.q)
        (fold,) = [e for e in row.branches["orbits"].events if e.kind == "fold"]
        assert abs(fold.p - mu_f) <= 1e-8, (fold.p, mu_f)
        got = regions(row)
        (bi,) = [(lo, hi) for lo, hi, name in got if name == "bistable"]
        assert abs(bi[0] - mu_f) <= 1e-8 and abs(bi[1] - mu_h) <= 1e-9, (bi, mu_f, mu_h)
        # below the fold the rest alone; above mu_H the large circle alone (no friction: it slips)
        assert [name for _, _, name in got][:3] == ["stable rest", "bistable", "oscillation"]
        # the orbit branch's points lie on the exact circles: mu = mu_H - c1 r^2 - c2 r^4
        t = row.branches["orbits"]
        r = t.amplitude[:, 0]
        assert np.max(np.abs(t.p - (mu_h - C1 * r ** 2 - C2 * r ** 4))) <= 1e-6
        # the small circles (r^2 < c1 / 2|c2|) unstable, the large ones stable, as verified
        assert all(s is bool(x ** 2 > C1 / (2 * abs(C2))) for s, x in zip(t.stable, r)
                   if abs(x ** 2 - C1 / (2 * abs(C2))) > 1e-3)


def test_dask_gives_the_same_rows_bitwise(grid):
    distributed = pytest.importorskip("distributed")
    psutil = pytest.importorskip("psutil")
    before = {p.pid for p in psutil.Process().children(recursive=True)}
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None, host="127.0.0.1")
    try:
        with distributed.Client(cluster) as client, warnings.catch_warnings():
            warnings.simplefilter("ignore", da.GridWarning)
            other = da.continue_over((G_VALUES[0], FAILING, G_VALUES[1]), branches,
                                     client=client)
    finally:
        cluster.close()
    # every worker and nanny has ended (multiprocessing's resource tracker stays with this
    # interpreter, which it serves, and ends with it)
    started = [p for p in psutil.Process().children(recursive=True) if p.pid not in before
               and "resource_tracker" not in " ".join(p.cmdline())]
    gone, alive = psutil.wait_procs(started, timeout=30)
    left = [p.cmdline() for p in alive]
    for p in alive:
        p.kill()
    assert not left, f"processes left running: {left}"
    assert [r.q for r in other.rows] == [r.q for r in grid.rows]
    for a, b in zip(grid.rows, other.rows):
        assert (a.error or "").splitlines()[:1] == (b.error or "").splitlines()[:1]
        assert a.warnings == b.warnings and a.branches.keys() == b.branches.keys()
        for name in a.branches:
            x, y = a.branches[name], b.branches[name]
            for field in ("p", "amplitude"):
                assert getattr(x, field).tobytes() == getattr(y, field).tobytes()
            assert list(x.stable) == list(y.stable) and list(x.sticks) == list(y.sticks)
            assert x.events == y.events and x.status == y.status


# ---- the regions' logic on rows written here --------------------------------------------------
def trace(name, on, p, stable, sticks=None, events=()):
    n = len(p)
    return Trace(name, on, np.array(p, float), np.array(stable, dtype=object), np.zeros((n, 1)),
                 np.array(sticks if sticks is not None else [None] * n, dtype=object),
                 list(events), "")


def ev(kind, p, index, on="orbits"):
    return GridEvent(kind, p, 0.0, "o", on, index)


def test_stick_slip_and_oscillation_split_at_the_stick_onset():
    rest = trace("r", "equilibria", [0.0, 1.0, 2.0], [True, False, False],
                 events=[ev("hopf", 0.5, 1, "equilibria")])
    orbits = trace("o", "orbits", [0.5, 1.2, 2.0], [True, True, True], [False, False, True],
                   [ev("stick-onset", 1.6, 2)])
    row = GridRow(0.0, {"r": rest, "o": orbits})
    assert regions(row) == [(0.0, 0.5, "stable rest"), (0.5, 1.6, "oscillation"),
                            (1.6, 2.0, "stick-slip")]


def test_a_verdict_none_decides_no_region_and_warns():
    rest = trace("r", "equilibria", [0.0, 1.0, 2.0], [True, None, None])
    row = GridRow(0.0, {"r": rest})
    assert regions(row) == [(0.0, 2.0, UNDECIDED)]
    assert facts_at(row, 0.5)[3] is True
    grid = da.Grid(np.array([0.0]), [row])
    with pytest.warns(da.StabilityWarning, match="not decided"):   # bad-inputs PL08
        da.plot_curves([], grid)
    # a stable rest beside an orbit branch whose verdict is None: not "stable rest"
    orbits = trace("o", "orbits", [0.0, 2.0], [None, None], [False, False])
    row = GridRow(0.0, {"r": trace("r", "equilibria", [0.0, 2.0], [True, True]), "o": orbits})
    assert regions(row) == [(0.0, 2.0, UNDECIDED)]
    assert region_of(True, None, None, True) == UNDECIDED


def test_a_change_of_verdict_without_an_event_decides_nothing():
    row = GridRow(0.0, {"r": trace("r", "equilibria", [0.0, 1.0], [True, False])})
    assert regions(row) == [(0.0, 1.0, UNDECIDED)]


def test_refusals():
    with pytest.raises(ValueError, match="a value twice"):   # bad-inputs PL01
        da.continue_over([0.1, 0.1], branches)
    with pytest.raises(ValueError, match="finite"):   # bad-inputs PL02
        da.continue_over([0.1, float("nan")], branches)
    with pytest.raises(ValueError, match="finite values"):
        da.continue_over([], branches)
    with pytest.raises(ValueError, match="give a function"):   # bad-inputs PL03
        da.continue_over([0.1], 3)
    with pytest.raises(ValueError, match="nothing to draw"):   # bad-inputs PL04
        da.plot_curves([])
    with pytest.raises(ValueError, match="not a Curve"):   # bad-inputs PL05
        da.plot_curves([object()])
    # a task that returns something other than branches: its row's error names it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", da.GridWarning)
        g = da.continue_over([0.1], lambda q: {"x": 1.0})
    assert g.rows[0].error.startswith("TypeError: branches(q = 0.1) gave x = float")   # PL07


class LosingClient:
    """A client (submit -> future with .result()) that runs each task here, but whose future of
    one value of q raises as a cluster's does when it loses the worker."""

    def __init__(self, lose: float):
        self.lose, self.cancelled = lose, 0

    def submit(self, fn):
        client = self

        class Future:
            def result(self):
                if fn.args[1] == client.lose:
                    raise RuntimeError("KilledWorker: the worker died running the task")
                return fn()

            def cancel(self):
                client.cancelled += 1
        return Future()


def test_a_task_the_cluster_loses_keeps_its_row():
    qs = [0.1, 0.2, 0.3]
    with pytest.warns(da.GridWarning, match="at q = 0.2: the cluster lost the task"):
        g = da.continue_over(qs, lambda q: {}, client=LosingClient(0.2))
    assert [r.q for r in g.rows] == qs                     # every q once, in order
    assert [r.error is None for r in g.rows] == [True, False, True]
    assert "KilledWorker" in g.rows[1].error
