"""
A forced orbit branch over the delay
====================================

The friction oscillator with a constant memory kernel, forced at the frequency 1/2,

.. math::

   w'' + w + \\int_0^\\tau 0.5\\, w(t-s)\\,ds + \\sigma(w') + 1.3\\cos(t/2) \\ni 0,

has a periodic orbit of the forcing period :math:`P = 4\\pi`. :func:`dmi.analysis.periodic_orbit`
finds it by shooting at :math:`\\tau = 2.2` (a plain run gives the guess),
:func:`dmi.analysis.continue_orbit` follows it in :math:`\\tau` with its Floquet multipliers, and
at the period doubling it detects, :func:`dmi.analysis.period_doubled_orbit` starts the branch of
period :math:`2P`, continued in turn. :func:`dmi.analysis.plot_branch` draws :math:`w` on the
Poincaré section :math:`t = 0 \\bmod P` against :math:`\\tau`: stable solid, unstable dashed.

The period is a whole number :math:`M` of steps (:math:`h = P/M`) while :math:`\\tau` moves freely:
``dmi.Solver(n, tau, h=h)``. ``orbit_tau.py`` beside this example is the full-resolution program
(:math:`M = 4000`, over the brute-force diagram of a parameter sweep); :doc:`/orbits` has the method
and its checks.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import matplotlib.pyplot as plt
import numba
import numpy as np

import dmi
from dmi.analysis import continue_orbit, period_doubled_orbit, periodic_orbit, plot_branch

P, M = 4 * np.pi, 1000                     # forcing period and steps per period: h = P / M


@numba.cfunc(dmi.RHS_SIGNATURE)             # f(t, u) compiled: the steps run without Python
def rhs(t, u, out, user):
    out[0] = -u[1]
    out[1] = u[0] + 1.3 * np.cos(0.5 * t)
    return 0


def make(tau: float) -> dmi.Solver:
    """The model at delay tau: configured, not initialised."""
    s = dmi.Solver(2, tau, h=P / M)
    s.set_rhs(rhs)
    s.set_friction([0.0, 1.0])
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [0.5, 0.0]]])   # H = 0.5 on w, in the v equation
    return s


s = make(2.2)
s.init()
s.advance(60 * M)                          # a plain run onto the attractor: the guess
orbit = periodic_orbit(make, 2.2, P, s)
print(f"tau = 2.2: orbit after {orbit.iterations} Newton iterations, residual {orbit.residual:.1e}, "
      f"multipliers {np.array2string(orbit.multipliers[:2], precision=3)}, stable: {orbit.stable}")

branch = continue_orbit(orbit, 2.6, step=0.04)
print(f"period-1 branch: {len(branch.points)} points, {branch.status}")
for e in branch.events:
    print(f"  {e.kind} at tau = {e.p:.4f}")

fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
plot_branch(branch, ax, color="C0")
pd = next((e for e in branch.events if e.kind == "period-doubling"), None)
if pd is not None:
    doubled = continue_orbit(period_doubled_orbit(branch, pd), 2.6, step=0.04, sections=2)
    print(f"period-2 branch from tau = {pd.p:.4f}: {len(doubled.points)} points, {doubled.status}")
    plot_branch(doubled, ax, color="C1")
ax.set_xlabel("delay τ")
ax.set_ylabel("w at t = 0 mod P (Poincaré section)")
ax.set_title("period 1 (blue) and period 2 (orange); dashed: unstable")
plt.show()
