"""
The belt with memory in its (belt speed, damping) plane: where stick-slip begins
================================================================================

A mass on a belt moving at the speed :math:`v_b`, held by a spring and a damper :math:`c`, with a
memory of its past positions and velocity-weakening (Stribeck) friction:

.. math::

   x'' + c\\,x' + k\\,x + \\frac{g}{\\tau}\\int_0^\\tau x(t-s)\\,ds + F(x' - v_b) \\ni 0,
   \\qquad F(v) = \\operatorname{sign}(v)\\bigl(\\mu_d + (\\mu_s - \\mu_d)\\,e^{-|v|/v_s}\\bigr),

split as in the Stribeck example: the sign graph at the static level :math:`\\mu_s` in
:math:`A`, the continuous weakening :math:`g(v) = F(v) - \\mu_s\\operatorname{sign}(v)` in
:math:`f`. The weakening is a negative damping :math:`F'(-v_b)` that fades as the belt speeds up:
the sliding rest loses its stability as :math:`v_b` falls, at a Hopf point.

What the map shows, each from one call of :mod:`dmi.analysis`:

1. **The Hopf curve** by :func:`~dmi.analysis.continue_curve` from the Hopf event of one branch of
   the equation's equilibria: where the sliding rest loses stability, its criticality at every
   point (dashed: *subcritical*, an unstable orbit is born, on the stable side of the rest). As
   :math:`v_b` grows the weakening fades and the curve tends to the damping at which the memory
   alone destabilises the rest. The curve's codimension-two points (Bautin, ...) are printed:
   on this range there are none, its :math:`\\ell_1` stays positive. The curve has a point on
   every row's damping (``at=``): the grid's Hopf points, found by its branches of equilibria,
   are checked against them (printed).
2. **The grid** by :func:`~dmi.analysis.continue_over` (one row a damping, serially here; with
   ``client=`` on a Dask cluster): at each :math:`c` the equation's equilibria over :math:`v_b`
   (their Hopf point with its criticality) and the orbits born there, continued by collocation
   (:func:`~dmi.analysis.continue_orbit` of the ``hopf_orbit(..., of="equation")`` start). The
   unstable orbit grows with :math:`v_b` until the relative velocity touches 0: a *stick onset*,
   where it turns into the stable stick-slip orbit. The grid's events are marked: the Hopf points
   (open: subcritical), the stick onsets (squares), the folds of orbits (triangles).
3. **The stick-onset curve** by :func:`~dmi.analysis.continue_curve`
   from the stick-onset event of the orbits' branch at :math:`c = 0.3`: where the unstable
   slipping orbit's relative velocity touches 0, continued in :math:`c` both ways (its least
   velocity held at 0 on the slipping orbit; each point with the estimated error of
   :math:`v_b` and the orbit's verified verdict, unstable all along). The grid's stick-onset
   events are its cross-check (printed: each row's event against the curve's point on that
   row's damping).
4. **The regions**, decided row by row from the verified verdicts of the grid's branches
   (:func:`~dmi.analysis.plot_curves`): *stable rest*; *bistable*, where the stable rest and the
   stable stick-slip orbit coexist, between the subcritical Hopf curve and the stick onset that
   ends the unstable orbit; *stick-slip* below the Hopf curve, where the stick-slip orbit is
   stable and the rest is not; grey hatched where a verdict is not decided. The curves decide
   the bistable region too: between the subcritical Hopf curve and the stick-onset curve of the
   unstable orbit, drawn as a polygon keyed "bistable (from the curves)".

**What is not there yet.** The fold curve of the orbits is not drawn here (this belt's unstable
orbit ends at its stick onset, not at a smooth fold). A region of the grid is named only where
the verdicts that decide it are verified; an orbit branch of this grid may end before it reaches
the edge of the map (its status is printed), and beyond its last point nothing is claimed about
the orbits. ``scripts/main.sh`` runs this example with more rows (``DMI_PLANE_ROWS``) and writes
the map and its interactive page into ``out/``.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import math
import os
import warnings

import matplotlib.pyplot as plt
import numpy as np

import dmi
from dmi import analysis

K, G, TAU = 1.0, 0.5, 1.0                  # stiffness, memory gain, memory length
MU_S, MU_D, V_S = 0.5, 0.3, 0.3            # static and dynamic friction, Stribeck velocity
V_LO, V_HI = 0.2, 1.6                      # the belt speeds of the map
C0 = 0.3                                   # the damping of the Hopf curve's start


def weakening(v: float) -> float:
    """g(v) = F(v) - mu_s sign(v): continuous, 0 at 0, decreasing (velocity weakening)."""
    return -math.copysign((MU_S - MU_D) * -math.expm1(-abs(v) / V_S), v)


def make2(vb: float, c: float) -> dmi.Solver:
    """The belt at the speed vb and the damping c; u = (x, y), y = x' - vb the relative velocity."""
    s = dmi.Solver(2, TAU, 50)
    s.set_rhs(lambda t, u: np.array([-(u[1] + vb),
                                     K * u[0] + c * (u[1] + vb) + weakening(u[1])]))
    s.set_friction([0.0, MU_S])
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [G / TAU, 0.0]]])
    return s


def sliding(vb: float) -> list:
    """The sliding rest: y = -vb, (k + g) x = F(vb)."""
    return [(MU_D + (MU_S - MU_D) * math.exp(-vb / V_S)) / (K + G), -vb]


def rest_branch(c: float):
    make = lambda vb: make2(vb, c)   # noqa: E731
    eq = analysis.equilibrium(make, V_HI, sliding(V_HI), of="equation")
    return analysis.continue_equilibrium(eq, V_LO, step=0.2)


