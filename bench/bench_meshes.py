#!/usr/bin/env python3
# The adaptive mesh and the error estimate of collocate against true errors (a benchmark, not a
# test): van der Pol with a distributed delay, w'' + eps (w^2 - 1) w' + w + a int_0^1 w(t - s) ds
# = 0, a = 0.5, at eps = 1 (degree 4 to 6) and its relaxation oscillation at eps = 10 (degree 6),
# each from a scheme orbit.  True errors against a collocation of degree 8 (80 intervals at eps =
# 1, 160 at eps = 10).  For each mesh: the true error of the period and the multipliers of the
# orbit returned (the finer level), the two-level difference and the three-level estimate
# (Richardson's where the levels are steady) over it; the Newton iterations and CPU time of each
# level: the orbit on the mesh, the halved mesh from its solution (transfer) and from the start,
# the merged mesh.  Then the refinement to several tol (eps = 1, degree 4, and not --small 5, 6
# and 8; eps = 5, degrees 5 and 4; eps = 10, degree 6 and the default 4; eps = 0.5 and 3, degree
# 3): the orbit returned against
# the smallest sufficient mesh of a scan and their ratio, its true error and estimate; and (not --small) the period's errors on nested levels and their local
# orders (eps = 1, degree 4: why a two-level estimate of one order cannot be both never below
# and within 10 x), and the estimate by degree elevation on one mesh: the orbit of degree 6
# against 7 and 8 on the same mesh, re-equidistributed 1 to 3 times, and the halved mesh;
# --scan: the estimate against the true error on every mesh of a scan of nine orbits and degrees;
# --multipliers-scan: the multipliers' default estimate against the true error on the scan's
# smooth orbits;
# --check-cost: collocate with check=True against without (CPU, interleaved, and estimates);
# --rounding: the period on several meshes and degrees where truncation is below rounding.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_meshes.py
#        [--small | --scan | --multipliers-scan | --rounding
#         | --check-cost [--rounds N]]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import dmi  # noqa: E402
from dmi import analysis as da  # noqa: E402
from dmi.analysis.collocation import adapt  # noqa: E402
from dmi.analysis.collocation.collocate import first_solve  # noqa: E402
from dmi.analysis.collocation.floquet import multipliers as floquet  # noqa: E402
from dmi.analysis.collocation.signature import read_signature  # noqa: E402
from dmi.analysis.collocation.system import Layout, Terms, carried, reference, solve  # noqa: E402
from dmi.analysis.scheme.stepmap import build  # noqa: E402


def van_der_pol(eps: float):
    def make(p: float, h: float | None = None) -> dmi.Solver:
        s = dmi.Solver(2, 1.0, h=h or 0.01)
        s.set_rhs(lambda t, u: np.array([-u[1], eps * (u[0] ** 2 - 1) * u[1] + u[0]]))
        s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p, 0.0]]])
        return s
    return make


def scheme_orbit(eps: float, T: float, steps: int, a: float = 0.5) -> da.Orbit:
    make = van_der_pol(eps)
    s = make(a, h=T / steps)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(40 * steps)
    return da.periodic_orbit(make, a, None, s, guess_period=T, steps=steps, multipliers=0)


def timed_solve(lay, terms, x0, ref):
    t = time.process_time()
    x, res = solve(lay, terms, x0, ref)
    return x, len(res), time.process_time() - t


