# dmi.kernels.fit against independent oracles: a kernel that is itself an exponential sum, the
# Braess-Hackbusch term bound for 1/(1+s), s^-1/2 checked on 1e4 log-spaced points, noisy samples.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import math
import pickle
import subprocess
import sys

import numpy as np
import pytest

from dmi import kernels


def paper_kernel(s):
    return np.cos(2 * np.pi * s) + np.cos(10 * np.pi * s) + np.cos(20 * np.pi * s)


def test_paper_kernel_is_found_as_three_cosines():
    f = kernels.fit(paper_kernel, 1.0, tol=1e-12)
    assert f.terms == 3
    assert f.max_error <= 1e-12
    order = np.argsort(f.b)
    assert np.allclose(f.b[order], [2 * np.pi, 10 * np.pi, 20 * np.pi], rtol=1e-10)
    assert np.all(np.abs(f.a) <= 1e-9) and np.all(f.a <= 0)
    assert np.allclose(f.C[order], 1.0, atol=1e-10) and np.allclose(f.D, 0.0, atol=1e-10)
    s = np.linspace(0, 1, 20011)  # independent check on another grid
    assert np.max(np.abs(f(s) - paper_kernel(s))) <= 1e-12


def braess_hackbusch_terms(R, eps):
    """The fewest k with 16 exp(-pi^2 k / log(8 R)) <= eps (1/x on [1, R])."""
    return math.ceil(math.log(16 / eps) * math.log(8 * R) / math.pi ** 2)


def test_one_over_one_plus_s_within_braess_hackbusch():
    f = kernels.fit(lambda s: 1 / (1 + s), 9.0, tol=1e-8)
    bound = braess_hackbusch_terms(10, 1e-8)
    assert bound == 10
    assert f.terms <= bound
    s = np.linspace(0, 9, 100_001)
    assert np.max(np.abs(f(s) - 1 / (1 + s))) <= 1e-8
    assert np.all(f.a <= 0)
    assert f.coefficient_sum() <= 2.0  # max |H| = 1: no large cancelling terms


def test_power_kernel_relative_on_log_points():
    f = kernels.fit(kernels.PowerKernel(0.5), 1.0, tol=1e-8, relative=True, delta=1e-4)
    s = np.geomspace(1e-4, 1, 10_000)
    assert np.max(np.abs(f(s) * np.sqrt(s) - 1)) <= 1e-8
    # the Laplace quadrature of s^-1/2 has about 190 nodes at this tol; compressed, the numerical rank of
    # the kernel's exponential functions on [1e-4, 1] at 1e-8 (docs/kernels.md): about 40 terms
    assert f.terms <= 42
    assert f.certified
    assert np.all(f.a < 0) and np.all(f.b == 0) and np.all(f.C > 0)  # positive weights: no cancellation
    assert f.coefficient_sum() <= 5 * 100  # max |H| on [delta, tau] = 100
    with pytest.warns(UserWarning, match="meets tol"):  # too few terms allowed: not certified
        g = kernels.fit(kernels.PowerKernel(0.5), 1.0, tol=1e-8, relative=True, delta=1e-4, max_terms=20)
    assert g.terms <= 20 and not g.certified
    assert np.max(np.abs(g(s) * np.sqrt(s) - 1)) > 1e-8


def test_noisy_samples_saturate():
    rng = np.random.default_rng(7)

    def true(s):
        return np.exp(-s) + 0.5 * np.exp(-2 * s) * np.cos(6 * s)
    counts = []
    for M, tol in ((2001, 1e-8), (4001, 1e-10), (2001, 1e-12)):
        s = np.linspace(0, 5, M)
        v = true(s) + 1e-6 * rng.standard_normal(M)
        with pytest.warns(UserWarning, match="noise"):  # tol is below the noise
            f = kernels.fit(None, 5.0, tol=tol, samples=(s, v))
        counts.append(f.terms)
        assert np.all(f.a <= 0)
        assert f.max_error <= 1e-5  # measured against the samples: near the noise
        fine = np.linspace(0, 5, 50_001)
        assert np.max(np.abs(f(fine) - true(fine))) <= 1e-5
    assert max(counts) <= 4  # a real term and a cosine: no term chasing the noise
    assert len(set(counts)) == 1