def branches(c: float) -> dict:
    """The grid's task at one damping: the rest over vb and the orbits born at its Hopf point."""
    rest = rest_branch(c)
    (h,) = [e for e in rest.events if e.kind == "hopf"]
    o = analysis.hopf_orbit(lambda vb: make2(vb, c), h.hopf, h.u, amplitude=0.05, of="equation")
    return {"rest": rest, "orbits": analysis.continue_orbit(o, V_HI, step=0.05, max_points=20)}


# 1. the Hopf curve through the Hopf event at c = C0, both ways in c
(start,) = [e for e in rest_branch(C0).events if e.kind == "hopf"]
print(f"c = {C0}: Hopf point at v_b = {start.p:.6f}, omega = {start.hopf.omega:.6f}, "
      f"l1 = {start.hopf.l1:.4g} +- {start.hopf.l1_error:.1g}: {start.hopf.criticality}")
rows = int(os.environ.get("DMI_PLANE_ROWS", "3"))
dampings = np.linspace(0.26, 0.40, rows)         # the grid's rows (a point of the curve on each)
curves = [analysis.continue_curve(start, make2, C0, q_end, step=0.03, max_points=60,
                                  at=dampings)
          for q_end in (0.2235, 0.45)]
for cur in curves:
    print(f"Hopf curve to c = {cur.q[-1]:.4f}: {len(cur.points)} points, {cur.status}; "
          f"v_b from {cur.p.min():.4f} to {cur.p.max():.4f}; criticality "
          f"{sorted({str(pt.criticality) for pt in cur.points})}")
codim2 = [e for cur in curves for e in cur.events if e.kind != "user"]
print(f"codimension-two points on the Hopf curve: {len(codim2)}")
for e in codim2:
    print(f"  {e.kind} at (v_b, c) = ({e.p:.8f}, {e.q:.8f}): {e.detail}")

# 2. the stick-onset curve from the stick onset of the orbits' branch at c = C0, both ways in c
with warnings.catch_warnings():
    warnings.simplefilter("ignore")      # the branch's own warnings (printed in the grid below)
    orbits = branches(C0)["orbits"]
onset = [e for e in orbits.events if e.kind == "stick-onset"][0]
sticks = [analysis.continue_curve(onset, make2, C0, q_end, branch=orbits, step=0.03,
                                   at=dampings, multipliers=4) for q_end in (0.26, 0.40)]
for cur in sticks:
    print(f"stick-onset curve to c = {cur.q[-1]:.4f}: {len(cur.points)} points, {cur.status}; "
          f"v_b from {cur.p.min():.4f} to {cur.p.max():.4f}; largest estimated error of v_b "
          f"{max(pt.p_error or math.inf for pt in cur.points):.1e}; the orbits "
          f"{sorted({str(pt.stable) for pt in cur.points})} stable")

# 3. the grid of one-parameter continuations over the damping
with warnings.catch_warnings():
    warnings.simplefilter("ignore", analysis.GridWarning)   # each row keeps its warnings
    grid = analysis.continue_over(dampings, branches)
for r in grid.rows:
    if r.error:
        print(f"c = {r.q:.4f}: failed: {r.error.splitlines()[0]}")
        continue
    evs = [e for t in r.branches.values() for e in t.events if e.kind != "user"]
    if r.warnings:
        print(f"c = {r.q:.4f}: {len(r.warnings)} warnings, the first: {r.warnings[0][:160]}")
    print(f"c = {r.q:.4f}: orbits: {r.branches['orbits'].status}; events: " + ", ".join(
        f"{e.kind} at v_b = {e.p:.5f}" + (f" ({e.criticality})" if e.criticality else "")
        for e in evs))

# the cross-check: each row's Hopf point (a branch of equilibria at that c) against the curve's
# point on that c (at=), two different computations of the same point
on_curve = {round(e.q, 12): e.p for cur in curves for e in cur.events if e.kind == "user"}
gaps = [abs(e.p - on_curve[round(e.q, 12)]) for e in grid.events("hopf")
        if round(e.q, 12) in on_curve]
if gaps:
    print(f"the grid's {len(gaps)} Hopf points against the curve's points at their c: "
          f"largest difference in v_b {max(gaps):.1e}")

# the grid's stick onsets against the stick-onset curve's points at their c
# (a branch's event that could not be located, at a corner of its stick-slip branch, is placed
# between its two points: counted, not compared)
on_stick = {round(e.q, 12): e.p for cur in sticks for e in cur.events if e.kind == "user"}
grid_onsets = [e for e in grid.events("stick-onset") if round(e.q, 12) in on_stick]
located = [e for e in grid_onsets if "not located" not in e.detail]
for e in located:
    print(f"c = {e.q:.4f}: the grid's stick onset at v_b = {e.p:.8f}, the curve's at "
          f"{on_stick[round(e.q, 12)]:.8f}")
print(f"the grid's stick onsets not located (placed between two points of their branch): "
      f"{len(grid_onsets) - len(located)}")

# 4. the map
fig, ax = plt.subplots(figsize=(8, 6.2), layout="constrained")
html = os.environ.get("DMI_FIGURE_HTML")
analysis.plot_curves(curves + sticks, grid, ax=ax, p_label="belt speed $v_b$",
                     q_label="damping $c$", html=html,
                     title="the belt with memory and Stribeck friction")
ax.set_xlim(V_LO, V_HI)
if os.environ.get("DMI_FIGURE"):          # scripts/main.sh: the map into out/
    fig.savefig(os.environ["DMI_FIGURE"], dpi=120)
plt.show()
