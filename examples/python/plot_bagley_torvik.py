"""
Fractional damping with dry friction: the forced Bagley–Torvik oscillator
==========================================================================

A unit mass on a spring with fractional damping of order 1/2 (a viscoelastic layer, the
Bagley–Torvik model) slides on a rough surface and is forced harmonically:

.. math::

   w'' + c\\,D^{1/2} w + k\\,w + \\mu\\,\\sigma(w') \\ni F\\cos\\omega t,
   \\qquad D^{1/2} w(t) = \\int_0^\\tau \\frac{s^{-1/2}}{\\Gamma(1/2)}\\,w'(t-s)\\,ds .

In :math:`u = (w, v)`, :math:`v = w'`: :math:`f = (-v,\\; k_\\tau w - F\\cos\\omega t)`,
:math:`A = \\{0\\} \\times \\mu\\sigma` and the kernel :math:`c\\,s^{-1/2}/\\Gamma(1/2)` in row
:math:`v`, column :math:`v`, singular at 0. It runs in O(1) per step: the kernel is fitted on
:math:`[h, \\tau]` by :func:`dmi.kernels.fit` (``PowerKernel``, relative error :math:`10^{-8}`) and
the first cell takes the exact integral of :math:`s^{-1/2}` (``set_quadrature("cell")`` and
``set_kernel_fit``).

**The memory.** A steady oscillation needs the derivative over the whole past (Liouville–Weyl),
which the solver truncates to :math:`\\tau` (the short-memory principle). Integrating the tail by
parts, :math:`\\int_\\tau^\\infty s^{-1/2} w'(t-s)\\,ds = \\tau^{-1/2}(w(t-\\tau) - \\bar w) -
\\tfrac12\\int_\\tau^\\infty s^{-3/2}(w(t-s) - \\bar w)\\,ds`, at most
:math:`2\\max|w - \\bar w|/\\sqrt\\tau`. With :math:`\\tau` a whole number of forcing periods,
:math:`w(t - \\tau) = w(t)` on the orbit and :math:`\\bar w = 0` (the orbit is symmetric), so the
leading term is a spring: the model puts it back, :math:`k_\\tau = k + c/\\sqrt{\\pi\\tau}`, leaving a
remainder of order :math:`\\tau^{-3/2}`. (The Caputo derivative of a run from rest, with
:math:`\\tau` at least the run's length, is checked against the Laplace transform's inverse in
``tests/python/kernels/test_bagley_torvik.py``.)

**The analysis** (:mod:`dmi.analysis`): :func:`~dmi.analysis.periodic_orbit` finds the forced
orbit by shooting for each friction level :math:`\\mu` (the previous orbit as the guess). As
:math:`\\mu` grows the amplitude falls and the mass starts to stick for part of each period. The
Floquet multipliers come from the whole monodromy matrix (the linearised period map of the
:class:`~dmi.analysis.StepMap` on all :math:`2(N+1)` values of the state, differenced column by
column): the memory gives a ring of many multipliers of nearly the same modulus, 0.54 to 0.57 here,
which the verified leading ones of :func:`~dmi.analysis.floquet_multipliers` (ARPACK, each pair's
residual checked by a fresh product) match: 0.544 against 0.543. All lie inside the unit
circle: the orbits are stable, and a run from rest approaches its orbit by about
:math:`|\\mu_1|` per period (left panel; the bumps every four periods are the start leaving the
memory).  Without forcing the equilibria form the whole segment :math:`|k_\\tau w| \\le \\mu`,
:math:`w' = 0` (the mass sticks wherever the spring cannot overcome friction): no equilibrium is
isolated, so there is none whose linear stability :func:`~dmi.analysis.equilibrium` could decide.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import math
import os

import matplotlib.pyplot as plt
import numba
import numpy as np

import dmi
from dmi import analysis, kernels
from dmi.analysis.scheme.floquet import monodromy_operator

C, K, F, OMEGA = 0.5, 1.0, 1.0, 0.8       # fractional damping, stiffness, forcing
P = 2 * math.pi / OMEGA                   # the forcing period
M = 100                                   # steps per period: h = P / M
TAU = 4 * P                               # the memory, a whole number of periods
K_TAU = K + C / math.sqrt(math.pi * TAU)  # the truncated tail's spring put back

FIT = kernels.fit(kernels.PowerKernel(0.5, C / math.sqrt(math.pi)), TAU, tol=1e-8, relative=True,
                  delta=P / M)
print(f"c s^-1/2 / Gamma(1/2) on [h, tau] = [{P / M:.4f}, {TAU:.2f}]: {FIT.terms} exponential terms, "
      f"relative error {FIT.max_error:.1e} (certified: {FIT.certified})")


@numba.cfunc(dmi.RHS_SIGNATURE)
def rhs(t, u, out, user):
    out[0] = -u[1]
    out[1] = K_TAU * u[0] - F * math.cos(OMEGA * t)
    return 0


def make(mu: float) -> dmi.Solver:
    """The oscillator at the friction level mu, from rest (w = w' = 0 on the history)."""
    s = dmi.Solver(2, TAU, h=P / M)
    s.set_rhs(rhs)
    s.set_friction([0.0, mu])
    s.set_quadrature("cell")
    s.set_kernel_fit(FIT, entry=(1, 1))   # the recursion, the first cell exact
    return s




def multipliers(o: analysis.Orbit) -> np.ndarray:
    """All Floquet multipliers of the orbit, largest first: the eigenvalues of the monodromy
    matrix, the period map's linearisation (dmi.analysis's differences) applied to every unit
    vector."""
    F = analysis.StepMap(o.make, o.p, o.steps, o.rows)
    J = monodromy_operator(F, o.state).matmat(np.eye(F.dim))
    mu = np.linalg.eigvals(J)
    return mu[np.argsort(-np.abs(mu))]


# the orbit along mu, each from the last
levels = np.linspace(0.05, 0.95, 19)
orbits, guess = [], np.zeros(2)
for mu in levels:
    o = analysis.periodic_orbit(make, mu, period=P, guess=guess, multipliers=0)
    orbits.append(o)
    guess = o.state
shown = {i: multipliers(orbits[i]) for i in (5, 11, 13, 15)}
for i, m in shown.items():
    o = orbits[i]
    print(f"mu = {o.p:.2f}: amplitude of w {o.amplitude[0]:.4f}, stuck {o.stick_fraction[1]:.0%} "
          f"of the period, |mu_1..4| {np.round(np.abs(m[:4]), 3)}, stable: {abs(m[0]) < 1}")

# a run from rest at mu = 0.7 against its orbit, period by period
orbit, mu1 = orbits[13], abs(shown[13][0])
s = make(orbit.p)
s.init()
distance = [np.max(np.abs(s.run(M)[1] - orbit.u)) for _ in range(16)]
rate = (distance[-1] / distance[3]) ** (1 / 12)
print(f"mu = {orbit.p:.2f}: a run from rest approaches the orbit by {rate:.3f} per period "
      f"(periods 4 to 16), |mu_1| = {mu1:.3f}")

fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(13, 4), layout="constrained")
k = np.arange(1, 17)
ax1.semilogy(k, distance, "o-", label="max |U - orbit| over period k")
ax1.semilogy(k, distance[3] * mu1 ** (k - 4.0), "k:", label=r"$|\mu_1|^k$")
ax1.set_xlabel("period k")
ax1.set_title(f"from rest to the orbit, $\\mu$ = {orbit.p:.2f}", fontsize=10)
ax1.legend(fontsize=8)

ax2.plot(levels, [o.amplitude[0] for o in orbits], "C0o-")
ax2.set_xlabel(r"friction $\mu$")
ax2.set_ylabel("amplitude of w", color="C0")
twin = ax2.twinx()
twin.plot(levels, [o.stick_fraction[1] for o in orbits], "C3s--")
twin.set_ylabel("stuck fraction of the period", color="C3")
ax2.set_title("the forced orbits", fontsize=10)

for i, color in zip((5, 11, 15), ("C0", "C1", "C3")):
    o = orbits[i]
    ax3.plot(o.u[:, 0], o.u[:, 1], color=color,
             label=f"$\\mu$ = {o.p:.2f}: $|\\mu_1|$ = {abs(shown[i][0]):.2f}")
    stuck = o.u[:, 1] == 0
    ax3.plot(o.u[stuck, 0], o.u[stuck, 1], "k.", ms=4)
ax3.set_xlabel("w")
ax3.set_ylabel("w' (black: at rest)")
ax3.legend(fontsize=8)
if os.environ.get("DMI_FIGURE"):          # scripts/main.sh: the docs' figure
    fig.savefig(os.environ["DMI_FIGURE"], dpi=120)
plt.show()
