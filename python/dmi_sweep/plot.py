# dmi-sweep plot: a bifurcation diagram (Poincare samples, or a metric, against
# one parameter; one colour per value of a second parameter with --hue) or a
# heatmap of a metric over two parameters (matplotlib Agg), with axis labels in
# words and symbols.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

# Words for the variables of the project's oscillator (modelName DelayFrictionOscillator); the
# variables of another FMU are labelled by their names.
OSCILLATOR = "DelayFrictionOscillator"
WORDS = {
    "b": "stiffness", "alpha": "friction coefficient", "tau": "delay", "N": "steps per delay",
    "w0": "initial displacement", "v0": "initial velocity", "g_offset": "forcing offset",
    "g_amp": "forcing amplitude", "g_omega": "forcing angular frequency", "g_phase": "forcing phase",
    "H_c0": "kernel constant", "H_c1": "kernel exponential coefficient", "H_lambda": "kernel decay rate",
    "H_a1": "kernel cosine amplitude", "H_omega1": "kernel angular frequency",
    "H_a2": "kernel cosine amplitude", "H_omega2": "kernel angular frequency",
    "H_a3": "kernel cosine amplitude", "H_omega3": "kernel angular frequency",
    "w": "displacement", "v": "velocity", "friction": "friction force", "delay_force": "delay force",
    "sticking": "sticking",
}
# a Boolean output's mean is the fraction of the time it is true
FRACTIONS = {"sticking": "stick fraction"}
STATS = {"final": "{} at the stop time", "min": "minimum of {}", "max": "maximum of {}",
         "mean": "mean of {}", "poincare": "{} on the Poincaré section"}


class PlotError(ValueError):
    """A column that is not there, a parameter left out, or no result folder (a ``ValueError``)."""


class Labels:
    """Axis labels: words and the symbol ("forcing amplitude g_amp", "stick fraction") for the
    oscillator's columns, the column's name for another FMU's.

    Parameters
    ----------
    meta : dict
        The sweep folder's ``_meta.json`` (``model_name``, ``output_types``); ``{}`` when it has none.
    """

    def __init__(self, meta: dict):
        self.words = WORDS if meta.get("model_name") == OSCILLATOR else {}
        self.types = meta.get("output_types", {})

    def variable(self, name: str) -> str:
        """The label of a variable.

        Parameters
        ----------
        name : str
            A parameter or output name.

        Returns
        -------
        str
            Its words and name for the oscillator's variables, else the name.
        """
        return f"{self.words[name]} {name}" if name in self.words else name

    def __call__(self, column: str) -> str:
        y, _, stat = column.rpartition("_")
        if stat not in STATS or not y:
            return self.variable(column)
        if stat == "mean" and self.types.get(y) == "Boolean":
            if self.words and y in FRACTIONS:
                return FRACTIONS[y]
            return f"fraction of the time {y} is true"
        return STATS[stat].format(self.variable(y))