def mesh_row(o, ref, L: int, m: int) -> None:
    """One mesh: the levels' costs, the true errors and the estimates."""
    terms = Terms(build(o.make, o.p))
    sig, b0 = read_signature(o.u, o.h, terms.alpha, terms.lo, terms.hi)
    lay = Layout(m, terms.n, sig, [], True, o.period, carried(terms, sig))
    lay0, x0 = first_solve(o, terms, lay, b0, max(8, L // 2), "bench")
    r = reference(lay0, x0)
    lay1 = lay0.with_fractions(adapt.adapted(lay0, x0, L))
    x1, n1, t1 = timed_solve(lay1, terms, adapt.transfer(lay0, x0, lay1), r)
    fine = lay1.with_fractions(adapt.halved(lay1.fractions))
    x2, n2, t2 = timed_solve(fine, terms, adapt.transfer(lay1, x1, fine), r)
    _, n2s, t2s = timed_solve(fine, terms, adapt.transfer(lay0, x0, fine), r)
    low = lay1.with_fractions(adapt.merged(lay1.fractions))
    x3, n3, t3 = timed_solve(low, terms, adapt.transfer(lay1, x1, low), r)
    c, f, g = adapt.Solved(lay1, x1), adapt.Solved(fine, x2), adapt.Solved(low, x3)
    for s in (g, c, f):
        s.mu = floquet(s.lay, terms, s.x, 4)
    two = adapt.estimate(c, f)
    three = adapt.estimate(c, f, coarser=g)
    tT = abs(f.T - ref.period)
    k = 1                                          # the largest nontrivial multiplier
    tmu = float(np.min(np.abs(ref.multipliers - f.mu[k])))
    seen = tmu > 100 * np.spacing(max(1.0, abs(f.mu[k])))       # above 100 ulp
    mu = (f"{two['multipliers'][k] / tmu:8.3g} | {three['multipliers'][k] / tmu:8.3g}" if seen
          else f"{'-':>8} | {'-':>8}")
    print(f"{fine.L:4d} x {m} | {tT:9.2e} | {two['period'] / tT:8.3g} | {three['period'] / tT:8.3g}"
          f" | {tmu:9.2e} | {mu} | {n1}, {t1:.2f} s | {n2}, {t2:.2f} s | {n2s}, {t2s:.2f} s | "
          f"{n3}, {t3:.2f} s", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=(
        "Prints, for meshes of van der Pol with a distributed delay (eps = 1 and its relaxation "
        "oscillation at eps = 10), the true errors of the period and a multiplier, the two- and "
        "three-level estimates over them and the Newton cost of each level; then the "
        "refinements to several tol against the least sufficient mesh (--small: 1e-8 at eps = "
        "10)."))
    ap.add_argument("--small", action="store_true",
                    help="one mesh of each orbit (for CI; default: all meshes)")
    ap.add_argument("--scan", action="store_true",
                    help="only the period's estimate against its true error on every mesh of "
                         "a scan of nine orbits and degrees (about 2 minutes)")
    ap.add_argument("--check-cost", action="store_true",
                    help="only the CPU of collocate with check=True against without, "
                         "interleaved, and both estimates over the true error")
    ap.add_argument("--rounds", type=int, default=5, help="rounds of --check-cost (default: 5)")
    ap.add_argument("--multipliers-scan", action="store_true",
                    help="only the default estimate of the two leading nontrivial multipliers "
                         "against their true error on every mesh of the scan's six smooth "
                         "orbits (about 30 seconds)")
    ap.add_argument("--tol-scale", type=float, default=1.0,
                    help="every refinement's tol times this (3: the tols between the table's; "
                         "default: 1)")
    ap.add_argument("--rounding", action="store_true",
                    help="only the period of orbits whose truncation is below rounding, on "
                         "several meshes and degrees: the spread is the collocation's "
                         "rounding floor (about a minute)")
    a = ap.parse_args()
    if a.scan:
        scan()
        return
    if a.check_cost:
        check_cost(a.rounds)
        return
    if a.multipliers_scan:
        multipliers_scan()
        return
    if a.rounding:
        rounding()
        return
    print("mesh | period: true | 2-level/true | 3-level/true | mu_2: true | 2-level/true | "
          "3-level/true | Newton its, CPU: on L | 2L from L | 2L from start | L/2 from L")
    o1 = scheme_orbit(1.0, 6.0, 600)
    ref1 = da.collocate(o1, intervals=40, degree=8, multipliers=4)
    for L, m in ((24, 4),) if a.small else ((12, 4), (24, 4), (32, 4), (8, 5), (16, 5), (12, 6)):
        mesh_row(o1, ref1, L, m)
    o2 = scheme_orbit(10.0, 16.0, 1000)
    ref2 = da.collocate(o2, intervals=80, degree=8, multipliers=4)    # 160 x 8
    for L in (56,) if a.small else (40, 44, 48, 56, 64):
        mesh_row(o2, ref2, L, 6)
    if a.small:
        refinements(o2, ref2, 6, (1e-8,), (80, 88, 96, 104, 112), a.tol_scale)
        return
    cpu, k = 0.0, a.tol_scale
    cpu += refinements(o1, ref1, 4, (1e-5, 1e-6, 1e-7, 1e-8, 1e-10), tuple(range(4, 81)), k)
    nested_rows(o1, ref1, 4, (8, 10, 12, 16, 18, 20, 24, 32))
    cpu += refinements(o2, ref2, 6, (1e-5, 1e-6, 1e-7, 1e-8, 1e-9), tuple(range(40, 160, 4)), k)
    cpu += refinements(o2, ref2, 4, (1e-7, 1e-8, 1e-9, 1e-10), tuple(range(100, 500, 10)), k)
    for m in (5, 6, 8):
        cpu += refinements(o1, ref1, m, (1e-6, 1e-8, 1e-9, 1e-10), tuple(range(4, 48)), k)
    print("eps = 5 (a steep orbit whose first round of a loose tol cannot be solved), degree 5:")
    o5 = scheme_orbit(5.0, 9.0, 900)
    ref5 = da.collocate(o5, intervals=80, degree=8, multipliers=0)
    cpu += refinements(o5, ref5, 5, (1e-3, 1e-4, 1e-5, 1e-6), tuple(range(8, 80)), k)
    cpu += refinements(o5, ref5, 4, (1e-3, 1e-4, 1e-5, 1e-6), tuple(range(8, 120)), k)
    print("degree 3: eps = 0.5 and eps = 3:")
    for eps, T, steps, tols, sizes in ((0.5, 6.3, 630, (1e-2, 1e-3, 1e-4), range(4, 60)),
                                       (3.0, 8.0, 800, (1e-2, 1e-3, 1e-4, 1e-5), range(8, 120))):
        o = scheme_orbit(eps, T, steps)
        cpu += refinements(o, da.collocate(o, intervals=80, degree=8, multipliers=0), 3, tols,
                           tuple(sizes), k)
    print(f"the refinements' CPU: {cpu:.2f} s")
    print("same mesh, degree 6 against 7 and 8 (errors of the period; the mesh "
          "equidistributed k times at L intervals): 6 | 7 | 8 | |x6 - x8| / |err 6| | 6 on 2L")
    for L in (60, 70, 80, 90):
        degree_rows(o2, ref2, L, 6)


def period_on(o, L: int, m: int) -> float:
    """The period of the orbit on L intervals of degree m equidistributed from the first solve
    collocate makes (on max(8, L / 2) intervals): a mesh as a refinement's round solves it."""
    terms = Terms(build(o.make, o.p))
    sig, b0 = read_signature(o.u, o.h, terms.alpha, terms.lo, terms.hi)
    lay = Layout(m, terms.n, sig, [], True, o.period, carried(terms, sig))
    lay0, x0 = first_solve(o, terms, lay, b0, max(8, L // 2), "bench")
    new = lay0.with_fractions(adapt.adapted(lay0, x0, L))
    return float(solve(new, terms, adapt.transfer(lay0, x0, new), reference(lay0, x0))[0][-1])


def refinements(o, ref, m: int, tols: tuple, scan: tuple, scale: float = 1.0) -> float:
    """The refinement to each tol (times ``scale``; their CPU returned): the orbit returned (its
    intervals, true error, estimate and CPU) against the least L of ``scan`` whose orbit on L
    intervals (:func:`period_on`) has a true error within tol and against the least from which
    every L of the scan has (the errors of one L are a lottery of its equidistribution: not
    monotone in L), and their ratios."""
    errs = {}
    for L in scan:
        try:
            errs[L] = abs(period_on(o, L, m) - ref.period)
        except (ValueError, RuntimeError):          # Newton fails on a coarse mesh
            errs[L] = np.inf
    total = 0.0
    for tol in (t * scale for t in tols):
        t = time.process_time()
        e = da.collocate(o, degree=m, tol=tol, multipliers=0)
        cpu = time.process_time() - t
        total += cpu
        true = abs(e.period - ref.period)
        enough = next((L for L in scan if errs[L] <= tol), None)
        steady = next((L for i, L in enumerate(scan)
                       if all(errs[k] <= tol for k in scan[i:])), None)
        ratio = "; ".join(f"{name} {L}, returned / it {e.intervals / L:.3g}" if L else
                          f"{name} -" for name, L in (("least sufficient L", enough),
                                                      ("all from", steady)))
        print(f"degree {m}, tol = {tol:g}: {e.intervals} returned; true {true:.2e}, estimate "
              f"{e.errors['period']:.2e} ({e.errors['period'] / true:.3g} x); CPU {cpu:.2f} s; "
              f"{ratio}", flush=True)
    return total


def nested(o, terms, sig, b0, L: int, m: int, T_ref: float, every: bool = False):
    """The three nested levels that collocate(o, intervals=L, check=every) solves (L / 2, L,
    2 L; the finer's check where asked), the period's errors on them against T_ref and the
    local orders between them: (c, f, e, q)."""
    lay = Layout(m, terms.n, sig, [], True, o.period, carried(terms, sig))
    lay, x1 = first_solve(o, terms, lay, b0, max(8, L // 2), "bench")
    c, f = adapt.levels(lay, terms, x1, reference(lay, x1), L, True, 1e-10, "bench",
                        every=every)
    if c.coarser is None:
        return c, f, None, None
    e = [s.T - T_ref for s in (c.coarser, c, f)]
    return c, f, e, (float(np.log2(abs(e[0] / e[1]))), float(np.log2(abs(e[1] / e[2]))))


def nested_rows(o, ref, m: int, sizes: tuple) -> None:
    """The period's errors on the three nested levels (L / 2, L, 2 L, as collocate(o,
    intervals=L) makes them) and the local orders between them; then what a rule of one order
    for the finer level's error (|d2| / (2^q - 1)) gives: never below the true error only with
    q at most the least order seen, and then up to 2^(largest - least) above it."""
    terms = Terms(build(o.make, o.p))
    sig, b0 = read_signature(o.u, o.h, terms.alpha, terms.lo, terms.hi)
    print(f"nested levels, degree {m}: L | period errors on L/2, L, 2L | local orders "
          "(L/2 to L, L to 2L) | steady")
    seen = []
    for L in sizes:
        c, f, e, q = nested(o, terms, sig, b0, L, m, ref.period)
        seen.append(q[1])
        steady = adapt.level_error(c, f)[2] is not None
        print(f"{L:3d} | {e[0]:+.2e} {e[1]:+.2e} {e[2]:+.2e} | {q[0]:.1f} {q[1]:.1f} | "
              f"{'yes' if steady else 'no'}", flush=True)
    lo, hi = min(seen), max(seen)
    print(f"local order of the finer pair: {lo:.1f} to {hi:.1f} (theory {2 * m}); one order "
          f"never below the true error: q <= {lo:.1f}, over it up to {2 ** (hi - lo):.3g} x",
          flush=True)


def degree_rows(o, ref, L: int, m: int) -> None:
    """The degree-elevation estimate on one mesh re-equidistributed 1, 2, 3 times at L."""
    terms = Terms(build(o.make, o.p))
    sig, b0 = read_signature(o.u, o.h, terms.alpha, terms.lo, terms.hi)
    lay = Layout(m, terms.n, sig, [], True, o.period, carried(terms, sig))
    cur, x = first_solve(o, terms, lay, b0, max(8, L // 2), "bench")
    r = reference(cur, x)
    for k in range(1, 4):
        new = cur.with_fractions(adapt.adapted(cur, x, L))
        x = solve(new, terms, adapt.transfer(cur, x, new), r)[0]
        cur = new
        Ts = [x[-1]]
        for ly in (Layout(m + 1, cur.n, sig, cur.fractions, True, cur.period, cur.carried),
                   Layout(m + 2, cur.n, sig, cur.fractions, True, cur.period, cur.carried),
                   cur.with_fractions(adapt.halved(cur.fractions))):
            Ts.append(solve(ly, terms, adapt.transfer(cur, x, ly), r)[0][-1])
        err = [T - ref.period for T in Ts]
        print(f"L = {L}, k = {k}: {err[0]:+.2e} | {err[1]:+.2e} | {err[2]:+.2e} | "
              f"{abs(Ts[0] - Ts[2]) / abs(err[0]):.3g} | {err[3]:+.2e}", flush=True)



def check_cost(rounds: int) -> None:
    """collocate with check=True against without (the default multipliers, 10, and none: the
    multipliers' check is the monodromy on the mesh halved), in interleaved rounds (the order
    swapped every round, the fastest CPU of each kept): their ratio and both period estimates
    over the true error."""
    o1 = scheme_orbit(1.0, 6.0, 600)
    ref1 = da.collocate(o1, intervals=40, degree=8, multipliers=0)
    o2 = scheme_orbit(10.0, 16.0, 1000)
    ref2 = da.collocate(o2, intervals=80, degree=8, multipliers=0)
    cases = {"eps = 1, intervals = 40": (o1, ref1, {"intervals": 40}),
             "eps = 1, intervals = 40, no multipliers": (o1, ref1, {"intervals": 40,
                                                                    "multipliers": 0}),
             "eps = 1, tol = 1e-10": (o1, ref1, {}),
             "eps = 1, tol = 1e-10, no multipliers": (o1, ref1, {"multipliers": 0}),
             "eps = 1, intervals = 8, degree 6": (o1, ref1, {"intervals": 8, "degree": 6}),
             "eps = 1, tol = 1e-8, degree 6": (o1, ref1, {"tol": 1e-8, "degree": 6}),
             "eps = 10, tol = 1e-8, degree 6": (o2, ref2, {"tol": 1e-8, "degree": 6})}
    best = {(k, c): np.inf for k in cases for c in (False, True)}
    ratio, true = {}, {}
    for r in range(rounds):
        for k, (o, ref, kw) in cases.items():
            for c in ((False, True) if r % 2 == 0 else (True, False)):
                t = time.process_time()
                e = da.collocate(o, check=c, **kw)
                best[k, c] = min(best[k, c], time.process_time() - t)
                true[k, c] = abs(e.period - ref.period)
                ratio[k, c] = e.errors["period"] / true[k, c]
    print("case | CPU: default | check=True | ratio | the period's true error (default; "
          "check=True where another mesh) | estimate / true: default | check=True (at the "
          "floor, FLOOR T, where the true error is below it)")
    for k in cases:
        print(f"{k} | {best[k, False]:.3f} s | {best[k, True]:.3f} s | "
              f"{best[k, True] / best[k, False]:.2f} | {true[k, False]:.2g}"
              + (f", {true[k, True]:.2g}" if true[k, True] != true[k, False] else "")
              + f" | {ratio[k, False]:.3g} | {ratio[k, True]:.3g}", flush=True)


#: The scan's orbits: eps, a (0: no memory), the scheme's period guess and steps, degree, the
#: meshes L.
SCAN = ((1.0, 0.0, 6.0, 600, 4, range(6, 48)), (1.0, 0.5, 6.0, 600, 4, range(6, 48)),
        (1.0, 0.5, 6.0, 600, 5, range(4, 36)), (1.0, 0.5, 6.0, 600, 6, range(4, 30)),
        (1.0, 0.2, 6.0, 600, 4, range(6, 40)), (0.5, 0.5, 6.0, 600, 4, range(6, 40)),
        (10.0, 0.5, 16.0, 1000, 4, range(24, 120, 4)),
        (10.0, 0.5, 16.0, 1000, 5, range(20, 100, 4)), (10.0, 0.5, 16.0, 1000, 6, range(16, 72, 2)))


def scan() -> None:
    """The period's estimate of the orbit returned for intervals = L against its true error
    (degree 8 on 96 or 160 intervals; compared where above ten times that reference's own
    uncertainty, at least 1e-13, and 100 ulp) on every L of SCAN: how many meshes, how many
    checked (levels not steady or a graded mesh: the finer level against its mesh halved) and
    how many with Richardson's estimate, the estimate / true range of each kind, and
    every estimate below its true error with the orders its levels show; for each orbit, the
    range of the local orders of the levels' coarser pair (L/2 to L) and finer pair (L to 2L);
    and the Richardson meshes' estimate with check=True (the finer level checked there too)."""
    below, counts = [], {"Richardson (steady, not graded)": [], "checked": [],
                         "the Richardson meshes with check=True": []}
    for eps, p, T, steps, m, sizes in SCAN:
        o = scheme_orbit(eps, T, steps, p)
        big = 80 if eps >= 10 else 48
        ref = da.collocate(o, intervals=big, degree=8, multipliers=0)
        gap = max(abs(da.collocate(o, intervals=big + big // 5, degree=8,
                                   multipliers=0).period - ref.period), 1e-13)
        terms = Terms(build(o.make, o.p))
        sig, b0 = read_signature(o.u, o.h, terms.alpha, terms.lo, terms.hi)
        orders, mine = [], {k: [] for k in counts}
        for L in sizes:
            try:
                c, f, _, q = nested(o, terms, sig, b0, L, m, ref.period)
            except (ValueError, RuntimeError):     # Newton fails on a coarse relaxation mesh
                continue
            true = abs(f.T - ref.period)
            if q is None or true < 10 * gap or true < 100 * np.spacing(f.T):
                continue
            est = adapt.estimate(c, f)["period"]
            kind = "checked" if f.check is not None else "Richardson (steady, not graded)"
            counts[kind].append(est / true)
            mine[kind].append(est / true)
            if f.check is None:
                c2, f2, _, _ = nested(o, terms, sig, b0, L, m, ref.period, every=True)
                assert f2.T == f.T
                kind = "the Richardson meshes with check=True"
                counts[kind].append(adapt.estimate(c2, f2)["period"] / true)
                mine[kind].append(counts[kind][-1])
            orders.append(q)
            if est < true:
                below.append(f"eps = {eps:g}, a = {p:g}, degree {m}, L = {L}: estimate / true "
                             f"{est / true:.3g}, the levels' orders {q[0]:.1f} (L/2 to L) and "
                             f"{q[1]:.1f} (L to 2L)")
        q = np.array(orders).reshape(-1, 2)
        print(f"eps = {eps:g}, a = {p:g}, degree {m}: {len(q)} meshes, local orders L/2 to L "
              f"{q[:, 0].min():.1f} to {q[:, 0].max():.1f}, L to 2L {q[:, 1].min():.1f} to "
              f"{q[:, 1].max():.1f} (theory {2 * m}); "
              + "; ".join(f"{k}: {len(r)}" + (f", {min(r):.3g} to {max(r):.3g}" if r else "")
                          for k, r in mine.items()), flush=True)
    for kind, r in counts.items():
        r = np.array(r)
        if r.size:
            print(f"{kind}: {r.size} meshes, estimate / true {r.min():.3g} to {r.max():.3g}, "
                  f"within [1, 10] {int(np.sum((r >= 1) & (r <= 10)))}, below 1 "
                  f"{int(np.sum(r < 1))}")
    print("below the true error:" if below else "no estimate below its true error")
    for line in below:
        print("  " + line)



def rounding() -> None:
    """The period returned for intervals = L at degrees 6 to 8 on meshes fine enough that its
    truncation error (h^(2 m): it would fall with L and with the degree) is below rounding (van
    der Pol at eps = 1, the relaxation oscillation at eps = 10), and the spread of each degree
    and of all: what the solve's rounding and Newton's stopping leave, the floor an estimate
    cannot go below."""
    for eps, T, steps, rows in ((1.0, 6.0, 600, ((8, (30, 42, 54, 66)), (6, (40, 60, 80)))),
                                (10.0, 16.0, 1000, ((8, (80, 120, 160)), (7, (80, 110, 140)),
                                                    (6, (100, 125, 150))))):
        o = scheme_orbit(eps, T, steps)
        every = []
        for m, sizes in rows:
            got = [da.collocate(o, intervals=L, degree=m, multipliers=0).period for L in sizes]
            every += got
            print(f"eps = {eps:g}, degree {m}, L = {', '.join(map(str, sizes))}: periods "
                  + ", ".join(f"{t:.15f}" for t in got) + f"; spread {max(got) - min(got):.2g} "
                  f"({(max(got) - min(got)) / got[0]:.2g} relative)", flush=True)
        print(f"eps = {eps:g}, all degrees: spread {max(every) - min(every):.2g} "
              f"({(max(every) - min(every)) / every[0]:.2g} relative)", flush=True)


def multipliers_scan() -> None:
    """The default estimate of the two leading nontrivial multipliers of the orbit returned for
    intervals = L (4 of them computed) against their true error, on every L of SCAN's smooth
    orbits (degree 8 on 96 intervals the reference; compared where the true error exceeds ten
    times that reference's difference to one on 116 intervals, at least 1e-13, and the
    estimates' floor): the estimate / true range per orbit and in all, and every one below."""
    ratios, below = [], []
    for eps, p, T, steps, m, sizes in SCAN:
        if eps >= 10:
            continue
        o = scheme_orbit(eps, T, steps, p)
        ref = da.collocate(o, intervals=48, degree=8, multipliers=4)
        ref2 = da.collocate(o, intervals=58, degree=8, multipliers=4)
        mine = []
        for L in sizes:
            try:
                e = da.collocate(o, intervals=L, degree=m, multipliers=4)
            except (ValueError, RuntimeError):
                continue
            for j in (1, 2):
                if e.multipliers.size <= j:
                    continue
                mu = e.multipliers[j]
                k = int(np.argmin(np.abs(ref.multipliers - mu)))
                true = abs(ref.multipliers[k] - mu)
                gap = float(np.min(np.abs(ref2.multipliers - ref.multipliers[k])))
                if true < 10 * max(gap, 1e-13) or true < adapt.FLOOR * max(1.0, abs(mu)):
                    continue
                r = float(e.errors["multipliers"][j] / true)
                mine.append(r)
                if r < 1:
                    below.append(f"eps = {eps:g}, a = {p:g}, degree {m}, L = {L}: multiplier "
                                 f"{complex(mu):.6g}, true error {true:.3g}, estimate / true "
                                 f"{r:.3g}")
        ratios += mine
        print(f"eps = {eps:g}, a = {p:g}, degree {m}: {len(mine)} compared"
              + (f", estimate / true {min(mine):.3g} to {max(mine):.3g}" if mine else ""),
              flush=True)
    r = np.array(ratios)
    print(f"all: {r.size} compared, estimate / true {r.min():.3g} to {r.max():.3g}, within "
          f"[1, 10] {int(np.sum((r >= 1) & (r <= 10)))}, below 1 {int(np.sum(r < 1))}")
    for line in below:
        print("  below: " + line)


if __name__ == "__main__":
    main()
