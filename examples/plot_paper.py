#!/usr/bin/env python3
# Figures 4.1-4.5 of the paper from the CSV files of scripts/main.sh, the
# FMU's Example 4.3 overlaid on the native run, the erratum of (4.4), and a
# comparison with the paper and with the independent reference values.
#
# Usage: plot_paper.py OUT_DIR [REFERENCE_DIR]
#   reads  OUT_DIR/ex41.csv ex42.csv ex43.csv order.csv scheme44.csv and, if
#          fmu43.csv (the FMU by fmpy) exists, ex43_fmu_native.csv (the native
#          run of Example 4.3 with the FMU's N, at every step)
#   writes OUT_DIR/fig4_1.png ... fig4_5.png, fmu_ex43.png, scheme44.png
#   prints the comparison table (stdout); exit status 1 if a check fails.
#
# The exact solutions (4.8) and (4.10) are evaluated here, independently of
# the C code, and the errors of the 1/9991 runs are recomputed from the CSV.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

PAPER_SLOPE = 0.993  # Figure 4.3
N_PAPER = 9991       # (4.5)
# Reproducible PNG files: no software version in the metadata.
PNG = {"dpi": 110, "metadata": {"Software": None}}


def exact(example, t):
    """(w, w') of (4.8) and (4.10)."""
    if example == 41:
        return (t - 1) * np.exp(-t), (2 - t) * np.exp(-t)
    return (t * t - t + 1) * np.exp(-t), (-t * t + 3 * t - 2) * np.exp(-t)


def read_csv(path):
    """Columns of a numeric CSV file with a header line, as a dict of arrays."""
    with open(path) as f:
        names = f.readline().strip().split(",")
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    return {name: data[:, i] for i, name in enumerate(names)}


def save(fig, path):
    fig.savefig(path, **PNG)
    plt.close(fig)
    print(f"wrote {path}")


def displacement_speed(title, curves, path, xlim=None):
    """Two panels, (a) displacement and (b) speed; curves: (label, t, w, v, style)."""
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True, layout="constrained")
    for label, t, w, v, style in curves:
        axes[0].plot(t, w, label=label, **style)
        axes[1].plot(t, v, label=label, **style)
    axes[0].set_ylabel("displacement w")
    axes[1].set_ylabel("speed w′ = dw/dt")
    axes[1].set_xlabel("time t")
    axes[0].set_title(f"{title} (a) displacement")
    axes[1].set_title("(b) speed")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        if xlim:
            ax.set_xlim(*xlim)
    if len(curves) > 1:   # below the panels, never over the curves
        fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=len(curves))
    save(fig, path)


def example_with_exact(out, example, figure):
    """Figures 4.1 / 4.2; returns the max errors (state, w, w') recomputed here."""
    d = read_csv(out / f"ex{example}.csv")
    t = d["t"]
    w_ex, v_ex = exact(example, t)
    errs = (float(np.max(np.hypot(d["w"] - w_ex, d["v"] - v_ex))),
            float(np.max(np.abs(d["w"] - w_ex))), float(np.max(np.abs(d["v"] - v_ex))))
    displacement_speed(
        f"Figure {figure}: Example {example // 10}.{example % 10}, h = 1/{N_PAPER},",
        [("exact (4.%s)" % ("8" if example == 41 else "10"), t, w_ex, v_ex,
          {"color": "black", "lw": 2.5}),
         ("computed (3.12)-(3.13)", t, d["w"], d["v"],
          {"color": "tab:orange", "lw": 1.2, "ls": "--"})],
        out / f"fig{figure.replace('.', '_')}.png")
    return errs


def slope(h, e):
    return float(np.polyfit(np.log(h), np.log(e), 1)[0])


def order_figure(out, order):
    """Figure 4.3: log-log max error against h for Example 4.2 with the fitted line."""
    sel = order["example"] == 4.2
    h, e = order["h"][sel], order["max_err_state"][sel]
    p = np.polyfit(np.log(h), np.log(e), 1)
    fig, ax = plt.subplots(figsize=(7, 5.5), layout="constrained")
    ax.loglog(h, e, "o", color="tab:blue", label="max error, Example 4.2")
    hh = np.array([h.min(), h.max()])
    ax.loglog(hh, np.exp(np.polyval(p, np.log(hh))), "-", color="tab:red",
              label=f"least-squares line, slope {p[0]:.3f} (paper {PAPER_SLOPE})")
    ax.set_xlabel("step size h = 1/(1001 + 50k), k = 1..18")
    ax.set_ylabel("max error over t_p in [−1, 10], |U^p − (w, w′)(t_p)|")
    ax.set_title("Figure 4.3: order of the scheme (3.12)-(3.13)")
    ax.grid(True, which="both", alpha=0.3)
    fig.legend(loc="outside lower center", ncols=2)
    save(fig, out / "fig4_3.png")
    return float(p[0])


