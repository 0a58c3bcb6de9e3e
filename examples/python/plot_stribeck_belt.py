"""
Velocity-weakening (Stribeck) friction: the split, and verified stability
=========================================================================

A mass on a belt moving at the speed :math:`v_b`, with a spring, fractional damping of order 1/2
(a viscoelastic layer, a memory of :math:`\\tau` = 8 periods) and the Stribeck friction law, the
most common after Coulomb's: the friction falls from the static level :math:`\\mu_s` to the
dynamic level :math:`\\mu_d` as the sliding speed grows,

.. math::

   x'' + c\\,D^{1/2}x + k\\,x + F(x' - v_b) \\ni 0, \\qquad
   F(v) = \\operatorname{sign}(v)\\bigl(\\mu_d + (\\mu_s - \\mu_d)\\,e^{-|v|/v_s}\\bigr),
   \\quad F(0) = [-\\mu_s, \\mu_s].

**The split.** dmi's inclusion :math:`u' + A(u) + f(t, u) + \\int_0^\\tau H u \\ni 0` wants A maximal
monotone and f Lipschitz. F is neither: it is set-valued at 0 and *decreasing* for
:math:`v \\neq 0`. Split it at the static level: :math:`A = \\mu_s\\sigma` (the sign graph, whose
resolvent's dead zone :math:`|X| \\le h\\mu_s` holds a stick exactly) and the continuous remainder

.. math::

   g(v) = F(v) - \\mu_s\\operatorname{sign}(v)
        = -\\operatorname{sign}(v)\\,(\\mu_s - \\mu_d)\\bigl(1 - e^{-|v|/v_s}\\bigr),

which is 0 at 0 (continuous), Lipschitz with :math:`L = (\\mu_s - \\mu_d)/v_s` (its slope at 0, the
largest) and goes to f; f need not be monotone. (Splitting at :math:`\\mu_d` instead would leave
a jump of :math:`\\mu_s - \\mu_d` in g at 0: not Lipschitz.) The scheme's step then sticks
exactly when the force besides friction is below :math:`\\mu_s`, and slides with
:math:`\\mu_s\\,\\mathrm{sign} + g = F`. The model is ``examples/python/stribeck_belt.py``.

**The checks** (printed below, and asserted in ``tests/python/analysis/scheme/test_verified.py``):

1. the split gives back F away from 0 and g is Lipschitz with L (sampled);
2. the equation's equilibrium (``of="equation"``, the fractional kernel's near cell by its exact
   transform) is :math:`k x = F(v_b)`, :math:`x' = 0`, to the fit's accuracy;
3. the equilibrium loses its stability at a Hopf point as :math:`v_b` falls (the weakening is a
   negative damping :math:`F'(v_b)`); the orbit born there at amplitude 0.05 is *unstable* (a
   subcritical Hopf point), its leading multiplier 1.0012, verified (the former block Krylov
   space reported 0.51, "stable"): a plain run kicked off it drifts further from the orbit's
   amplitude, slowly (red). The stick-slip orbit of amplitude 0.8 is stable: its nontrivial
   multipliers are at most 0.76, but the difference operator's noise (0.009 on this stick-slip
   orbit) leaves room for a second multiplier beside the trivial one, so a plain run at the
   scale of the difference step decides (it decays by 0.976 a period); a run kicked by 2 % of
   the amplitude comes back to it within ten periods (blue). (Kicked by far less than a step's
   worth of switch motion, the scheme's run drifts along the orbit by a fraction of a step and
   locks on again, 1e-4 from it: the discrete orbit's own phase locking, which the verdict at
   the difference step's scale does not take for an instability.) The multipliers are verified
   by :func:`dmi.analysis.scheme.floquet`: ARPACK on the monodromy operator, each pair's residual by a
   fresh product and the operator's noise, and a plain run where :math:`|\\mu| - 1` lies
   inside that error, or where a multiplier may hide beside the trivial one.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import os

import matplotlib.pyplot as plt
import numpy as np

from dmi import analysis
from stribeck_belt import (K, LIPSCHITZ, M, MU_S, amplitude_deviation,  # the model
                           make, stribeck, weakening)

# 1. the split
v = np.linspace(-1.5, 1.5, 3001)
v = v[v != 0]
total = np.array([MU_S * np.sign(x) + weakening(x) for x in v])
law = np.array([stribeck(x) for x in v])
slopes = np.abs(np.diff([weakening(x) for x in v]) / np.diff(v))
print(f"split: max |mu_s sign + g - F| = {np.max(np.abs(total - law)):.1e}, "
      f"max slope of g {slopes.max():.4f} <= L = {LIPSCHITZ:.4f}")

# 2. the equilibrium of the equation at v_b = 1
vb = 1.0
eq = analysis.equilibrium(make, vb, [0.3, -vb], of="equation")
print(f"v_b = {vb}: equilibrium x = {eq.u[0]:.10f}, F(v_b) / k = {stribeck(vb) / K:.10f}")

# 3. the Hopf point, and the orbits born there
equilibria = analysis.continue_equilibrium(analysis.equilibrium(make, vb, [0.3, -vb]), 0.3,
                                           step=0.05)
(hopf,) = [e for e in equilibria.events if e.kind == "hopf"]
print(f"Hopf point at v_b = {hopf.hopf.p:.6f}, omega = {hopf.hopf.omega:.6f}")
orbits = {}
for amplitude in (0.05, 0.8):
    o = analysis.hopf_orbit(make, hopf.hopf, hopf.u, amplitude=amplitude, steps=M)
    dev = amplitude_deviation(o.make, o.p, o.state, M, 150, 0.02 * amplitude, o.amplitude)
    orbits[amplitude] = (o, dev)
    print(f"amplitude {amplitude}: v_b = {o.p:.6f}, stuck {o.stick_fraction[1]:.0%} of the "
          f"period, stable: {o.stable} ({o.floquet.reason}); a plain run kicked by 2 % of the "
          f"amplitude is {dev[0]:.2e} off the orbit's amplitude in its first period, "
          f"{dev[10]:.2e} in the 11th, {dev[-1]:.2e} in the 150th")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
ax1.plot(v, law, "k", lw=2, label=r"$F$ (Stribeck)")
ax1.plot([0, 0], [-MU_S, MU_S], "k", lw=2)
ax1.plot(v, MU_S * np.sign(v), "C0--", label=r"$A = \mu_s\sigma$ (sign graph)")
ax1.plot(v, [weakening(x) for x in v], "C3", label=r"$g$ in $f$ (Lipschitz)")
ax1.set_xlabel("sliding speed v")
ax1.set_ylabel("friction force")
ax1.legend(fontsize=8)
ax1.set_title("the split at the static level", fontsize=10)
for (amplitude, (o, dev)), color in zip(orbits.items(), ("C3", "C0")):
    ax2.semilogy(np.arange(1, len(dev) + 1), dev, "o", ms=2, color=color,
                 label=f"orbit of amplitude {amplitude}: stable = {o.stable}")
ax2.set_xlabel("period k")
ax2.set_ylabel("max |amplitude over period k - the orbit's|")
ax2.set_title("plain runs kicked by 2 % of the orbits' amplitude", fontsize=10)
ax2.legend(fontsize=8)
if os.environ.get("DMI_FIGURE"):          # scripts/main.sh: the docs' figure
    fig.savefig(os.environ["DMI_FIGURE"], dpi=120)
plt.show()
