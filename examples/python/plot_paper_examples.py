"""
The paper's three examples
==========================

Examples 4.1, 4.2 and 4.3 of Lamarque, Bastien and Holland: the friction oscillator

.. math::

   w'' + b\\,w + \\int_0^\\tau H(s)\\,w(t-s)\\,ds + \\alpha\\,\\sigma(w') + g(t) \\ni 0,
   \\qquad b = \\alpha = \\tau = 1,

with :math:`\\sigma` the sign graph (dry friction), as the first-order inclusion of libdmi in
:math:`u = (w, w')`:

.. math::

   u' + A(u) + f(t, u) + \\int_0^\\tau \\begin{pmatrix} 0 & 0 \\\\ H(s) & 0 \\end{pmatrix} u(t-s)\\,ds
   \\ni 0, \\qquad f(t, u) = \\begin{pmatrix} -w' \\\\ w + g(t) \\end{pmatrix},
   \\qquad A = \\{0\\} \\times \\sigma.

Examples 4.1 and 4.2 have the constant kernel :math:`H = 1`, a forcing :math:`g` built so that
their exact solutions are :math:`w = (t - 1)e^{-t}` and :math:`w = (t^2 - t + 1)e^{-t}`, and start
from those on :math:`[-1, 0]`; Example 4.3 has :math:`H(s) = \\cos 2\\pi s + \\cos 10\\pi s +
\\cos 20\\pi s`, :math:`g(t) = 1.3 \\cos 8t` and starts from rest. The scheme is of order 1 on the
first two: the error printed below halves with :math:`h`.
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import matplotlib.pyplot as plt
import numpy as np

import dmi


def g41(t):
    return (-t + 4) * np.exp(-t) + (-t + 1) * np.exp(1 - t) + np.sign(t - 2)


def g42(t):
    base = (-t * t + 7 * t - 4) * np.exp(-t) + (-t * t + t - 2) * np.exp(1 - t)
    return base + (1.0 if t < 1 or t > 2 else (-1.0 if 1 < t < 2 else 0.0))


EXAMPLES = {  # forcing g, kernel H, exact w and w' (None: no closed form, start from rest)
    "4.1": (g41, lambda s: 1.0, lambda t: (t - 1) * np.exp(-t), lambda t: (2 - t) * np.exp(-t)),
    "4.2": (g42, lambda s: 1.0, lambda t: (t * t - t + 1) * np.exp(-t),
            lambda t: (-t * t + 3 * t - 2) * np.exp(-t)),
    "4.3": (lambda t: 1.3 * np.cos(8 * t),
            lambda s: np.cos(2 * np.pi * s) + np.cos(10 * np.pi * s) + np.cos(20 * np.pi * s),
            None, None),
}


def solve(name: str, N: int, T: float):
    """Example `name` with h = 1/N up to t = T: the times and the states (w, w')."""
    g, H, w, v = EXAMPLES[name]
    s = dmi.Solver(2, 1.0, N)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] + g(t)]))
    s.set_kernel(lambda x: np.array([[0.0, 0.0], [H(x), 0.0]]))
    if w is not None:
        s.set_history(lambda t: np.array([w(t), v(t)]))
    s.set_friction([0.0, 1.0])
    s.init()
    return s.run(int(round(T * N)), stride=max(1, N // 200))


fig, axes = plt.subplots(1, 3, figsize=(12, 3.4), layout="constrained")
for ax, name in zip(axes, EXAMPLES):
    T = 10.0 if name != "4.3" else 15.0
    t, U = solve(name, 1000, T)
    ax.plot(t, U[:, 0], label="dmi, h = 1/1000")
    exact = EXAMPLES[name][2]
    if exact is not None:
        ax.plot(t, exact(t), "k--", lw=1, label="exact")
        for N in (250, 500, 1000):
            tN, UN = solve(name, N, 10.0)
            print(f"Example {name}: h = 1/{N:<4}  max |w - w_exact| on [0, 10] = "
                  f"{np.max(np.abs(UN[:, 0] - exact(tN))):.2e}")
    ax.set_title(f"Example {name}")
    ax.set_xlabel("t")
    ax.set_ylabel("w")
    ax.legend(loc="upper right", fontsize=8)
plt.show()
