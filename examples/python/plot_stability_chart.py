"""
A stability chart
=================

The oscillator with a distributed delay

.. math::

   w'' + c\\,w' + b\\,w + a \\int_0^\\tau G(s)\\,w(t-s)\\,ds = 0, \\qquad
   G(s) = \\frac{e^{-s/\\theta}}{\\theta},

over the delay gain :math:`a` and the delay :math:`\\tau`, with :math:`c = 0.3`, :math:`b = 1`,
:math:`\\theta = 1`. :func:`dmi.analysis.stability_chart` computes the rightmost characteristic root
:math:`\\lambda_1` of the scheme's step map linearised at the rest :math:`w = 0` at every grid
point (in parallel processes), and traces the curves where :math:`\\lambda_1` crosses the imaginary
axis (Hopf curves, :math:`\\lambda = \\pm i\\omega`) by continuation. The model is the function
``oscillator(a, tau, N)`` of ``stability_chart.py`` beside this example (the program that draws the
chart at full resolution): the chart's worker processes import it from there.
See :doc:`/stability` for the method and its checks.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import functools

import matplotlib.pyplot as plt
import numpy as np

from dmi import analysis
from stability_chart import oscillator   # examples/python/stability_chart.py

N = 64                                     # steps per delay tau: h = tau / N
gains = np.linspace(-1.5, 3.0, 31)
delays = np.linspace(0.2, 8.0, 27)
model = functools.partial(oscillator, N=N)
chart = analysis.stability_chart(model, gains, delays, [0.0, 0.0], workers=2)

print(f"{len(gains)} x {len(delays)} grid, N = {N}: {len(chart.curves)} curves traced, "
      f"stable at {np.mean(chart.stable) * 100:.0f} % of the grid points")
# the rightmost roots at one point, and the Hopf point on the line tau = 2 between a = 0 and 3
lam = analysis.roots(lambda a: oscillator(a, 2.0, N), 1.0, [0.0, 0.0], count=3)
print("rightmost roots at a = 1, tau = 2:", np.array2string(lam, precision=4))
hp = analysis.hopf(lambda a: oscillator(a, 2.0, N), 0.0, 3.0, [0.0, 0.0])
print(f"Hopf point on tau = 2: a = {hp.p:.6f}, omega = {hp.omega:.6f} rad/s")

ax = analysis.plot_stability_chart(chart, p_label="delay gain a (1/s²)", q_label="delay τ (s)")
ax.plot([hp.p], [2.0], "o", color="C3")
ax.annotate("Hopf point at τ = 2", (hp.p, 2.0), xytext=(8, -14), textcoords="offset points",
            color="C3", fontsize=8)
plt.show()
