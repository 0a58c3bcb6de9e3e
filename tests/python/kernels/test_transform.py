# dmi._transform against mpmath: phi1 in 50 digits, Hhat and the cell weights by mpmath quadrature of the
# kernel's own formula.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import mpmath as mp
import numpy as np
import pytest

from dmi import _transform as tr

mp.mp.dps = 40


def phi1_mp(z):
    z = mp.mpc(z)
    return mp.mpf(1) if z == 0 else mp.expm1(z) / z


@pytest.mark.parametrize("z", [0.0, 1e-300, -1e-12, 3e-9, 1e-6 + 2e-6j, 4e-6j, 1e-5, -0.37, 0.5 + 3j,
                               -2.0 - 0.25j, -40.0 + 1j, 1e-3j, 2 * np.pi * 1j, 1j * np.pi, 30.0,
                               -800.0, 7e-6 - 7e-6j])
def test_phi1_against_mpmath(z):
    got = complex(tr.phi1(np.complex128(z)))
    ref = complex(phi1_mp(z))
    assert abs(got - ref) <= 4e-16 * abs(ref) + 1e-300
    if np.imag(z) == 0:  # the real path gives the same, as a real number
        r = tr.phi1(np.float64(np.real(z)))
        assert r.dtype == np.float64 and abs(float(r) - ref.real) <= 4e-16 * abs(ref)


def test_phi1_vectorised_shapes():
    z = np.linspace(-1, 1, 12).reshape(3, 4)
    assert tr.phi1(z).shape == (3, 4)
    assert tr.phi1(z + 0j).shape == (3, 4)


# a 2 x 2 matrix kernel: a real decaying term, a damped cosine/sine and an undamped oscillation
A = np.array([-1.5, -0.3, 0.0])
B = np.array([0.0, 4.0, 7.0])
C = np.array([[[1.0, 0.2], [0.0, -0.5]], [[0.3, -1.0], [2.0, 0.1]], [[0.5, 0.0], [0.25, 1.0]]])
D = np.array([[[0.0, 0.0], [0.0, 0.0]], [[0.7, 0.0], [-0.4, 0.2]], [[0.0, -0.3], [0.0, 0.6]]])


def H_mp(s, i, j):
    return sum(mp.exp(A[k] * s) * (C[k, i, j] * mp.cos(B[k] * s) + D[k, i, j] * mp.sin(B[k] * s))
               for k in range(3))


def test_evaluate_matches_formula():
    s = np.array([0.0, 0.3, 1.7])
    got = tr.evaluate(s, A, B, C, D)
    for m, sv in enumerate(s):
        for i in range(2):
            for j in range(2):
                assert got[m, i, j] == pytest.approx(float(H_mp(sv, i, j)), rel=1e-14, abs=1e-15)


@pytest.mark.parametrize("lam", [0.0, 1.0, -0.8 + 2j, 3j, 0.2 - 7j])
def test_laplace_truncated_against_quadrature(lam):
    tau = 1.3
    got = tr.laplace(np.array([lam]), A, B, C, D, tau=tau)[0]
    for i in range(2):
        for j in range(2):
            ref = mp.quad(lambda s: H_mp(s, i, j) * mp.exp(-mp.mpc(lam) * s), [0, 0.4, 0.8, tau])
            assert abs(got[i, j] - complex(ref)) <= 1e-14 * (1 + abs(complex(ref)))


def test_laplace_infinite_tau():
    lam = np.array([0.5 + 1j, 2.0])
    got = tr.Hhat(lam, A[:2], B[:2], C[:2], D[:2])  # both decaying: Re lam > max a
    for m, lv in enumerate(lam):
        for i in range(2):
            for j in range(2):
                f = lambda s: sum(mp.exp(A[k] * s) * (C[k, i, j] * mp.cos(B[k] * s) + D[k, i, j]
                                                      * mp.sin(B[k] * s)) for k in range(2)) \
                    * mp.exp(-mp.mpc(lv) * s)
                ref = mp.quad(f, [0, 1, 5, 20, mp.inf])
                assert abs(got[m, i, j] - complex(ref)) <= 1e-13 * (1 + abs(complex(ref)))


def test_laplace_scalar_kernel_shape():
    out = tr.laplace(np.zeros((2, 3)), [-1.0], [0.0], [2.0], tau=1.0)
    assert out.shape == (2, 3)
    assert out[0, 0] == pytest.approx(2 * (1 - np.exp(-1.0)), rel=1e-15)


@pytest.mark.parametrize("theta", [1.0, 0.37])
def test_cell_weights_against_quadrature(theta):
    h, N = 0.21, 6
    got = tr.cell_weights(A, B, C, D, h=h, N=N, theta=theta)
    assert got.shape == (N, 2, 2)
    for l in range(N):
        hi = (l + (theta if l == N - 1 else 1)) * h
        for i in range(2):
            for j in range(2):
                ref = mp.quad(lambda s: H_mp(s, i, j), [l * h, hi])
                assert abs(got[l, i, j] - float(ref)) <= 2e-16 * 8


def test_cell_weights_constant_and_tiny_h():
    # the constant kernel: every full cell weighs h, the partial one theta h
    w = tr.cell_weights([0.0], [0.0], [3.0], h=1e-9, N=4, theta=0.5)
    assert np.allclose(w, 3e-9 * np.array([1, 1, 1, 0.5]), rtol=1e-15, atol=0)


def test_bad_arguments():
    with pytest.raises(ValueError):
        tr.cell_weights([0.0], [0.0], [1.0], h=-1.0, N=3)
    with pytest.raises(ValueError):
        tr.cell_weights([0.0], [0.0], [1.0], h=1.0, N=3, theta=1.5)
    with pytest.raises(ValueError):
        tr.laplace(1.0, [0.0, 1.0], [0.0], [1.0, 1.0])
