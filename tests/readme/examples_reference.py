#!/usr/bin/env python3
# The models of examples/chain and examples/box computed independently of libdmi: the scheme
# (3.12)-(3.13) written out in numpy (the delay sum as a plain sum over the N lags, the kernel
# sampled from its formula, the resolvent of the friction a soft threshold and of the box a
# clip), then compared with the CSV the example printed.
#   examples_reference.py chain|box N T stride CSV
# Exit status 0 when every printed value agrees to 1e-9 (absolute, values of order 1), else 1;
# for box also when a printed state leaves K.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import sys

import numpy as np


def chain():
    m1, m2, k1, k2, mu1, mu2, F, om, tau = 1.0, 0.5, 4.0, 2.0, 1.2, 0.5, 1.5, 1.7, 5.0
    g, theta = [3.0, 1.0, 0.5], [0.05, 0.5, 2.0]

    def f(t, u):
        return np.array([-u[2], -u[3], ((k1 + k2) * u[0] - k2 * u[1] - F * np.cos(om * t)) / m1,
                         k2 * (u[1] - u[0]) / m2])

    def H(s):
        h = np.zeros((4, 4))
        for gk, th in zip(g, theta):
            h[2, 0] += np.exp(-s / th) * gk / m1
            h[3, 1] += np.exp(-s / th) * gk / (2 * m2)
        return h

    alpha = np.array([0, 0, mu1 / m1, mu2 / m2])

    def resolvent(lam, x):
        return np.sign(x) * np.maximum(np.abs(x) - lam * alpha, 0)

    return 4, tau, f, H, resolvent, np.array([0.5, 0, 0, 0]), None


def box():
    tau = 2.0
    M = np.array([[0.1, -2, 0], [2, 0.1, 0], [0, 0, 0.5]])
    lo, hi = np.array([-1, -1, 0.0]), np.array([1, 1, np.inf])

    def f(t, u):
        return M @ u - np.array([1.5 * np.cos(t), 0, 0.8 * np.sin(3 * t)])

    def H(s):
        return 0.7 * np.exp(-2 * s) * np.eye(3)

    def resolvent(lam, x):
        return np.clip(x, lo, hi)

    return 3, tau, f, H, resolvent, np.array([0.5, 0, 0.2]), (lo, hi)


def scheme(model, N, T, stride):
    n, tau, f, H, resolvent, z, _ = model
    h = tau / N
    steps = int(T / h + 0.5)
    Hs = np.array([H(l * h) for l in range(N)])               # H(l h), l = 0..N-1
    U = np.zeros((N + steps + 1, n))                          # U[N + p] = U^p, p = -N..steps
    U[: N + 1] = z
    rows = []
    for p in range(steps + 1):
        if p % stride == 0:
            rows.append([p * h, *U[N + p]])
        if p == steps:
            break
        lags = U[p + 1: N + p + 1][::-1]                      # U^{p-l}, l = 0..N-1
        W = h * np.einsum("lij,lj->i", Hs, lags)
        U[N + p + 1] = resolvent(h, U[N + p] - h * f(p * h, U[N + p]) - h * W)
    return np.array(rows)


def main(argv):
    if len(argv) != 6:
        print("usage: examples_reference.py chain|box N T stride CSV", file=sys.stderr)
        return 2
    name, N, T, stride, csv = argv[1], int(argv[2]), float(argv[3]), int(argv[4]), argv[5]
    model = {"chain": chain, "box": box}[name]()
    got = np.loadtxt(csv, delimiter=",", skiprows=1)
    want = scheme(model, N, T, stride)
    if got.shape != want.shape:
        print(f"{name}: {got.shape[0]} rows of {got.shape[1]} columns printed, {want.shape} expected")
        return 1
    err = np.max(np.abs(got - want))
    print(f"{name}: {got.shape[0]} rows, max |example - independent scheme| = {err:.2e}, "
          f"max |u| = {np.max(np.abs(want[:, 1:])):.3g}")
    ok = err <= 1e-9
    if name == "chain":     # the friction must matter: each mass sticks (v = 0) at some printed times
        stuck = np.mean(got[:, 3:5] == 0, axis=0)
        print(f"chain: v1 = 0 in {100 * stuck[0]:.0f} %, v2 = 0 in {100 * stuck[1]:.0f} % of the rows")
        ok = ok and bool(np.all(stuck > 0.02))
    if model[6] is not None:
        lo, hi = model[6]
        inside = np.all((got[:, 1:] >= lo) & (got[:, 1:] <= hi))
        contact = np.mean(np.any(np.isclose(got[:, 1:], lo) | np.isclose(got[:, 1:], hi), axis=1))
        print(f"{name}: every state in K: {inside}; on a face of K in {100 * contact:.0f} % of the rows")
        ok = ok and inside and contact > 0.1      # the box must actually constrain the motion
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
