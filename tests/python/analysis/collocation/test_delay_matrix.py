# The delay integral's quadrature matrix against adaptive quadrature of the piecewise polynomial.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""``collocation.mesh.delay_matrix`` times node values against ``scipy.integrate.quad`` of
int_0^tau H(s) u(t - s) ds, u the piecewise polynomial of those values evaluated here by Lagrange's
formula: on the periodic locator (a memory shorter and longer than the period), and on the history
locator whose past mesh is not the period's (the past read on its own mesh while the period's
switching times moved), where a whole interval of the period's mesh is not an interval of the past
and must not take the whole-interval basis."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from dmi.analysis.collocation.mesh import (Basis, DelayPlan, delay_matrix, history_locator,
                                           history_rows, periodic_locator)

M, Q, N = 4, 5, 2
PATTERN = np.array([[False, True], [True, False]])
#: quad warns of roundoff at its 1e-14 tolerance on some pieces; the comparison below is the check
pytestmark = pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")


def kernel(s: np.ndarray) -> np.ndarray:
    """H(s) = [[0, 1 - s + 0.3 s^2], [0.5 s^5 - s, 0]] (k, 2, 2): of degree 2 q - 1 - m at most,
    where the rule of q nodes a piece is exact."""
    s = np.asarray(s, dtype=float)
    out = np.zeros((s.size, N, N))
    out[:, 0, 1] = 1.0 - s + 0.3 * s ** 2
    out[:, 1, 0] = 0.5 * s ** 5 - s
    return out


def lagrange(left: float, h: float, values: np.ndarray, t: float) -> np.ndarray:
    """The polynomial through values (m + 1, n) at left + k h / m, at t."""
    x = left + h * np.arange(M + 1) / M
    w = np.array([np.prod([(t - x[j]) / (x[k] - x[j]) for j in range(M + 1) if j != k])
                  for k in range(M + 1)])
    return w @ values


def reference(t: float, tau: float, u, cuts: np.ndarray) -> np.ndarray:
    """int_0^tau H(s) u(t - s) ds by quad, split at the lags of the mesh crossings."""
    lags = np.unique(np.concatenate([[0.0, tau], t - cuts]))
    lags = lags[(lags >= 0.0) & (lags <= tau)]
    out = np.zeros(N)
    for a, b in zip(lags[:-1], lags[1:]):
        for i in range(N):
            out[i] += quad(lambda s: (kernel(np.array([s]))[0] @ u(t - s))[i], a, b,
                           epsabs=1e-15, epsrel=1e-14, limit=200)[0]
    return out


def mesh_of(L: int, T: float, seed: int) -> np.ndarray:
    """A nonuniform mesh of [0, T] with L intervals."""
    h = 1.0 + 0.8 * np.random.default_rng(seed).random(L)
    return np.concatenate([[0.0], np.cumsum(h)]) * T / np.sum(h)


@pytest.mark.parametrize("tau", [0.7, 2.3])
def test_periodic_locator(tau: float) -> None:
    T, L = 1.3, 9
    mesh = mesh_of(L, T, 1)
    U = np.random.default_rng(2).standard_normal((L * M, N))

    def u(t: float) -> np.ndarray:
        i = min(int(np.searchsorted(mesh, t % T, side="right")) - 1, L - 1)
        rows = (i * M + np.arange(M + 1)) % (L * M)
        return lagrange(mesh[i], mesh[i + 1] - mesh[i], U[rows], t % T)

    times = np.array([0.05, 0.31, 0.6, 1.0, 1.29])
    G, _ = delay_matrix(times, tau, mesh, T, kernel, periodic_locator(mesh, M), Basis(M, Q), N,
                        L * M, pattern=PATTERN)
    got = (G @ U.ravel()).reshape(-1, N)
    k = np.arange(-4, 3)
    cuts = (mesh[:, None] + T * k[None, :]).ravel()
    for c, t in enumerate(times):
        want = reference(t, tau, u, cuts)
        assert np.max(np.abs(got[c] - want)) < 1e-13 * max(1.0, np.max(np.abs(want)))


