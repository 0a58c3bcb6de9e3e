"""
An interactive branch: hover a point, click it for its orbit
============================================================

A Stuart–Landau oscillator with a distributed memory, whose frequency grows with its amplitude,
in :math:`z = u_1 + i u_2`:

.. math::

   z' = (\\mu - |z|^2)\\,z + i\\,(\\omega_0 + b\\,|z|^2)\\,z
        - \\int_0^\\tau k\\,e^{-a s}\\,z(t-s)\\,ds .

The rest :math:`z = 0` loses its stability at a Hopf point as :math:`\\mu` grows; the orbits born
there are circles whose period shrinks as they grow.  :func:`~dmi.analysis.continue_equilibrium`
finds the Hopf point, :func:`~dmi.analysis.hopf_orbit` and :func:`~dmi.analysis.continue_orbit`
follow the orbits, and ``branch.to_html(path)`` writes the branch as one standalone HTML file
(BokehJS inlined: it opens offline).  In the figure at the end of this page, hover a point of the
branch for its :math:`\\mu`, period, amplitude, leading Floquet multipliers and stability, and click
it to draw its orbit in the right panel.  The model is ``make(mu)`` of ``landau_memory.py`` beside
this example.  See :doc:`/orbits` (Interactive figures).
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import html
import math
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from dmi import analysis
from landau_memory import N, TAU, make     # examples/python/landau_memory.py: the model


eq = analysis.equilibrium(make, 0.0, [0.02, -0.01])
equilibria = analysis.continue_equilibrium(eq, 0.6, step=0.1)
(hopf,) = [e for e in equilibria.events if e.kind == "hopf"]
print(f"Hopf point at mu = {hopf.hopf.p:.6f}, omega = {hopf.hopf.omega:.6f}")
M = round(2 * math.pi / hopf.hopf.omega / (TAU / N))
orbit = analysis.hopf_orbit(make, hopf.hopf, hopf.u, amplitude=0.1, steps=M)
branch = analysis.continue_orbit(orbit, 1.0, step=0.1, max_points=10, multipliers=3)
for q in branch.points[::3]:
    print(f"mu = {q.p:.4f}: period {q.period:.4f}, amplitude {q.amplitude[0]:.4f}")

fig, ax = plt.subplots(figsize=(6.4, 4), layout="constrained")
analysis.plot_branch(equilibria, ax, color="C2", p_label="mu")
analysis.plot_branch(branch, ax, color="C0", p_label="mu")
ax.set_ylabel("u_0: equilibrium (green), amplitude of the orbits (blue)")
plt.show()

# %%
# In Jupyter, a branch as the last expression of a cell shows a short summary:
branch

# %%
# The interactive figure: ``branch.to_html(path)`` writes it; here it is read back and shown in
# an ``iframe`` (Jupyter and this page display an object's ``_repr_html_``).


class Standalone:
    """A standalone HTML file shown in an iframe."""

    def __init__(self, text: str, height: int = 460):
        self.text, self.height = text, height

    def _repr_html_(self) -> str:
        return (f'<iframe srcdoc="{html.escape(self.text)}" style="width: 100%; '
                f'height: {self.height}px; border: none"></iframe>')


with tempfile.TemporaryDirectory() as folder:
    path = Path(folder) / "branch.html"
    branch.to_html(path, p_label="mu")
    print(f"{path.name}: {path.stat().st_size / 1e6:.2f} MB")
    figure = Standalone(path.read_text())
figure