def test_matrix_kernel_shares_exponents():
    def H(s):
        s = np.asarray(s)[..., None, None]
        return np.exp(-s) * np.array([[1.0, 0.5], [0.0, 2.0]]) + np.exp(-3 * s) * np.cos(2 * s) \
            * np.array([[0.0, 1.0], [1.0, -1.0]])
    f = kernels.fit(H, 2.0, tol=1e-10)
    assert f.terms == 2 and f.C.shape == (2, 2, 2)
    s = np.linspace(0, 2, 4001)
    assert np.max(np.abs(f(s) - H(s))) <= 1e-10


def test_pickle_and_solution_bound():
    f = kernels.fit(lambda s: 1 / (1 + s), 9.0, tol=1e-6)
    g = pickle.loads(pickle.dumps(f))
    assert np.array_equal(g.a, f.a) and np.array_equal(g.C, f.C) and g.terms == f.terms
    # kernel_l1 = int_0^9 1/(1+s) = log 10
    assert f.kernel_l1 == pytest.approx(math.log(10), rel=1e-8)
    L, T, U = 0.5, 2.0, 3.0
    gam = L + math.log(10)
    assert f.solution_bound(T, L, U) == pytest.approx(f.l1_error * U * math.expm1(gam * T) / gam, rel=1e-6)
    h = 0.01
    assert f.solution_bound(T, L, U, h=h) == pytest.approx(f.l1_error * U * ((1 + h * gam) ** 200 - 1) / gam,
                                                           rel=1e-6)
    assert f.solution_bound(T, L, U, h=h) <= f.solution_bound(T, L, U)  # (1 + x)^n <= e^{n x}
    assert 0 < f.l1_error <= 9 * f.max_error


def test_bad_arguments():
    with pytest.raises(ValueError):
        kernels.fit(lambda s: s, -1.0)
    with pytest.raises(ValueError):
        kernels.fit(lambda s: s, 1.0, delta=2.0)
    with pytest.raises(ValueError):
        kernels.fit(None, 1.0)
    with pytest.raises(ValueError):
        with np.errstate(divide="ignore"):
            kernels.fit(lambda s: s ** -0.5, 1.0)  # infinite at 0: needs delta
    with pytest.raises(ValueError):
        kernels.PowerKernel(-0.5)


def test_console_script_formats(tmp_path):
    run = [sys.executable, "-m", "dmi.kernels", "--expr", "np.exp(-2*s)*np.cos(3*s)", "--tau", "1",
           "--tol", "1e-10"]
    out = subprocess.run(run + ["--format", "json"], capture_output=True, text=True, timeout=120, check=True)
    d = json.loads(out.stdout)
    assert d["terms"] == 1
    assert d["a"][0] == pytest.approx(-2, rel=1e-8) and d["b"][0] == pytest.approx(3, rel=1e-8)
    c = subprocess.run(run + ["--format", "c", "--name", "k"], capture_output=True, text=True, timeout=120,
                       check=True).stdout
    assert "enum { k_K = 1 };" in c and "static const double k_a[1]" in c
    src = tmp_path / "k.c"
    src.write_text("#include <math.h>\n" + c + "int main(void) { return fabs(k_a[0] + k_b[0] + k_C[0] + k_D[0] - 2)"
                   " < 1e-6 ? 0 : 1; }\n")
    cc = subprocess.run(["cc", "-std=c99", "-Wall", "-Werror", str(src), "-o", str(tmp_path / "k")],
                        capture_output=True, text=True, timeout=60)
    assert cc.returncode == 0, cc.stderr
    assert subprocess.run([str(tmp_path / "k")], timeout=10).returncode == 0  # -2 + 3 + 1 + 0 = 2
    ftn = subprocess.run(run + ["--format", "fortran"], capture_output=True, text=True, timeout=120,
                         check=True).stdout
    assert "data kernel_a" in ftn and "kernel_K = 1" in ftn
    bad = subprocess.run([sys.executable, "-m", "dmi.kernels", "--expr", "1/(1+s)", "--tau", "-1"],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "tau" in bad.stderr
