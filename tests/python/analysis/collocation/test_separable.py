# The delay matrix of an exponential-sum kernel with its far cells by separated factors
# (collocation.mesh.delay_matrix_separable) against the direct quadrature of every piece
# (collocation.mesh.delay_matrix), on the history locator of the monodromy's fixed past (several
# periods, the period's mesh moved off the past's): the fractional kernel's fit with near cells
# (the fractional belt's), and an oscillating sum (complex rates) with a near part; the memory
# ends inside a cell for every time.  The same for the periodic orbit's kernel folded onto one
# period (collocation.fold), its memory's rest r beyond the near part (inside the period, and
# within a cell of its end), inside the near part, and 0.  The two rules differ by their quadrature errors
# (Gauss-Legendre on pieces at least their own length from 0): agreement to 1e-13 of the
# matrix's scale.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi
from dmi import kernels
from dmi.analysis.collocation import mesh
from dmi.analysis.collocation import system as S
from dmi.analysis.collocation.fold import exp_sum, fold_of
from dmi.analysis.collocation.mesh import (Basis, Kernel, Near, crossings, delay_matrix,
                                           history_locator, history_rows, periodic_locator)

M, Q, T, L = 4, 6, 6.3, 30


def fractional(tau: float) -> S.Terms:
    """The fractional belt's terms: c s^-1/2 on u_2 by a fit with near cells delta = 0.002."""
    fit = kernels.fit(kernels.PowerKernel(0.5, 0.1 / math.sqrt(math.pi)), tau, tol=1e-8,
                      relative=True, delta=0.002)
    s = dmi.Solver(2, tau, h=0.01)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0]]))
    s.set_quadrature("cell")
    s.set_kernel_fit(fit, entry=(1, 1))
    return S.Terms(s)


def oscillating() -> tuple[Kernel, tuple]:
    """H(s) = sum_j e^(a_j s) (C_j cos b_j s + D_j sin b_j s) past s^-0.3 C0 on (0, 0.01]."""
    a = np.array([-0.05, -0.4, -3.0, -60.0])
    b = np.array([0.0, 1.7, 0.6, 9.0])
    rng = np.random.default_rng(3)
    C, D = rng.standard_normal((4, 2, 2)), rng.standard_normal((4, 2, 2))
    D[0] = 0.0
    terms = (a, b, C, D)
    near = Near(0.01, 0.3, np.array([[0.4, -0.2], [0.1, 0.3]]))
    return Kernel(lambda s: exp_sum(s, *terms), near, (), 0.0), terms


def meshes(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(the past's mesh of [0, T], the period's: the past's with some points moved)."""
    h = 1.0 + 0.7 * np.random.default_rng(seed).random(L)
    past = np.concatenate([[0.0], np.cumsum(h)]) * T / np.sum(h)
    now = past.copy()
    now[7:12] += 0.4 * np.min(np.diff(past))
    return past, now


def products(build):
    """build() with every window's far cells by the products (MIN_CELLS 0), checked taken."""
    used = []
    real, least = mesh._far_part, mesh.MIN_CELLS
    try:
        mesh._far_part = lambda *a, **k: used.append(1) or real(*a, **k)
        mesh.MIN_CELLS = 0
        out = build()
    finally:
        mesh._far_part, mesh.MIN_CELLS = real, least
    assert used, "no far cells taken by the products"
    return out


def check(kernel, terms, tau: float, pattern: np.ndarray) -> None:
    past, now = meshes(1)
    P = math.ceil(tau / T)
    basis = Basis(M, Q)
    rows = history_rows(L, M, P)
    loc = history_locator(now, past, M, P)
    gz = basis.gauss()[0]
    times = np.concatenate([(now[:-1, None] + np.diff(now)[:, None] * gz).ravel(),
                            [0.0, 0.41, 3.3, T]])
    pts = np.union1d(now, past)
    # the memory's end t - tau inside a cell for every time (the cell cut by the truncation)
    ext, j0, _ = crossings(times, tau, pts[:-1], T)
    assert np.all((ext[j0 - 1] < times - tau) & (times - tau < ext[j0]))
    G0 = delay_matrix(times, tau, pts, T, kernel, loc, basis, 2, rows, pattern=pattern)[0]
    G1 = products(lambda: mesh.delay_matrix_separable(times, tau, pts, T, kernel, terms, loc,
                                                      basis, 2, rows, pattern=pattern))
    A0, A1 = G0.toarray(), G1.toarray()
    scale = np.max(np.abs(A0))
    assert np.max(np.abs(A1 - A0)) < 1e-13 * scale
    # the rows' sums: the far cells are most of each row
    u = np.random.default_rng(5).standard_normal(rows * 2)
    assert np.max(np.abs((A1 - A0) @ u)) < 1e-13 * np.max(np.abs(A0) @ np.abs(u))


@pytest.mark.parametrize("tau", [14.5, 25.9])
def test_fractional_fit_with_near_cells(tau: float) -> None:
    terms = fractional(tau)
    assert terms.H.near is not None
    check(terms.H, terms.terms, tau, terms.pattern)


def test_oscillating_sum_with_a_near_part() -> None:
    kernel, terms = oscillating()
    check(kernel, terms, 17.2, np.ones((2, 2), bool))


def test_growing_term_is_left_to_the_direct_quadrature() -> None:
    kernel, (a, b, C, D) = oscillating()
    a = a.copy()
    a[0] = 0.01
    grow = Kernel(lambda s: exp_sum(s, a, b, C, D), kernel.near, (), 0.0)
    past, now = meshes(2)
    basis = Basis(M, Q)
    loc = history_locator(now, past, M, 2)
    times = np.array([0.3, 2.0, 5.0])
    rows = history_rows(L, M, 2)
    pts = np.union1d(now, past)
    G0 = delay_matrix(times, 9.0, pts, T, grow, loc, basis, 2, rows)[0]
    G1 = mesh.delay_matrix_separable(times, 9.0, pts, T, grow, (a, b, C, D), loc, basis, 2,
                                     rows)
    assert (G1 != G0).nnz == 0


@pytest.mark.parametrize("which, tau", [("fractional", 25.9), ("oscillating", 17.2),
                                        ("fractional", 4 * T - 0.01),
                                        ("oscillating", 3 * T + 0.004), ("oscillating", 3 * T)])
def test_folded_kernel(which: str, tau: float) -> None:
    if which == "fractional":
        terms = fractional(tau)
        H, sums, pattern = terms.H, terms.terms, terms.pattern
    else:
        (H, sums), pattern = oscillating(), np.ones((2, 2), bool)
    f = fold_of(H, sums, tau, T)
    assert f is not None
    assert (f.r > 0.01) == (tau in (25.9, 17.2, 4 * T - 0.01))
    now = meshes(4)[1]
    basis = Basis(M, Q)
    loc = periodic_locator(now, M)
    gz = basis.gauss()[0]
    times = np.concatenate([(now[:-1, None] + np.diff(now)[:, None] * gz).ravel(), [0.0, 2.2]])
    G0 = delay_matrix(times, T, now, T, f.kernel, loc, basis, 2, L * M, pattern=pattern)[0]
    G1 = products(lambda: mesh.folded_matrix(times, f, now, T, loc, basis, 2, L * M,
                                             pattern=pattern))
    A0, A1 = G0.toarray(), G1.toarray()
    assert np.max(np.abs(A1 - A0)) < 1e-13 * np.max(np.abs(A0))
