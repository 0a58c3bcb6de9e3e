# The verified verdict of each cell of a stability chart (dmi.analysis.stability_chart): the
# mean-delay equation's closed-form boundary on both sides, a cell exactly on it, the plot's
# undecided cells, and the opt-out.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dmi
from dmi import analysis
from dmi.analysis import StabilityWarning


def mean_delay(a: float, tau: float, N: int = 100) -> dmi.Solver:
    """x' = -(a / tau) int_0^tau x(t - s) ds: Delta(lambda) = lambda + a (1 - e^(-lambda tau)) /
    (lambda tau); on the axis sin(w tau) = 0, cos(w tau) = -1, w^2 tau = 2 a: the first crossing
    at w = pi / tau, a* = pi^2 / (2 tau)."""
    s = dmi.Solver(1, tau, N)
    s.set_kernel_exp([0.0], [0.0], [[[a / tau]]])
    return s


def a_star(tau: float) -> float:
    return math.pi ** 2 / (2 * tau)


class InProcess:
    """An executor that runs each task at once in this process (stability_chart's ``client``):
    no pool to start for a grid of a few cells."""

    class _Done:
        def __init__(self, value):
            self.value = value

        def result(self):
            return self.value

        def cancel(self):
            return False

    def submit(self, fn):
        return self._Done(fn())


TAUS = np.array([1.0, 2.0])
#: a*(2) = pi^2 / 4 and a*(1) = pi^2 / 2 are grid values: one cell on the boundary in each row
GAINS = np.array([1.0, a_star(2.0), a_star(1.0), 8.0])


def chart(of: str = "equation", verify: bool = True, gains=GAINS, taus=TAUS):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        c = analysis.stability_chart(mean_delay, gains, taus, [0.0], count=4,
                                     client=InProcess(), trace=False, of=of, verify=verify)
    return c, got


@pytest.fixture(scope="module")
def verified():
    return chart()


def test_cells_on_both_sides_as_the_closed_form_says(verified):
    c, _ = verified
    for j, tau in enumerate(TAUS):
        for i, a in enumerate(GAINS):
            if abs(a - a_star(tau)) < 1e-12:
                continue
            assert c.verdict[j, i] is bool(a < a_star(tau)), (a, tau, c.reason[j, i])
            assert 0 < c.error[j, i] < abs(c.re[j, i])
    expected = np.array([[True, True, False, False], [True, False, False, False]])
    assert np.array_equal(c.stable, expected)
    assert np.array_equal(c.unstable, np.array([[False, False, False, True],
                                                [False, False, True, True]]))


def test_cell_on_the_boundary_is_none_with_one_warning(verified):
    c, got = verified
    on = np.array([[False, False, True, False], [False, True, False, False]])
    assert np.array_equal(c.undecided, on)
    for j, i in np.argwhere(on):
        assert c.verdict[j, i] is None
        # the root found is the crossing pair +-i pi / tau
        assert abs(complex(c.re[j, i], abs(c.im[j, i])) - 1j * math.pi / TAUS[j]) < 1e-8
        assert "imaginary axis within its error" in c.reason[j, i]
    msgs = [str(w.message) for w in got if issubclass(w.category, StabilityWarning)]
    assert len(msgs) == 1, msgs
    assert "2 of 8 grid points" in msgs[0] and "imaginary axis within its error" in msgs[0]
    assert not [w for w in got if w.category is UserWarning]


def test_scheme_cells_away_from_the_boundary():
    # the scheme's boundary lies O(h) from the equation's: cells at half and twice a* decide
    gains = np.array([0.5 * a_star(1.0), 2.0 * a_star(1.0)])
    c, got = chart(of="scheme", gains=gains, taus=TAUS[:1])
    assert c.verdict[0, 0] is True and c.verdict[0, 1] is False, c.reason
    assert not [w for w in got if issubclass(w.category, StabilityWarning)]


def test_verify_false_gives_none_and_a_user_warning(verified):
    c, got = chart(verify=False)
    assert all(v is None for v in c.verdict.ravel())
    assert not c.stable.any() and not c.unstable.any() and c.undecided.all()
    assert np.all(np.isnan(c.error))
    # the roots stay, as the verified chart's
    assert np.array_equal(c.re, verified[0].re) and np.array_equal(c.im, verified[0].im)
    msgs = [str(w.message) for w in got if w.category is UserWarning]
    assert len(msgs) == 1 and "verify=False" in msgs[0], msgs
    assert not [w for w in got if issubclass(w.category, StabilityWarning)]
    with pytest.raises(ValueError, match=r"verify = .yes.\): give True"):   # bad-inputs SC01
        analysis.stability_chart(mean_delay, GAINS, TAUS, [0.0], client=InProcess(),
                                 verify="yes")


def test_plot_draws_the_undecided_cells_hatched(verified):
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.patches import Rectangle
    c, _ = verified
    ax = analysis.plot_stability_chart(c)
    cells = [p for p in ax.patches if isinstance(p, Rectangle) and p.get_hatch()]
    assert len(cells) == int(c.undecided.sum()) == 2
    # each undecided grid point inside one hatched cell, every decided one outside them all
    def inside(p, x, y):
        return (p.get_x() < x < p.get_x() + p.get_width()
                and p.get_y() < y < p.get_y() + p.get_height())
    for j, tau in enumerate(TAUS):
        for i, a in enumerate(GAINS):
            n = sum(inside(p, a, tau) for p in cells)
            assert n == (1 if c.undecided[j, i] else 0), (a, tau, n)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "not decided" in labels


def test_a_chart_built_by_hand_has_no_verdict():
    c = analysis.StabilityChart(np.array([0.0, 1.0]), np.array([0.0]), np.array([[-1.0, 1.0]]),
                                np.zeros((1, 2)))
    assert c.undecided.all() and not c.stable.any()