def plot(directory: str | os.PathLike, x: str, y: str | None, metric: str | None,
         output: str | os.PathLike, hue: str | None = None):
    """Writes the plot of the sweep in `directory` to `output` (PNG).

    Against the parameter `x`: one set of points per value of `hue`, or a heatmap over `x` and `y`.
    Every swept parameter must be `x`, `y` or `hue`, or hold a single value among the successful
    points.

    Parameters
    ----------
    directory : str or os.PathLike
        The sweep's folder (``dmi-sweep run --out``).
    x : str
        The parameter on the horizontal axis.
    y : str or None
        A second parameter: a heatmap of `metric` over `x` and `y`.
    metric : str or None
        The column to show (default: the first ``*_poincare`` column, or with `y` the first
        ``*_mean`` column).
    output : str or os.PathLike
        The PNG to write.
    hue : str, optional
        A second parameter: one set of points (or line) per value of it; excludes `y`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure, already written and closed.

    Raises
    ------
    PlotError
        If `directory` is not a folder or holds no results, a name is not a column or not a swept
        parameter, both `y` and `hue` are given, a swept parameter is left out, there is no metric
        column or no successful point, or a heatmap is asked of a list column.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    if not os.path.isdir(directory):
        raise PlotError(f"{directory} is not a folder")
    try:
        df = pd.read_parquet(directory)
    except Exception as e:
        raise PlotError(f"{directory}: no results to read ({e})") from None
    try:
        meta = json.loads((Path(directory) / "_meta.json").read_text())
    except (OSError, ValueError):
        meta = {}
    label = Labels(meta)
    df = df.sort_values("point")
    if "error" in df:
        df = df[df["error"].isna()]
    cols = list(df.columns)
    for name in (x, y, hue):
        if name is not None and name not in cols:
            raise PlotError(f"{name!r} is not a column of {directory}; columns: {', '.join(cols)}")
    if y is not None and hue is not None:
        raise PlotError("give --y (a heatmap) or --hue (one line per value), not both")
    params = meta.get("params") or []
    for name in (x, y, hue):
        if name is not None and params and name not in params:
            raise PlotError(f"{name!r} is not a swept parameter; the parameters: {', '.join(params)}")
    others = [p for p in params if p not in (x, y, hue) and df[p].nunique() > 1]
    if others:
        raise PlotError(f"the sweep varies {others[0]} besides {x}: give it as "
                        "--hue (one line per value) or --y (a heatmap)" if len(others) == 1 else
                        f"the sweep varies {', '.join(others)} besides {x}: a plot shows {x} and at "
                        "most one more (--hue or --y); select the points with pandas for the rest")
    if metric is None:
        pick = [c for c in cols if c.endswith("_poincare")] if y is None else []
        pick = pick or [c for c in cols if c.endswith("_mean")]
        if not pick:
            raise PlotError("no metric column; give --metric")
        metric = pick[0]
    if metric not in cols:
        raise PlotError(f"{metric!r} is not a column of {directory}; columns: {', '.join(cols)}")
    if df.empty:
        raise PlotError(f"{directory}: no successful point to plot")

    fig, ax = plt.subplots(figsize=(8, 5), dpi=120)
    if y is None:
        groups = [(None, df)] if hue is None else list(df.groupby(hue, sort=True))
        colours = plt.cm.viridis(np.linspace(0, 0.9, len(groups)))
        for (value, g), colour in zip(groups, colours):
            name = None if hue is None else f"{hue} = {value:g}" if isinstance(value, float) \
                else f"{hue} = {value}"
            colour = "k" if hue is None else colour
            if metric.endswith("_poincare"):
                xs = np.concatenate([np.full(len(v), xv) for xv, v in zip(g[x], g[metric])])
                ys = np.concatenate([np.asarray(v, dtype=float) for v in g[metric]])
                ax.plot(xs, ys, "," if len(xs) > 20000 else ".", color=colour,
                        markersize=1 if len(xs) > 20000 else 2, label=name)
            else:
                d = g.groupby(x)[metric].mean().sort_index()
                ax.plot(d.index, d.values, ".-", color=colour, label=name)
        if metric.endswith("_poincare"):
            ax.set_title(f"Bifurcation diagram: {label.variable(metric.removesuffix('_poincare'))} on "
                         "the Poincaré section")
        else:
            ax.set_title(f"{label(metric)} against {label(x)}")
        if hue is not None:
            ax.legend(title=label(hue), markerscale=4)
        ax.set_xlabel(label(x))
        ax.set_ylabel(label(metric))
    else:
        if metric.endswith("_poincare"):
            raise PlotError("a heatmap needs a scalar metric, not a list column")
        table = df.pivot_table(index=y, columns=x, values=metric, aggfunc="mean")
        xs, ys = table.columns.to_numpy(float), table.index.to_numpy(float)
        mesh = ax.pcolormesh(xs, ys, table.to_numpy(float), shading="nearest")
        fig.colorbar(mesh, ax=ax, label=label(metric))
        ax.set_xlabel(label(x))
        ax.set_ylabel(label(y))
        ax.set_title(f"{label(metric)} over {x} and {y}")
    fig.tight_layout()
    fig.savefig(output)
    plt.close(fig)
    return fig
