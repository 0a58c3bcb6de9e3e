# The friction oscillator of the tau-diagram (examples/python/oscillator_tau.toml) continued in
# the delay tau with dmi.analysis, over the sweep's brute-force diagram (scripts/main.sh runs it).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""w'' + w + int_0^tau 0.5 w(t - s) ds + sigma(w') + 1.3 cos(0.5 t) ∋ 0 over tau.

As u = (w, v): u' + A(u) + f(t, u) + int_0^tau H u(t - s) ds ∋ 0 with f = (-v, w + 1.3 cos 0.5 t),
A = (0, sigma(v)), H = [[0, 0], [0.5, 0]] (a constant kernel: the O(1) recursion).  The forcing
period P = 4 pi is M steps of h = P / M for every tau (libdmi 1.2's free step: N = ceil(tau / h)
changes with tau, the state gains rows by periodicity).  The period-1 orbit is found at tau_0
from a plain run (the solver is the guess), continued down to tau_min and up to tau_1; the
branch born at the first period doubling is continued too.  Writes OUT/orbit_tau.png (over
OUT/sweep_ex43 when it exists) and OUT/orbit_tau.csv (tau, period, branch, w on the section,
stable, events).

Usage: python orbit_tau.py OUT [--M 4000] [--tau0 2.0] [--tau-min 1.9] [--tau1 3.1] [--step 0.02]
"""
from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

import dmi
from dmi.analysis import continue_orbit, period_doubled_orbit, periodic_orbit, plot_branch

P = 4 * np.pi  # forcing period 2 pi / 0.5


def model(M: int):
    """make(tau) with h = P / M (numba cfunc right-hand side when numba is there)."""
    h = P / M
    try:
        import numba

        @numba.cfunc(dmi.RHS_SIGNATURE)
        def rhs(t, u, out, user):
            out[0] = -u[1]
            out[1] = u[0] + 1.3 * np.cos(0.5 * t)
            return 0
    except ImportError:  # pragma: no cover
        def rhs(t, u):
            return np.array([-u[1], u[0] + 1.3 * np.cos(0.5 * t)])

    C = np.array([[[0.0, 0.0], [0.5, 0.0]]])

    def make(tau: float) -> dmi.Solver:
        if not 0 < tau <= 6:
            raise ValueError(f"tau = {tau}: the model is defined for 0 < tau <= 6")
        s = dmi.Solver(2, tau, h=h)
        s.set_rhs(rhs)
        s.set_friction([0.0, 1.0])
        s.set_kernel_exp([0.0], [0.0], C)
        return s
    return make


def compare(branches, df) -> None:
    """Prints how far the sweep's Poincare points lie from the stable parts of the branches: at
    each swept tau covered by a stable stretch (two consecutive stable points) of some branch,
    the largest distance from a sweep point to the nearest section value of a covering stretch
    (linear in tau).  Runs from rest reach one attractor: a stable branch the runs do not reach
    (multistability) does not count against it."""
    stretches = []
    for br in branches:
        sec = [q.section[:, 0] for q in br.points]
        for i in range(1, len(br.points)):
            a, b = br.points[i - 1], br.points[i]
            if a.stable and b.stable and a.p != b.p:
                stretches.append((min(a.p, b.p), max(a.p, b.p), a.p, b.p, sec[i - 1], sec[i]))
    worst, count, at = 0.0, 0, float("nan")
    for tau, w in zip(df["tau"], df["w_poincare"]):
        refs = [ya + (tau - pa) / (pb - pa) * (yb - ya)
                for lo, hi, pa, pb, ya, yb in stretches if lo <= tau <= hi]
        if not refs:
            continue
        ref = np.concatenate(refs)
        d = np.abs(np.asarray(w, float)[:, None] - ref[None, :]).min(axis=1).max()
        if d > worst:
            at = tau
        worst, count = max(worst, float(d)), count + 1
    print(f"the sweep's points at the {count} values of tau on a stable stretch lie within "
          f"{worst:.3g} of it (the farthest at tau = {at:g}; the sweep's h = tau / 1e4, the "
          "branches' h = 4 pi / M)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--M", type=int, default=4000, help="steps per forcing period")
    ap.add_argument("--tau0", type=float, default=2.0, help="start (continued both ways)")
    ap.add_argument("--tau-min", type=float, default=1.9)
    ap.add_argument("--tau1", type=float, default=3.1)
    ap.add_argument("--step", type=float, default=0.02)
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    make = model(a.M)
    t0 = time.perf_counter()
    s = make(a.tau0)
    s.init()
    s.advance(60 * a.M)  # onto the attractor: 60 forcing periods
    orbit = periodic_orbit(make, a.tau0, P, s, multipliers=8)
    print(f"orbit at tau = {a.tau0}: {orbit.iterations} Newton iterations, |mu_1| = "
          f"{abs(orbit.multipliers[0]):.4f}, stick fraction {orbit.stick_fraction[1]:.3f}")
    down = continue_orbit(orbit, a.tau_min, step=a.step / 2, max_step=a.step, multipliers=8)
    print(f"period 1 down to tau = {a.tau_min}: {len(down.points)} points, {down.status}")
    b = continue_orbit(orbit, a.tau1, step=a.step, max_step=2 * a.step, multipliers=8)
    branches = [down, b]
    print(f"period 1: {len(b.points)} points, {b.status}")
    for e in b.events:
        print(f"  {e.kind} at tau = {e.p:.4f}: {e.detail}")
    pd = [e for e in b.events if e.kind == "period-doubling"]
    if pd:
        try:
            o2 = period_doubled_orbit(b, pd[0], multipliers=8)
            b2 = continue_orbit(o2, a.tau1, step=a.step, max_step=2 * a.step, multipliers=8,
                                sections=2)
            branches.append(b2)
            print(f"period 2 from tau = {o2.p:.4f}: {len(b2.points)} points, {b2.status}")
            for e in b2.events:
                print(f"  {e.kind} at tau = {e.p:.4f}: {e.detail}")
        except Exception as e:  # the figure is still worth having
            print(f"period 2: not continued: {e}")
    print(f"continuation: {time.perf_counter() - t0:.0f} s")
    with open(out / "orbit_tau.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["branch", "tau", "period", "section", "w", "stable", "stick_fraction"])
        for k, br in enumerate(branches):
            for q in br.points:
                for j, row in enumerate(q.section):
                    w.writerow([k + 1, q.p, q.period, j, row[0], int(q.stable),
                                q.stick_steps[1] / a.M / br.sections])
        for k, br in enumerate(branches):
            for e in br.events:
                w.writerow([f"event {k + 1}", e.p, "", e.kind, "", "", ""])
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5), dpi=120)
    sweep = out / "sweep_ex43"
    if sweep.is_dir():
        import pandas as pd_
        df = pd_.read_parquet(sweep)
        df = df[df["error"].isna()] if "error" in df else df
        xs = np.concatenate([np.full(len(v), x) for x, v in zip(df["tau"], df["w_poincare"])])
        ys = np.concatenate([np.asarray(v, float) for v in df["w_poincare"]])
        ax.plot(xs, ys, ".", color="0.6", markersize=2, zorder=1)
        compare(branches, df)
        ax.text(0.02, 0.03, "grey dots: dmi-sweep, w at t = k 4\u03c0, t \u2208 [400, 800], "
                "h = \u03c4/10\u2074", transform=ax.transAxes, fontsize=8, color="0.35")
    for br, colour in zip(branches, ("C0", "C0", "C3")):
        plot_branch(br, ax, component=0, color=colour)
    ax.set_xlabel("delay \u03c4")
    ax.set_ylabel("displacement w at t = k 4\u03c0 (Poincar\u00e9 section)")
    ax.set_title(f"Periodic orbits over \u03c4: period 1 (blue), period 2 (red); solid stable, "
                 f"dashed unstable; M = {a.M}", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "orbit_tau.png")
    print(f"wrote {out / 'orbit_tau.png'} and {out / 'orbit_tau.csv'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
