# examples/python/two_mass_chain.py runs as a user runs it (a program, numba
# callbacks, matplotlib): it writes its plot, and its trajectory is the scheme
# (3.12)-(3.13) computed here independently, in plain NumPy with the direct
# delay sum (libdmi computes it by the recursion of exponential terms).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).parents[3])) / "examples" / "python" / \
    "two_mass_chain.py"


def load_model():
    spec = importlib.util.spec_from_file_location("two_mass_chain", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def numpy_scheme(m, T: float, N: int) -> np.ndarray:
    """U^p, p = 0..T/h, of U^{p+1} = R(U^p - h f(t_p, U^p) - h W^p), W^p = h sum_{l<N} H(l h) U^{p-l},
    R the soft threshold of the friction on v, U = 0 on [-tau, 0]."""
    h = m.TAU / N
    steps = round(T / h)
    Kx = m.stiffness()
    mass = np.array([m.M1, m.M2])
    alpha = np.array(m.MU) / mass
    H = np.zeros((N, 4, 4))  # H(l h): sum_k g_k exp(-l h / theta_k) M^-1 K in the block (v, x)
    s = np.arange(N) * h
    for g, theta in zip(m.G, m.THETA):
        H[:, 2:, :2] += g * np.exp(-s / theta)[:, None, None] * (Kx / mass[:, None])
    U = np.zeros((N + steps + 1, 4))  # U[N + p] = U^p
    for p in range(steps):
        u, t = U[N + p], p * h
        x, v = u[:2], u[2:]
        f = np.concatenate([-v, (Kx @ x - np.array([0.0, m.FORCE * np.cos(m.OMEGA * t)])) / mass])
        past = U[p + 1:N + p + 1][::-1]  # U^{p-l}, l = 0..N-1
        W = h * np.einsum("lij,lj->i", H, past)
        X = u - h * f - h * W
        out = X.copy()
        out[2:] = np.sign(X[2:]) * np.maximum(np.abs(X[2:]) - h * alpha, 0.0)
        U[N + p + 1] = out
    return U[N:]


def test_two_mass_chain(tmp_path):
    pytest.importorskip("numba")
    pytest.importorskip("matplotlib")
    T, N = 12.0, 400
    png, csv = tmp_path / "chain.png", tmp_path / "chain.csv"
    r = subprocess.run([sys.executable, str(EXAMPLE), "--T", str(T), "--N", str(N), "--out", str(png),
                        "--csv", str(csv)], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert f"{round(T * N / 2)} steps of h = 0.005" in r.stdout and "mass 2 sticks" in r.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20000
    got = np.loadtxt(csv, delimiter=",", skiprows=1)
    want = numpy_scheme(load_model(), T, N)
    assert got.shape == (len(want), 5)
    assert np.array_equal(got[:, 0], np.arange(len(want)) * (2.0 / N))
    dev = np.abs(got[:, 1:] - want).max()
    print(f"two-mass chain: max |U - U_numpy| = {dev:.2e}, max |U| = {np.abs(want).max():.3f}")
    assert dev <= 1e-10 and np.abs(want).max() > 0.1
    assert (want[1:, 2:] == 0).any(axis=0).all()  # both masses stick at some time (the friction acts)
    assert np.array_equal(got[:, 3:] == 0, want[:, 2:] == 0)


def test_docs_first_snippet():
    """The first Python block of docs/python.md runs and gives the shapes its comment says."""
    import re
    page = (EXAMPLE.parents[2] / "docs" / "python.md").read_text()
    code = re.findall(r"```python\n(.*?)```", page, re.S)[0]
    scope: dict = {}
    exec(code, scope)
    assert "t: (3001,), U: (3001, 2)" in code
    assert scope["t"].shape == (3001,) and scope["U"].shape == (3001, 2) and scope["t"][-1] == 30.0
    assert (scope["U"][1:, 1] == 0).any() and abs(scope["U"][:, 1]).max() > 0.01  # stick and slip