def test_history_locator_on_its_own_past_mesh() -> None:
    """The past's mesh moved against the period's: u a polynomial of degree m in t (every
    piecewise interpolant of it is itself), its integral by quad."""
    T, L, periods = 1.3, 7, 2
    mesh = mesh_of(L, T, 3)
    hist = mesh.copy()
    hist[1:-1] += 0.02 * np.sin(np.arange(1, L))       # the switching times moved
    coef = np.random.default_rng(4).standard_normal((M + 1, N))

    def p(t: float) -> np.ndarray:
        return np.array([np.polyval(coef[:, i], t) for i in range(N)])

    rows = history_rows(L, M, periods)
    U = np.zeros((rows, N))
    for i in range(L):
        for k in range(M + 1):
            U[i * M + k] = p(mesh[i] + k * (mesh[i + 1] - mesh[i]) / M)
    base = L * M + 1
    for per in range(1, periods + 1):
        for i in range(L):
            g = (periods - per) * L + i
            for k in range(M + 1):
                U[base + g * (M + 1) + k] = p(hist[i] + k * (hist[i + 1] - hist[i]) / M - per * T)
    times = np.array([0.1, 0.5, 0.77, 1.2])
    tau = 2.1
    G, _ = delay_matrix(times, tau, mesh, T, kernel, history_locator(mesh, hist, M, periods),
                        Basis(M, Q), N, rows, pattern=PATTERN)
    got = (G @ U.ravel()).reshape(-1, N)
    cuts = np.concatenate([mesh, hist - T, hist - 2 * T])
    for c, t in enumerate(times):
        want = reference(t, tau, p, cuts)
        assert np.max(np.abs(got[c] - want)) < 1e-13 * max(1.0, np.max(np.abs(want)))



@pytest.mark.parametrize("tau", [0.05, 0.7, 2.3])
def test_plan_follows_the_mesh(tau: float) -> None:
    """DelayPlan (the pieces kept while no crossing enters or leaves a memory) made on one mesh
    and used on meshes that scale with T (an autonomous orbit's Newton iterates: by 1e-6 and 1e-3
    relative) or whose points 3..5 move by 1e-3 of the smallest interval (switching times
    moving), the times each mesh's Gauss points: against quad (tau = 0.05 inside one interval for
    some times); its T derivative (node values fixed in theta = t / T) against central
    differences of quad's integrals (Richardson); a move that brings a crossing into a memory
    does not fit."""
    T0, L = 1.3, 9
    grid = mesh_of(L, 1.0, 1)
    U = np.random.default_rng(2).standard_normal((L * M, N))
    gz = Basis(M, Q).gauss()[0]

    def times(mesh: np.ndarray) -> np.ndarray:
        return (mesh[:-1, None] + np.diff(mesh)[:, None] * gz[None, :]).ravel()[::3]

    def integrals(mesh: np.ndarray) -> np.ndarray:
        T = mesh[-1]

        def u(t: float) -> np.ndarray:
            i = min(int(np.searchsorted(mesh, t % T, side="right")) - 1, L - 1)
            rows = (i * M + np.arange(M + 1)) % (L * M)
            return lagrange(mesh[i], mesh[i + 1] - mesh[i], U[rows], t % T)
        cuts = (mesh[:, None] + T * np.arange(-4, 3)[None, :]).ravel()
        return np.array([reference(t, tau, u, cuts) for t in times(mesh)])

    ia, ib = np.nonzero(PATTERN)
    plan = DelayPlan(times(T0 * grid), T0 * grid, tau, T0, lambda s: kernel(s)[:, ia, ib],
                     Basis(M, Q), N, L * M, PATTERN)
    moved = T0 * grid
    moved[3:6] += 1e-3 * np.min(np.diff(moved))
    for mesh in (T0 * grid, T0 * (1 + 1e-6) * grid, T0 * (1 - 1e-3) * grid, moved):
        G, _ = plan.matrix(times(mesh), mesh, mesh[-1])
        want = integrals(mesh)
        assert np.max(np.abs((G @ U.ravel()).reshape(-1, N) - want)) < 1e-13 * np.max(np.abs(want))

    def central(step: float) -> np.ndarray:
        return (integrals((T0 + step) * grid) - integrals((T0 - step) * grid)) / (2 * step)
    fd = (4.0 * central(5e-5 * T0) - central(1e-4 * T0)) / 3.0     # Richardson: O(step^4)
    dT = plan.matrix(times(T0 * grid), T0 * grid, T0, slope_of=U)[1]
    assert np.max(np.abs(dT - fd)) < 1e-8 * np.max(np.abs(fd))
    assert plan.matrix(times(1.3 * T0 * grid), 1.3 * T0 * grid, 1.3 * T0) is None
