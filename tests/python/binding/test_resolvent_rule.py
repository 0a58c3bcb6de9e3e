# The built-in resolvents' rule of the Python package (dmi._resolvent) against libdmi's own: the
# hold read by dmi_watch_start (held_of) and the state after one step of a one-component solver
# (rule_ref.c), at and near the thresholds, ties included; the slopes against differences of the
# C library's resolvent on the same piece; the modes of a run of libdmi against the C holds of its
# steps; the saltation factor against the equation's velocities by hand and identify's own
# reversal test; and numba compiling every function to the same values.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import os
import subprocess

import numpy as np
import pytest

import dmi
from dmi import _resolvent as rule

H = 0.25          # rule_ref's step: tau = 1, N = 4


def c_rule(lines: list[str]) -> list[tuple[int, float, float, float] | None]:
    """rule_ref's answers (held, R(x), X, h) for its input lines; None where libdmi refused."""
    prog = os.environ.get("DMI_RULE_REF")
    if not prog:
        pytest.skip("DMI_RULE_REF not set (ctest sets it)")
    r = subprocess.run([prog], input="\n".join(lines) + "\n", capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    out: list[tuple[int, float, float, float] | None] = []
    for line in r.stdout.splitlines():
        if line == "refused":
            out.append(None)
            continue
        held, R, X, h = line.split()
        out.append((int(held), float.fromhex(R), float.fromhex(X), float.fromhex(h)))
    assert len(out) == len(lines)
    return out


def around(b: float) -> list[float]:
    """b itself (the tie), its floating-point neighbours, and points 1e-12 and 1e-3 (relative)
    on either side."""
    pts = [b, math.nextafter(b, math.inf), math.nextafter(b, -math.inf)]
    for r in (1e-12, 1e-3):
        pts += [b + r * max(abs(b), 1.0), b - r * max(abs(b), 1.0)]
    return pts


ALPHAS = [0.0, 2.0, 1e-3, 3.7, 1e-300]
BOXES = [(-1.0, 1.0), (1.0, 1.0), (-math.inf, 2.0), (0.0, math.inf), (-0.3, 0.7), (2.0, 1.0)]


def friction_cases() -> list[tuple[float, float]]:
    cases = []
    for a in ALPHAS:
        lam = H * a
        for x in around(lam) + around(-lam) + [0.0, -0.0, 5e-324, -5e-324, 7.5, -7.5]:
            cases.append((a, x))
    return cases


def box_cases() -> list[tuple[float, float, float]]:
    cases = []
    for lo, hi in BOXES:
        for b in (lo, hi):
            if math.isfinite(b):
                cases += [(lo, hi, x) for x in around(b)]
        cases += [(lo, hi, x) for x in (0.0, -5.0, 5.0)]
    return cases


def line(kind: str, *v: float) -> str:
    return " ".join([kind] + [float(x).hex() for x in v])


def c_slope(R_of: dict, x: float, side: int, sides: dict) -> float:
    """R'(x) of the C library's resolvent on the piece of x (its side): the difference quotient
    to a neighbour on the same side; where x's piece is the point x alone (a hold at lam = 0),
    the quotients to both neighbours, which must agree."""
    same = [y for y in R_of if y != x and sides[y] == side]
    if same:
        y = min(same, key=lambda y: abs(y - x))
        return (R_of[y] - R_of[x]) / (y - x)
    q = [(R_of[y] - R_of[x]) / (y - x) for y in R_of if y != x]
    assert max(q) - min(q) <= 1e-6, (x, q)
    return q[0]


def test_friction_hold_and_slope_are_libdmi_s():
    cases = friction_cases()
    got = c_rule([line("friction", a, x) for a, x in cases])
    by_alpha: dict[float, dict] = {}
    for (a, x), g in zip(cases, got):
        assert g is not None, (a, x)
        held, R, X, h = g
        assert h == H and X == x         # the step's argument is the history's value itself
        lam = h * a
        assert bool(rule.friction_held(x, lam)) == bool(held), (a, x)
        side = 0 if held else (1 if R > 0 else -1)
        assert rule.friction_side(x, lam) == side, (a, x)
        by_alpha.setdefault(a, {})[x] = (R, side)
    ties = 0
    for a, pts in by_alpha.items():
        R_of = {x: r for x, (r, _) in pts.items()}
        sides = {x: s for x, (_, s) in pts.items()}
        for x, (_, side) in pts.items():
            assert rule.friction_slope(x, H * a) == pytest.approx(
                c_slope(R_of, x, side, sides), abs=1e-3), (a, x)
            ties += a > 0 and abs(x) == H * a
    assert ties == 2 * (len(ALPHAS) - 1)        # every threshold's tie was among the cases
    # elementwise on arrays, as on scalars
    a = np.array([c[0] for c in cases])
    x = np.array([c[1] for c in cases])
    assert np.array_equal(rule.friction_side(x, H * a),
                          [rule.friction_side(xi, H * ai) for xi, ai in zip(x, a)])


def test_box_hold_and_slope_are_libdmi_s():
    cases = box_cases()
    got = c_rule([line("box", lo, hi, x) for lo, hi, x in cases])
    by_box: dict[tuple, dict] = {}
    for (lo, hi, x), g in zip(cases, got):
        if lo > hi:
            assert g is None         # refused by libdmi: no rule to mirror
            continue
        assert g is not None, (lo, hi, x)
        side, R, X, _ = g
        assert X == x
        assert rule.box_side(x, lo, hi) == side, (lo, hi, x)
        assert bool(rule.box_held(x, lo, hi)) == (side != 0)
        assert R == (lo if side < 0 else hi if side > 0 else x)
        by_box.setdefault((lo, hi), {})[x] = (R, side)
    for (lo, hi), pts in by_box.items():
        R_of = {x: r for x, (r, _) in pts.items()}
        sides = {x: s for x, (_, s) in pts.items()}
        for x, (_, side) in pts.items():
            assert rule.box_slope(x, lo, hi) == pytest.approx(c_slope(R_of, x, side, sides),
                                                              abs=1e-3), (lo, hi, x)
    assert rule.box_side(1.0, 1.0, 1.0) == -1          # lo = hi: held on lo, as in C


def forced_friction_run(F: float) -> tuple[np.ndarray, np.ndarray]:
    """U, X of libdmi's run of u' = F cos(t) - sigma(u) (friction alpha = 1, h = H): it sticks
    while |F cos t| <= 1 and slips otherwise; at F = 3 it reverses through the dead zone."""
    s = dmi.Solver(1, 1.0, 4)
    s.set_rhs(lambda t, u: np.array([-F * math.cos(t)]))
    s.set_friction([1.0])
    s.set_history(lambda t: np.array([0.3]))
    s.init()
    assert s.h == H
    _, U, X = s.run_terms(1000)
    s.close()
    return U[:, 0], X[:, 0]


def test_modes_of_a_run_follow_libdmi_s_holds():
    found = set()
    for F in (1.5, 3.0):
        U, X = forced_friction_run(F)
        held = np.array([g[0] for g in c_rule([line("friction", 1.0, x) for x in X])],
                        dtype=bool)                                   # C's hold of each step
        assert np.array_equal(held, U[1:] == 0.0)
        u = U[1:]
        modes = rule.friction_mode(u[:-2], u[1:-1], u[2:])
        hp, hn, hm = held[:-2], held[2:], held[1:-1]
        assert np.array_equal(modes == rule.STUCK, hm & (hp | hn))
        lone = hm & ~hp & ~hn
        assert np.array_equal(modes == rule.REVERSAL,
                              lone & (np.sign(u[:-2]) != np.sign(u[2:])))
        assert np.array_equal(modes == rule.TOUCH, lone & (np.sign(u[:-2]) == np.sign(u[2:])))
        assert np.array_equal(modes == rule.SLIP_POS, ~hm & (u[1:-1] > 0))
        assert np.array_equal(modes == rule.SLIP_NEG, ~hm & (u[1:-1] < 0))
        found |= set(np.unique(modes).tolist())
    assert {rule.STUCK, rule.SLIP_POS, rule.SLIP_NEG, rule.REVERSAL} <= found, found


def test_saltation_factor_is_the_ratio_of_the_equation_s_velocities():
    # u' = -phi - alpha sigma(u): from u > 0, F- = -phi - alpha; after, u < 0, F+ = -phi + alpha
    for phi, alpha in ((3.0, 1.0), (1.25, 0.5), (10.0, 9.0)):
        want = (-phi + alpha) / (-phi - alpha)
        assert rule.saltation_factor(1.0, phi, alpha) == pytest.approx(want, rel=1e-15)
        assert rule.saltation_factor(-1.0, -phi, alpha) == pytest.approx(want, rel=1e-15)
    assert math.isnan(rule.saltation_factor(1.0, 0.5, 1.0))    # |phi| < alpha: it sticks
    assert math.isnan(rule.saltation_factor(1.0, -3.0, 1.0))   # moving away from 0: no reversal
    assert rule.crossing(3.0, -1.0) == 0.75
    assert rule.salted(0.5, 2.0, 0.1, -1.0, 3.0) == pytest.approx(0.5 * (2.0 + 0.3))


def test_saltation_agrees_with_identify_s_reversal():
    from dmi.identify import _saltation as sal
    rng = np.random.default_rng(3)
    counts = {sal.REVERSAL: 0, sal.UNPLACED: 0}
    for _ in range(400):
        U = rng.choice([-1.0, 1.0], size=(3, 1)) * rng.uniform(0.01, 1.0, size=(3, 1))
        U[1, 0] = -abs(U[1, 0]) * np.sign(U[0, 0])            # the step changes sign
        phi = rng.normal(0.0, 2.0, size=(2, 1))
        what, rho = sal.reversal(0, 0, U, phi, np.array([1.0]))
        sign = math.copysign(1.0, U[0, 0])
        f = rule.crossing(U[0, 0], U[1, 0])
        mine = rule.saltation_factor(sign, (1 - f) * phi[0, 0] + f * phi[1, 0], 1.0)
        assert what in counts
        counts[what] += 1
        if what == sal.REVERSAL:
            assert mine == pytest.approx(rho, rel=1e-14)
        else:
            assert math.isnan(mine)
    assert min(counts.values()) > 20, counts


def test_numba_compiles_the_rule_to_the_same_values():
    numba = pytest.importorskip("numba")
    rng = np.random.default_rng(5)
    x = np.concatenate([rng.normal(0.0, 1.0, 50), [0.5, -0.5, 0.0, 1.0, -1.0]])
    lam, lo, hi = 0.5, -1.0, 1.0
    for name, args in (("friction_side", (x, lam)), ("friction_held", (x, lam)),
                       ("friction_slope", (x, lam)), ("friction_slope_alpha", (x, lam, 0.1)),
                       ("box_side", (x, lo, hi)), ("box_held", (x, lo, hi)),
                       ("box_slope", (x, lo, hi)), ("box_mode", (np.clip(x, lo, hi), lo, hi)),
                       ("near", (x, lam, 1e-9))):
        fn = getattr(rule, name)
        jit = numba.njit(fn)
        assert np.array_equal(jit(*args), fn(*args)), name
        assert all(jit(xi, *args[1:]) == fn(xi, *args[1:]) for xi in x[:8]), name
    u = np.array([0.3, 0.0, -0.2, 0.0, 0.0, 0.1, 0.0, 0.4])
    m = numba.njit(rule.friction_mode)(u[:-2], u[1:-1], u[2:])
    assert np.array_equal(m, rule.friction_mode(u[:-2], u[1:-1], u[2:]))
    assert m.tolist() == [rule.REVERSAL, rule.SLIP_NEG, rule.STUCK, rule.STUCK, rule.SLIP_POS,
                          rule.TOUCH]
    for name, args in (("crossing", (0.3, -0.1)), ("saltation_factor", (1.0, 3.0, 1.0)),
                       ("salted", (0.5, 2.0, 0.1, -1.0, 3.0))):
        assert numba.njit(getattr(rule, name))(*args) == getattr(rule, name)(*args), name
