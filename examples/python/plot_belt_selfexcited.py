"""
A belt with memory: from the equilibrium to the stick-slip branch
=================================================================

A mass on a belt that moves at the speed :math:`v_b`, held by a spring and a damper, with a
memory of its past positions (a material that relaxes) and dry friction against the belt:

.. math::

   x'' + c\\,x' + k\\,x + \\frac{g}{\\tau}\\int_0^\\tau x(t-s)\\,ds
   + \\alpha\\,\\sigma(x' - v_b) \\ni 0 .

Nothing forces it: its oscillations are *self-excited*.  In the relative velocity
:math:`y = x' - v_b`, :math:`u = (x, y)` solves
:math:`u' + A(u) + f(u) + \\int_0^\\tau H\\,u(t-s)\\,ds \\ni 0` with
:math:`f = (-(y + v_b),\\; k x + c (y + v_b))`, :math:`A = \\{0\\} \\times \\alpha\\sigma` and a
constant kernel in row :math:`y`, column :math:`x` (the O(1) recursion).

The steps, each one call of :mod:`dmi.analysis`:

1. :func:`~dmi.analysis.equilibrium` corrects the sliding equilibrium
   :math:`x = \\alpha / (k + g)`, :math:`y = -v_b` and
   :func:`~dmi.analysis.continue_equilibrium` follows it as the damping :math:`c` falls: the
   memory destabilises it at a ``hopf`` event;
2. :func:`~dmi.analysis.hopf_orbit` starts the branch of orbits born there, at a small amplitude;
3. :func:`~dmi.analysis.continue_orbit` follows it with the period as an unknown.  While the
   mass slips the system is linear: the branch rises vertically from the Hopf point, until the
   relative velocity touches 0 (grazing); then the mass sticks to the belt for part of each
   period, and the stick-slip branch bends away (a ``stick-onset`` event).

The left panel is :func:`~dmi.analysis.plot_branch` of both branches (the equilibria's :math:`x`,
the orbits' amplitude of :math:`x`); the right panel shows three orbits in the phase plane, the
dotted line the belt's speed, where the mass sticks.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import os

import matplotlib.pyplot as plt
import numpy as np

import dmi
from dmi import analysis

K, G, ALPHA, VB, TAU = 1.0, 0.8, 0.5, 0.3, 1.0   # stiffness, memory gain, friction, belt speed, memory


def make(c: float, h: float = TAU / 100) -> dmi.Solver:
    """The belt at the damping c, with the step h (an autonomous orbit's period sets h).  The
    right-hand side is plain Python compiled to C by numba (``jit=True``): compiled once for every
    c, which it reads from its closure at run time."""
    s = dmi.Solver(2, TAU, h=h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + VB), K * u[0] + c * (u[1] + VB)]), jit=True)
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [G / TAU, 0.0]]])
    return s


eq = analysis.equilibrium(make, 1.0, [0.2, -0.2])
print(f"c = 1: equilibrium {eq.u}, rightmost root {eq.roots[0]:.5f}, stable: {eq.stable}")
equilibria = analysis.continue_equilibrium(eq, -0.2, step=0.1)
(hopf,) = [e for e in equilibria.events if e.kind == "hopf"]
print(f"Hopf point at c = {hopf.hopf.p:.8f}, omega = {hopf.hopf.omega:.6f}")

orbit = analysis.hopf_orbit(make, hopf.hopf, hopf.u, amplitude=0.05, steps=400)
print(f"orbit of amplitude 0.05: c = {orbit.p:.8f}, period {orbit.period:.5f}")
branch = analysis.continue_orbit(orbit, -0.2, step=0.02, max_points=40, multipliers=4)
print(f"orbit branch: {len(branch.points)} points, {branch.status}")
for e in branch.events:
    print(f"  {e.kind} at c = {e.p:.5f}: {e.detail}")
for q in branch.points[::6]:
    print(f"  c = {q.p:.4f}: period {q.period:.4f}, amplitude of x {q.amplitude[0]:.4f}, "
          f"stuck steps {q.stick_steps[1]:3d}, stable: {q.stable}")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
analysis.plot_branch(equilibria, ax1, component=0, color="C2", p_label="damping c")
analysis.plot_branch(branch, ax1, component=0, color="C0", p_label="damping c")
ax1.set_ylabel("x: equilibrium (green), amplitude (blue)")
pick = [branch.points[1], branch.points[len(branch.points) // 2], branch.points[-1]]
for q, color in zip(pick, ("C0", "C1", "C3")):
    o = analysis.periodic_orbit(make, q.p, guess=q.state, guess_period=q.period, steps=400,
                                multipliers=0)
    ax2.plot(o.u[:, 0], o.u[:, 1] + VB, color=color, label=f"c = {q.p:.3f}")
ax2.axhline(VB, color="0.5", lw=0.8, ls=":")
ax2.set_xlabel("displacement x")
ax2.set_ylabel("velocity x' (dotted: the belt's speed)")
ax2.legend(fontsize=8)
if os.environ.get("DMI_FIGURE"):                           # scripts/main.sh: the docs' figure
    fig.savefig(os.environ["DMI_FIGURE"], dpi=120)
plt.show()
