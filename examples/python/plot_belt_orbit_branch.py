"""
A belt with memory: from shooting to the orbit branch
=====================================================

A mass on a belt that moves at the speed :math:`v`, held by a spring whose material relaxes (a
fading memory of the past displacements, one Prony term) and forced harmonically:

.. math::

   x'' + x + \\int_0^\\tau g\\,e^{-s/\\theta}\\,x(t-s)\\,ds + \\alpha\\,\\sigma(x' - v)
   \\ni F\\cos\\omega t,

with :math:`\\sigma` the sign graph of dry friction. In the relative velocity :math:`y = x' - v`,
:math:`u = (x, y)` solves :math:`u' + A(u) + f(t, u) + \\int_0^\\tau H(s)\\,u(t-s)\\,ds \\ni 0` with
:math:`f = (-(y + v),\\; x - F\\cos\\omega t)`, :math:`A = \\{0\\} \\times \\alpha\\sigma` and
:math:`H(s) = g e^{-s/\\theta}` in row :math:`y`, column :math:`x`: the friction is the built-in one
on the second component, the memory an exponential kernel computed in O(1) per step.

:func:`dmi.analysis.periodic_orbit` shoots the orbit of the forcing period at :math:`F = 0.3`, where
the mass sticks to the belt part of the time, and :func:`dmi.analysis.continue_orbit` follows it as
the forcing grows: the stick phases shrink and end (stick events), and the branch's ``margin``
says how far each point is from sticking (see :doc:`/orbits`). The plot shows the branch and the
orbits at its two ends.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import matplotlib.pyplot as plt
import numba
import numpy as np

import dmi
from dmi.analysis import continue_orbit, periodic_orbit, plot_branch

V, ALPHA, G, THETA, TAU = 0.4, 0.6, 0.3, 0.5, 2.0   # belt speed, friction, memory gain and time, cut
OMEGA = 0.8
P, M = 2 * np.pi / OMEGA, 800                         # forcing period, steps per period


# f(t, u) compiled once; the forcing amplitude F comes in through the user pointer
@numba.cfunc(numba.types.intc(numba.float64, numba.types.CPointer(numba.float64),
                              numba.types.CPointer(numba.float64), numba.types.CPointer(numba.float64)))
def rhs(t, u, out, F):
    out[0] = -(u[1] + V)
    out[1] = u[0] - F[0] * np.cos(OMEGA * t)
    return 0


def make(F: float) -> dmi.Solver:
    """The belt at the forcing amplitude F: configured, not initialised."""
    s = dmi.Solver(2, TAU, h=P / M)
    s.set_rhs(rhs, user=np.array([F]))
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [G, 0.0]]])
    return s


s = make(0.3)
s.init()
s.advance(10 * M)                                     # a plain run onto the attractor: the guess
orbit = periodic_orbit(make, 0.3, P, s)
print(f"F = 0.3: Newton iterations {orbit.iterations}, residual {orbit.residual:.1e}; "
      f"sticks {orbit.stick_fraction[1] * 100:.0f} % of the period; "
      f"multipliers {np.array2string(np.abs(orbit.multipliers[:3]), precision=3)} (moduli)")

branch = continue_orbit(orbit, 1.5, step=0.05)
print(f"branch to F = 1.5: {len(branch.points)} points, {branch.status}")
for e in branch.events:
    print(f"  {e.kind} at F = {e.p:.4f}")
for q in branch.points[::4]:
    print(f"  F = {q.p:.3f}: stuck steps {q.stick_steps[1]:3d}, margin {q.margin[1]:+.4f}, "
          f"stable: {q.stable}")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
plot_branch(branch, ax1)
ax1.set_xlabel("forcing amplitude F")
ax1.set_ylabel("x at t = 0 mod P (Poincaré section)")
for q, color in ((branch.points[0], "C0"), (branch.points[-1], "C1")):
    rows = make(q.p).N + 1                            # the window of N + 1 states is the guess
    o = periodic_orbit(make, q.p, P, q.state.reshape(-1, 2)[-rows:])
    F = q.p
    ax2.plot(o.u[:, 0], o.u[:, 1] + V, color=color, label=f"F = {F:.2f}")
ax2.axhline(V, color="0.6", lw=0.8, ls=":")
ax2.set_xlabel("displacement x")
ax2.set_ylabel("velocity x'  (dotted: the belt's speed, sticking)")
ax2.legend(fontsize=8)
plt.show()