def scheme44_figure(out):
    d = read_csv(out / "scheme44.csv")
    fig, ax = plt.subplots(figsize=(8, 6), layout="constrained")
    styles = [("err_printed", "(4.4) as printed: +h·Σ", "tab:red", "-"),
              ("err_no_h", "only the factor h missing: -h·Σ", "tab:purple", "-"),
              ("err_sign", "only the sign flipped: +h·h·Σ", "tab:green", "-"),
              ("err_312", "(3.12)-(3.13) by hand: -h·h·Σ", "tab:blue", "-"),
              ("err_library", "libdmi (3.12)-(3.13)", "black", ":")]
    for col, label, color, ls in styles:
        e = d[col]
        ok = np.isfinite(e) & (e > 0)
        ax.semilogy(d["t"][ok], e[ok], ls, color=color, label=label)
    top = math.ceil(math.log10(np.nanmax(np.where(np.isfinite(d["err_printed"]), d["err_printed"],
                                                   np.nan))))
    ax.set_yticks([10.0 ** k for k in range(-4, top + 1, 10)])
    ax.set_xlabel("time t")
    ax.set_ylabel("error |U^p − (w, w′)(t_p)|")
    ax.set_title(f"Example 4.2, h = 1/{N_PAPER}: scheme (4.4) as printed diverges")
    ax.grid(True, which="both", alpha=0.3)
    fig.legend(loc="outside lower center", ncols=2, fontsize=9)
    save(fig, out / "scheme44.png")


def fmu_figure(out):
    """The FMU's Example 4.3 (fmpy, fmu43.csv) over the native run with the FMU's step h
    (ex43_fmu_native.csv); returns max |difference| of (w, w'), the number of times, 1/h."""
    f = read_csv(out / "fmu43.csv")
    nat = read_csv(out / "ex43_fmu_native.csv")
    keep = f["t"] <= nat["t"][-1] + 1e-12
    tf, wf, vf = f["t"][keep], f["w"][keep], f["v"][keep]
    # Both are the piecewise linear u_h: compare at the FMU's communication points.
    dw = np.abs(wf - np.interp(tf, nat["t"], nat["w"]))
    dv = np.abs(vf - np.interp(tf, nat["t"], nat["v"]))
    inv_h = round(1.0 / (nat["t"][1] - nat["t"][0]))
    diff = float(max(dw.max(), dv.max()))
    displacement_speed(
        f"Example 4.3, h = 1/{inv_h}: FMU by fmpy and native libdmi,\n"
        f"max |difference| {diff:.1e} on [0, {tf[-1]:g}], shown on [0, 5];",
        [("native libdmi", nat["t"], nat["w"], nat["v"], {"color": "black", "lw": 2.5}),
         ("FMU (fmpy)", tf, wf, vf, {"color": "tab:orange", "lw": 1.2, "ls": "--"})],
        out / "fmu_ex43.png", xlim=(0, 5))
    return diff, len(tf), inv_h


