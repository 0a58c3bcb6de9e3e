# dmi-sweep plot: a bifurcation diagram (Poincare samples, or a metric, against
# one parameter) or a heatmap of a metric over two parameters (matplotlib Agg).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

import numpy as np


class PlotError(ValueError):
    """A column that is not there, or no result folder."""


def plot(directory: str | os.PathLike, x: str, y: str | None, metric: str | None,
         output: str | os.PathLike) -> None:
    """Writes the plot of the sweep in `directory` to `output` (PNG)."""
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
    df = df.sort_values("point")
    if "error" in df:
        df = df[df["error"].isna()]
    cols = list(df.columns)
    for name in (x, y):
        if name is not None and name not in cols:
            raise PlotError(f"{name!r} is not a column of {directory}; columns: {', '.join(cols)}")
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
        if metric.endswith("_poincare"):
            xs = np.concatenate([np.full(len(v), xv) for xv, v in zip(df[x], df[metric])])
            ys = np.concatenate([np.asarray(v, dtype=float) for v in df[metric]])
            ax.plot(xs, ys, ",", color="k", alpha=0.8, markersize=1) if len(xs) > 20000 else \
                ax.plot(xs, ys, ".", color="k", markersize=2)
            ax.set_title(f"Bifurcation diagram: {metric.removesuffix('_poincare')} on the Poincaré section")
        else:
            d = df.groupby(x)[metric].mean().sort_index()
            ax.plot(d.index, d.values, ".-")
            ax.set_title(f"{metric} against {x}")
        ax.set_xlabel(x)
        ax.set_ylabel(metric)
    else:
        if metric.endswith("_poincare"):
            raise PlotError("a heatmap needs a scalar metric, not a list column")
        table = df.pivot_table(index=y, columns=x, values=metric, aggfunc="mean")
        xs, ys = table.columns.to_numpy(float), table.index.to_numpy(float)
        mesh = ax.pcolormesh(xs, ys, table.to_numpy(float), shading="nearest")
        fig.colorbar(mesh, ax=ax, label=metric)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_title(f"{metric} over {x} and {y}")
    fig.tight_layout()
    fig.savefig(output)
    plt.close(fig)
