"""
A stick-slip orbit of the equation by collocation
=================================================

A mass on a belt that moves at the speed :math:`V`, held by a spring, driven by a negative damping
:math:`k` and dry friction against the belt, with a memory of its past positions:

.. math::

   x'' + x - k\\,x' + \\alpha\\,\\sigma(x' - V) + g\\int_0^\\tau e^{-s}\\,x(t-s)\\,ds \\ni 0 .

In the relative velocity :math:`y = x' - V`, :math:`u = (x, y)` solves
:math:`u' + A(u) + f(u) + \\int_0^\\tau H\\,u(t-s)\\,ds \\ni 0` with
:math:`f = (-(y + V),\\; x - k (y + V))` and :math:`A = \\{0\\} \\times \\alpha\\sigma`.

1. :func:`~dmi.analysis.periodic_orbit` finds the scheme's orbit (first order in h: its period is
   off by about h);
2. :func:`~dmi.analysis.collocate` reads its signature (the mass slips backwards, forwards, then
   sticks to the belt) and solves the equation's orbit by collocation on three segments whose ends
   are unknowns: the relative velocity reaching 0, the force reaching the friction's threshold.

The figure shows both orbits in the phase plane, the collocated orbit's switches marked; the
printout gives the period, its estimated error and the multipliers (the trivial one, 1, and the
rest: the stuck segment wipes a perturbation of y out).
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import os

import matplotlib.pyplot as plt
import numpy as np

import dmi
from dmi import analysis as da

V, K, ALPHA, G, TAU = 0.5, 0.2, 0.4, 0.3, 2.0


def belt(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + V), u[0] - K * (u[1] + V)]))
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [G, 0.0]]])
    return s


steps, guess = 1000, 6.46
s = belt(1.0, h=guess / steps)
s.set_history(lambda t: np.array([1.0, 0.0]))
s.init()
s.advance(40 * steps)
scheme = da.periodic_orbit(belt, 1.0, None, s, guess_period=guess, steps=steps, multipliers=0)
orbit = da.collocate(scheme, tol=1e-9)

print(f"scheme's period      {scheme.period:.10f}  (h = {scheme.h:.4g})")
print(f"equation's period    {orbit.period:.12f}  (estimated error {orbit.errors['period']:.1e})")
print(f"signature            {' -> '.join(orbit.signature.describe())}")
print(f"switching times      {np.array2string(orbit.switches, precision=6)}")
print(f"multipliers          {np.array2string(np.abs(orbit.multipliers[:3]), precision=6)}")
print(f"intervals            {orbit.intervals} (degree {orbit.degree})")

fig, ax = plt.subplots(figsize=(6.4, 4.2))
t = np.linspace(0.0, orbit.period, 2001)
u = orbit.u_at(t)
ax.plot(scheme.u[:, 0], scheme.u[:, 1], lw=3, color="0.8", label=f"scheme, h = {scheme.h:.3g}")
ax.plot(u[:, 0], u[:, 1], color="C0", label="equation, collocation")
w = orbit.u_at(orbit.switches)
ax.plot(w[:, 0], w[:, 1], "o", color="C3", label="switches")
ax.axhline(0.0, color="0.5", ls=":", lw=1)
ax.set_xlabel("x")
ax.set_ylabel("y = x' - V (0: stuck to the belt)")
ax.legend(loc="lower right")
ax.set_title("A stick-slip orbit with memory")
fig.tight_layout()
if os.environ.get("DMI_FIGURE"):                           # scripts/main.sh: the docs' figure
    fig.savefig(os.environ["DMI_FIGURE"], dpi=120)
plt.show()