def main(argv):
    if len(argv) < 2:
        print(__doc__ if __doc__ else "usage: plot_paper.py OUT_DIR [REFERENCE_DIR]")
        return 2
    out = Path(argv[1])
    ref = Path(argv[2]) if len(argv) > 2 else None
    failed = []

    err = {41: example_with_exact(out, 41, "4.1"), 42: example_with_exact(out, 42, "4.2")}
    order = read_csv(out / "order.csv")
    our_slope = order_figure(out, order)
    ex43 = read_csv(out / "ex43.csv")
    for fig, upto in (("4.4", 2), ("4.5", 30)):
        sel = ex43["t"] <= upto + 1e-12
        displacement_speed(f"Figure {fig}: Example 4.3 on [0, {upto}], h = 1/{N_PAPER},",
                           [("computed (3.12)-(3.13)", ex43["t"][sel], ex43["w"][sel],
                             ex43["v"][sel], {"color": "tab:blue", "lw": 1.0})],
                           out / f"fig{fig.replace('.', '_')}.png", xlim=(0, upto))
    scheme44_figure(out)
    fmu = None
    if (out / "fmu43.csv").exists():
        fmu = fmu_figure(out)
    else:
        print(f"skipped the FMU figure: {out / 'fmu43.csv'} does not exist")

    # The comparison table: ours, the paper, the reference.
    refs = {}
    if ref and (ref / "errors_ex41_ex42.csv").exists():
        r = read_csv(ref / "errors_ex41_ex42.csv")
        refs = {(float(r["example"][i]), int(r["N"][i])): (r["max_err_state"][i], r["max_err_w"][i],
                                                          r["max_err_v"][i])
                for i in range(len(r["N"]))}
    rows = []

    def rel(a, b):
        return abs(a - b) / abs(b)

    def fmt(x, spec, prefix=""):
        return "-" if math.isnan(x) else prefix + format(x, spec)

    for ex in (41, 42):
        key = (ex / 10, N_PAPER)
        for j, name in enumerate(("(w, w')", "w", "w'")):
            ours = err[ex][j]
            theirs = refs.get(key, (math.nan,) * 3)[j]
            rows.append((f"Example {ex / 10} max error in {name}, h = 1/{N_PAPER}", f"{ours:.4e}",
                         "-", fmt(theirs, ".4e"), fmt(rel(ours, theirs), ".1e", "rel. ")))
            if refs and not rel(ours, theirs) < 0.01:
                failed.append(rows[-1][0])
    sel42 = order["example"] == 4.2
    ref_slope = math.nan
    worst = 0.0
    if refs:
        hs = [k for k in refs if k[0] == 4.2 and k[1] != N_PAPER]
        ref_slope = slope(np.array([1.0 / k[1] for k in hs]), np.array([refs[k][0] for k in hs]))
        for N, e in zip(order["N"][sel42], order["max_err_state"][sel42]):
            worst = max(worst, rel(e, refs[(4.2, int(N))][0]))
        rows.append(("Figure 4.3 errors, Example 4.2, 18 h (largest difference)", "-", "-", "-",
                     f"rel. {worst:.1e}"))
        if not worst < 0.01:
            failed.append(rows[-1][0])
    rows.append(("Figure 4.3 slope, Example 4.2, (w, w')", f"{our_slope:.4f}", f"{PAPER_SLOPE}",
                 fmt(ref_slope, ".4f"), fmt(abs(our_slope - ref_slope), ".1e", "abs. ")))
    if not 0.95 <= our_slope <= 1.05:
        failed.append(rows[-1][0])
    for col, name in (("max_err_w", "w"), ("max_err_v", "w'")):
        rows.append((f"Figure 4.3 slope, Example 4.2, {name} alone",
                     f"{slope(order['h'][sel42], order[col][sel42]):.4f}", "-", "-", "-"))
    if ref and (ref / "ex43_N9991.csv").exists():
        r = read_csv(ref / "ex43_N9991.csv")
        p = r["p"].astype(int)
        if p.max() < len(ex43["t"]):
            dt = np.max(np.abs(ex43["t"][p] - r["t"]))
            dev = max(np.max(np.abs(ex43["w"][p] - r["w"])), np.max(np.abs(ex43["v"][p] - r["v"])))
            rows.append(("Example 4.3 (w, w') at every 100th t_p, h = 1/9991", "-", "-", "-",
                         f"abs. {dev:.1e}"))
            if not (dt < 1e-12 and dev < 1e-10):
                failed.append(rows[-1][0])
    if fmu:
        rows.append((f"Example 4.3, max |FMU - native| (w, w'), h = 1/{fmu[2]}, at {fmu[1]} times",
                     f"{fmu[0]:.1e}", "-", "-", "-"))
    widths = [max(len(row[i]) for row in rows + [HEADER]) for i in range(len(HEADER))]
    for row in [HEADER] + rows:
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths)))
    if failed:
        print("plot_paper.py: disagreement with the reference: " + "; ".join(failed))
        return 1
    return 0


HEADER = ("quantity", "ours", "paper", "reference", "ours - reference")

if __name__ == "__main__":
    sys.exit(main(sys.argv))
