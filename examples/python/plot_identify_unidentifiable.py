"""
When the data cannot determine a parameter
==========================================

Two bodies: a mass on a spring with viscous damping that oscillates freely, and a block on a
rough surface pushed by a force that never exceeds its friction level,

.. math::

   w'' + c\\,w' + k\\,w = 0, \\qquad x' + \\mu\\,\\sigma(x) \\ni 0.3\\cos t ,

with the friction level :math:`\\mu = 1`: the block never slips. Both are measured with noise and
:func:`dmi.identify.estimate` is asked for :math:`(k, c, \\mu)`. The stiffness and damping come
out with small standard errors; the friction level cannot: any :math:`\\mu > 0.3` explains the
data equally well, the Jacobian's column of :math:`\\mu` is zero, and the estimate says so in
``unidentifiable`` (the combination ``1.00*mu``) with an infinite standard error for
:math:`\\mu` rather than a small one. The profile of :math:`\\mu` (right) tells what the data
do say: it is flat above 0.3 (the likelihood-ratio interval does not close there) and rises below
it, where the block would slip: :math:`\\mu \\ge 0.29` at 95 %.

A second fit has a memory with two Prony terms of equal exponents, :math:`(c_1 + c_2)e^{-s}`
acting on :math:`w'`: only the sum :math:`c_1 + c_2` matters, and the estimate names the
combination :math:`c_1 - c_2` (in units relative to each parameter's value) as undetermined.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import math
import os

import matplotlib.pyplot as plt
import numpy as np

import dmi
from dmi import identify

SIGMA = 0.01


def make(p):
    """State (w, w', x); p = (k, c, mu)."""
    k, c, mu = p
    s = dmi.Solver(3, 1.0, h=0.02)
    s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] + c * u[1], -0.3 * math.cos(t)]))
    s.set_friction([0.0, 0.0, mu])
    s.set_history(lambda t: np.array([1.0, 0.0, 0.0]))
    return s


def make_memory(p):
    """w'' + k w + int_0^5 (c1 + c2) e^{-s} w'(t - s) ds = 0; p = (k, c1, c2)."""
    k, c1, c2 = p
    s = dmi.Solver(2, 5.0, h=0.02)
    s.set_rhs(lambda t, u: np.array([-u[1], k * u[0]]))
    C = np.zeros((2, 2, 2))
    C[0, 1, 1], C[1, 1, 1] = c1, c2
    s.set_kernel_exp([-1.0, -1.0], [0.0, 0.0], C)
    s.set_history(lambda t: np.array([1.0, 0.0]))
    return s


def measure(mk, p, comps, steps, rng):
    s = mk(np.array(p, float))
    s.init()
    t, U = s.run(steps)
    return t[::3], U[::3][:, comps] + SIGMA * rng.standard_normal((len(t[::3]), len(comps)))


rng = np.random.default_rng(7)
t, y = measure(make, [1.0, 0.2, 1.0], [0, 2], 500, rng)
est = identify.estimate(make, [0.8, 0.3, 0.5], identify.Record(t, y, components=[0, 2], sigma=SIGMA),
                        names=["k", "c", "mu"], bounds=([0, 0, 0], [5, 5, 10]))
print(f"fit: {est.message}")
for name, pv, se in zip(est.names, est.p, est.stderr):
    print(f"  {name:3} {pv:9.5f} +- {se:.5f}")
print(f"undetermined: {est.unidentifiable}")
prof = identify.profile_likelihood(est, "mu", step=0.2, max_steps=6)
print(f"profile of mu: likelihood-ratio interval [{prof.interval[0]:.3f}, {prof.interval[1]}]: "
      f"{prof.message}")

t2, y2 = measure(make_memory, [1.0, 0.4, 0.6], [0], 500, rng)
est2 = identify.estimate(make_memory, [1.2, 0.5, 0.5], identify.Record(t2, y2[:, 0], sigma=SIGMA),
                         names=["k", "c1", "c2"])
print(f"equal exponents: k = {est2.p[0]:.5f} +- {est2.stderr[0]:.5f}, c1 + c2 = "
      f"{est2.p[1] + est2.p[2]:.5f}; undetermined: {est2.unidentifiable}")

fig, ax = plt.subplots(1, 2, figsize=(11, 4))
s = make(est.p)
s.init()
tt, U = s.run(500)
ax[0].plot(t, y[:, 0], ".", ms=2, color="0.5", label="measured w")
ax[0].plot(t, y[:, 1], ".", ms=2, color="0.7", label="measured x (never slips)")
ax[0].plot(tt, U[:, 0], lw=1, label="fitted w")
ax[0].set_xlabel("t")
ax[0].legend()
ax[0].set_title("data and fit")
ax[1].plot(prof.values, prof.cost - est.cost, "o-")
ax[1].axhline(prof.threshold, color="r", lw=0.8, label="95 % threshold")
ax[1].set_xlabel("mu")
ax[1].set_ylabel("cost - least cost")
ax[1].set_yscale("symlog")
ax[1].set_title("profile of the friction level: flat above 0.3")
ax[1].legend()
fig.tight_layout()
if os.environ.get("DMI_FIGURE"):
    fig.savefig(os.environ["DMI_FIGURE"], dpi=110)
