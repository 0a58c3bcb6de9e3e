# dmi-sweep on a LocalCluster: values against plain fmpy.simulate_fmu runs,
# independence of the number of workers, failing points, resume and restart,
# bad specs refused before anything runs, the plots.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from fmpy import simulate_fmu

from conftest import log_entries, run_sweep, write_spec

OUTPUTS = ["w", "v", "friction", "delay_force", "sticking"]

SPEC = """
fmu = "{fmu}"
stop_time = 3.0
output_interval = 0.01
transient = 1.5
[start]
N = 400
tau = 0.5
[grid]
g_amp = {{ start = 0.8, stop = 2.4, num = 3 }}
alpha = [-0.5, 0.3, 1.0]
[poincare]
period = "g_omega"
"""


def plain(fmu, values, stop, interval, **kw):
    return simulate_fmu(fmu, stop_time=stop, output_interval=interval, start_values=values,
                        output=OUTPUTS, **kw)


def assert_stats_equal(row, res, transient):
    """The row's statistics against those of the simulate_fmu result `res`, computed here (math.fsum
    for the mean) over its rows with time >= transient."""
    window = res[res["time"] >= transient - 1e-9]
    for y in OUTPUTS:
        col = [float(x) for x in window[y]]
        want = [float(res[y][-1]), min(col), max(col), math.fsum(col) / len(col)]
        got = [row[f"{y}_{s}"] for s in ("final", "min", "max", "mean")]
        assert np.max(np.abs(np.subtract(got, want))) <= 1e-12, (y, got, want)
    return window


@pytest.fixture(scope="module")
def two_workers(tmp_path_factory, fmu_path):
    d = tmp_path_factory.mktemp("two")
    spec = write_spec(d, SPEC.format(fmu=fmu_path))
    r = run_sweep("run", spec, "--out", d / "out", "--workers", "2", "--chunk-size", "1")
    # alpha = -0.5 fails at 3 of the 9 points: exit status 1, the count printed
    assert r.returncode == 1 and "3 of 9 points failed" in r.stderr, r.stderr
    assert "9 points in" in r.stdout and "3 failed" in r.stdout, r.stdout
    assert not list((d / "out").glob(".*")), "temporary files left"
    return d, pd.read_parquet(d / "out").sort_values("point").reset_index(drop=True)


def test_values_equal_plain_fmpy_runs(two_workers, fmu_path):
    """Every successful point against a fresh simulate_fmu run (statistics over the communication
    points in [1.5, 3], computed here with math.fsum); the Poincare samples against a simulate_fmu
    run whose input has events at t = k 2 pi / g_omega in [1.5, 3] (fmpy then adds those points)."""
    _, df = two_workers
    assert list(df["point"]) == list(range(9))
    grid = [(a, b) for a in (0.8, 1.6, 2.4) for b in (-0.5, 0.3, 1.0)]   # last parameter fastest
    assert np.allclose(df[["g_amp", "alpha"]].to_numpy(), grid, rtol=0, atol=1e-15)
    ok = df[df["error"].isna()]
    assert len(ok) == 6
    period = 2 * math.pi / 8.0
    for _, row in ok.iterrows():
        values = {"N": 400, "tau": 0.5, "g_amp": row["g_amp"], "alpha": row["alpha"]}
        res = plain(fmu_path, values, 3.0, 0.01)
        assert len(res) == 301 and res["time"][-1] == 3.0
        assert len(assert_stats_equal(row, res, 1.5)) == 151
        times = [k * period for k in range(100) if 1.5 <= k * period <= 3.0]   # phase-locked
        t_in = [0.0] + [t for t in times for _ in (0, 1)] + [3.0]
        signal = np.array([(t, 0.0) for t in t_in], dtype=[("time", float), ("g_in", float)])
        ev = plain(fmu_path, values, 3.0, 0.01, input=signal)
        assert all(min(abs(ev["time"] - t)) < 1e-12 for t in times)
        for y in OUTPUTS:
            want = [float(ev[y][np.argmin(np.abs(ev["time"] - t))]) for t in times]
            assert np.max(np.abs(np.subtract(row[f"{y}_poincare"], want))) <= 1e-12, y
    # the stick fraction is the mean of the Boolean output: some points stick part of the time
    assert ((ok["sticking_mean"] > 0) & (ok["sticking_mean"] < 1)).any()


def test_fmi3_fmu_equals_plain_fmpy(tmp_path):
    """The same sweep on an FMI 3.0 build of the oscillator (DMI_FMU3, set by ctest when the build
    has one): FMU3Slave chosen from fmiVersion, values as simulate_fmu gives them."""
    import os
    fmu3 = os.environ.get("DMI_FMU3")
    if not fmu3:
        pytest.fail("environment variable DMI_FMU3 is not set (run the tests through ctest, which "
                    "sets it to the FMI 3.0 FMU of the build)")
    from fmpy import read_model_description
    assert read_model_description(fmu3).fmiVersion.startswith("3")
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu3).replace("[-0.5, 0.3, 1.0]", "[1.0]"))
    r = run_sweep("run", spec, "--out", tmp_path / "out", "--workers", "2", "--chunk-size", "1")
    assert r.returncode == 0, r.stderr
    df = pd.read_parquet(tmp_path / "out").sort_values("point")
    assert len(df) == 3 and df["error"].isna().all()
    for _, row in df.iterrows():
        res = plain(fmu3, {"N": 400, "tau": 0.5, "g_amp": row["g_amp"], "alpha": 1.0}, 3.0, 0.01)
        assert_stats_equal(row, res, 1.5)


def test_failing_point_recorded(two_workers):
    """alpha < 0: the FMU rejects it; the row keeps the FMU's reason, the sweep goes on."""
    _, df = two_workers
    bad = df[df["alpha"] < 0]
    assert len(bad) == 3
    for msg in bad["error"]:
        assert "friction coefficient must be >= 0" in msg
    assert bad["w_final"].isna().all()
    assert df[df["alpha"] > 0]["error"].isna().all()


def test_independent_of_workers(two_workers, tmp_path):
    """One worker and default chunks give the same table, bit for bit."""
    d, df2 = two_workers
    r = run_sweep("run", d / "spec.toml", "--out", tmp_path / "one", "--workers", "1")
    assert r.returncode == 1, r.stderr
    df1 = pd.read_parquet(tmp_path / "one").sort_values("point").reset_index(drop=True)
    pd.testing.assert_frame_equal(df1, df2, check_exact=True)


def test_metadata_and_resume_nothing_to_do(two_workers, fmu_path):
    import hashlib
    import json
    d, _ = two_workers
    meta = json.loads((d / "out" / "_meta.json").read_text())
    assert meta["fmu_sha256"] == hashlib.sha256(open(fmu_path, "rb").read()).hexdigest()
    assert meta["versions"]["fmpy"] and meta["versions"]["distributed"]
    assert (d / "out" / "_spec.toml").read_text() == (d / "spec.toml").read_text()
    r = run_sweep("run", d / "spec.toml", "--out", d / "out")
    # the failed points of the first run still count: exit 1 until the folder holds 9 good points
    assert r.returncode == 1 and "9 already there, 0 computed" in r.stdout, r.stdout + r.stderr
    assert "3 of 9 points failed" in r.stderr, r.stderr
    assert log_entries(d / "out")[-1] == {**log_entries(d / "out")[-1], "run": True, "todo": 0}


def test_changed_spec_refused_unless_restart(tmp_path, fmu_path):
    small = SPEC.format(fmu=fmu_path).replace("num = 3", "num = 1").replace("[-0.5, 0.3, 1.0]", "[1.0]")
    spec = write_spec(tmp_path, small)
    assert run_sweep("run", spec, "--out", tmp_path / "o", "--workers", "1").returncode == 0
    write_spec(tmp_path, small.replace("stop_time = 3.0", "stop_time = 2.5"))
    r = run_sweep("run", spec, "--out", tmp_path / "o", "--workers", "1")
    assert r.returncode == 2 and "the spec differs" in r.stderr and "--restart" in r.stderr, r.stderr
    r = run_sweep("run", spec, "--out", tmp_path / "o", "--workers", "1", "--restart")
    assert r.returncode == 0 and "0 already there, 1 computed" in r.stdout, r.stdout + r.stderr
    df = pd.read_parquet(tmp_path / "o")
    res = plain(fmu_path, {"N": 400, "tau": 0.5, "g_amp": 0.8, "alpha": 1.0}, 2.5, 0.01)
    assert len(df) == 1 and abs(df["w_final"][0] - res["w"][-1]) <= 1e-12


def test_plots(two_workers, tmp_path, capsys):
    """A sweep of g_amp and alpha: --x g_amp alone is refused naming alpha; --hue alpha draws one
    set per value of alpha, with the Poincare samples of the table; the labels are words with the
    symbol; the heatmap's colour bar is the stick fraction."""
    from dmi_sweep.cli import main
    from dmi_sweep.plot import plot
    d, df = two_workers
    png = tmp_path / "p.png"
    assert main(["plot", str(d / "out"), "--x", "g_amp", "-o", str(png)]) == 2
    err = capsys.readouterr().err
    assert "the sweep varies alpha besides g_amp" in err and "--hue" in err, err
    assert not png.exists()

    fig = plot(d / "out", "g_amp", None, None, png, hue="alpha")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ax = fig.axes[0]
    assert ax.get_xlabel() == "forcing amplitude g_amp"
    assert ax.get_ylabel() == "displacement w on the Poincaré section"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["alpha = 0.3", "alpha = 1"]
    assert ax.get_legend().get_title().get_text() == "friction coefficient alpha"
    ok = df[df["error"].isna()]
    for line, alpha in zip(ax.get_lines(), (0.3, 1.0)):
        rows = ok[ok["alpha"] == alpha]
        want = sorted((g, y) for g, ys in zip(rows["g_amp"], rows["w_poincare"]) for y in ys)
        assert sorted(zip(line.get_xdata(), line.get_ydata())) == want

    fig = plot(d / "out", "g_amp", "alpha", "sticking_mean", png)
    assert (fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()) == ("forcing amplitude g_amp",
                                                                     "friction coefficient alpha")
    assert fig.axes[1].get_ylabel() == "stick fraction"          # the colour bar
    fig = plot(d / "out", "alpha", None, "w_max", png, hue="g_amp")
    assert fig.axes[0].get_ylabel() == "maximum of displacement w"
    assert len(fig.axes[0].get_lines()) == 3

    assert main(["plot", str(d / "out"), "--x", "nope", "-o", str(png)]) == 2
    assert "'nope' is not a column" in capsys.readouterr().err


def test_plot_refuses_naming_the_other_parameters(tmp_path, capsys):
    """Three swept parameters (a folder made here): --x a is refused, naming b and c; --x a --hue b
    too, naming c; a parameter that holds one value is not in the way."""
    import json
    from dmi_sweep.cli import main
    rows = [(a, b, c) for a in (1.0, 2.0) for b in (0.1, 0.2) for c in (5.0, 6.0)]
    table = pd.DataFrame({"a": [r[0] for r in rows], "b": [r[1] for r in rows], "c": [r[2] for r in rows],
                          "k": 3.0, "point": range(8), "w_mean": np.arange(8.0), "error": None})
    out = tmp_path / "out"
    out.mkdir()
    table.to_parquet(out / "part-000000000.parquet")
    (out / "_meta.json").write_text(json.dumps({"params": ["a", "b", "c", "k"], "model_name": "X"}))
    png = str(tmp_path / "p.png")
    assert main(["plot", str(out), "--x", "a", "--metric", "w_mean", "-o", png]) == 2
    assert "the sweep varies b, c besides a" in capsys.readouterr().err
    assert main(["plot", str(out), "--x", "a", "--hue", "b", "--metric", "w_mean", "-o", png]) == 2
    assert "the sweep varies c besides a" in capsys.readouterr().err
    assert main(["plot", str(out), "--x", "a", "--y", "b", "--hue", "c",
                 "-o", png]) == 2
    assert "not both" in capsys.readouterr().err
    table[table["c"] == 5.0].to_parquet(out / "part-000000000.parquet")
    assert main(["plot", str(out), "--x", "a", "--hue", "b", "--metric", "w_mean", "-o", png]) == 0
    from dmi_sweep.plot import plot
    ax = plot(out, "a", None, "w_mean", png, hue="b").axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("a", "mean of w")   # another FMU: names only


GOOD = """
fmu = "{fmu}"
stop_time = 1.0
output_interval = 0.1
transient = 0.5
[grid]
g_amp = [1.0]
"""

@pytest.mark.parametrize("change,message", [
    (("[grid]\ng_amp = [1.0]", "[grid]\ng_ampp = [1.0]"), "'g_ampp' is not a variable of the FMU; valid names: b, alpha, tau"),
    (("[grid]\ng_amp = [1.0]", "[grid]\nw = [1.0]"), "'w' is not a parameter or input of the FMU"),
    (("g_amp = [1.0]", "g_amp = [1.0, \"x\"]"), "'x' is not a (finite) number"),
    (("g_amp = [1.0]", "g_amp = { start = 1, stop = 2, num = 0 }"), "num = 0 is less than 1"),
    (("g_amp = [1.0]", "N = [10.5]"), "10.5 is not an integer"),
    (("transient = 0.5", "transient = 1.0"), "transient = 1 is not before stop_time = 1"),
    (("transient = 0.5", "transient = 0.5\noutputs = [\"w\", \"vv\"]"), "'vv' is not an output of the FMU; valid: w, v, friction"),
    (("stop_time = 1.0", "stop_time = \"1\""), "stop_time: '1' is not a (finite) number"),
    (("output_interval = 0.1", "output_interval = 0"), "output_interval = 0 is not positive"),
    (("transient = 0.5", "transient = 0.5\nstoptime = 2"), "unknown entries stoptime"),
    (("[grid]", "[start]\ng_amp = 2\n[grid]"), "g_amp is both in [start] and swept"),
    (("g_amp = [1.0]", "g_amp = []"), "the list of values is empty"),
    (("transient = 0.5", "transient = 0.5\n[poincare]\nperiod = -1"), "poincare.period = -1 is not positive"),
    (("transient = 0.5", "transient = 0.5\n[random]\nn = 0"), "random.n = 0 is not an integer >= 1"),
    (("fmu = ", "fmu = \"nothere.fmu\" #"), "nothere.fmu does not exist"),
    (("[grid]", "[grid"), "not valid TOML"),
])
def test_bad_spec_refused(tmp_path, fmu_path, change, message, capsys):
    """Refused before anything runs: exit 2, a clear message, no result folder."""
    from dmi_sweep.cli import main
    text = GOOD.format(fmu=fmu_path)
    assert change[0] in text
    spec = write_spec(tmp_path, text.replace(change[0], change[1], 1))
    assert main(["run", str(spec), "--out", str(tmp_path / "out"), "--workers", "1"]) == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert not (tmp_path / "out").exists()


def test_good_spec_accepted_and_random(tmp_path, fmu_path):
    """The base of the bad specs is good; a Latin hypercube has one sample per stratum."""
    from dmi_sweep.spec import load
    spec = load(write_spec(tmp_path, GOOD.format(fmu=fmu_path)))
    assert spec.params == ["g_amp"] and spec.n_points == 1
    text = GOOD.format(fmu=fmu_path).replace("[grid]\ng_amp = [1.0]",
                                             "[random]\nn = 50\nseed = 3\ng_amp = { low = 1, high = 2 }\n"
                                             "[grid]\nalpha = { low = 0, high = 5 }")
    spec = load(write_spec(tmp_path, text))
    assert spec.mode == "random" and spec.params == ["g_amp", "alpha"] and spec.n_points == 50
    for j, (lo, hi) in enumerate([(1, 2), (0, 5)]):
        strata = np.floor((spec.values[:, j] - lo) / (hi - lo) * 50)
        assert sorted(strata) == list(range(50))


def test_bad_spec_exit_status_of_the_command(tmp_path, fmu_path):
    spec = write_spec(tmp_path, GOOD.format(fmu=fmu_path).replace("g_amp = [1.0]", "gamp = [1.0]"))
    r = run_sweep("run", spec, "--out", tmp_path / "out")
    assert r.returncode == 2 and "'gamp' is not a variable" in r.stderr, r.stderr


def test_reset_instance_equals_fresh_instance(fmu_path, tmp_path):
    """A worker's instance, reset between points, gives what a fresh instance gives, bit for bit,
    also after a point the FMU rejected."""
    from dmi_sweep.simulate import Runner, unpack
    job = {"start_time": 0.0, "stop_time": 2.0, "output_interval": 0.01, "transient": 1.0,
           "start": {"N": 300}, "outputs": OUTPUTS, "poincare": 0.3}
    a, b, bad = {"g_amp": 2.0, "alpha": 0.4}, {"g_amp": 1.2, "alpha": 1.0}, {"alpha": -1.0}
    unzipdir = unpack(open(fmu_path, "rb").read(), str(tmp_path))
    fresh = [Runner(unzipdir).run(job, p) for p in (a, b)]
    reused = Runner(unzipdir)
    runs = [reused.run(job, p) for p in (a, b, a, bad, b, a)]
    assert runs[3]["error"] and "friction coefficient" in runs[3]["error"]
    for got, want in zip([runs[0], runs[1], runs[2], runs[4], runs[5]], [fresh[0], fresh[1], fresh[0], fresh[1], fresh[0]]):
        assert got == want
    assert fresh[0] != fresh[1]


def test_point_that_kills_its_worker(tmp_path, fmu_path, monkeypatch):
    """A chunk whose task kills its worker (an FMU crashing the process) is split into single points;
    the culprit is recorded with the error, the other points are computed."""
    import os

    import dask
    from distributed import LocalCluster

    import dmi_sweep.run as sweep
    from dmi_sweep.spec import load
    real = sweep.run_chunk

    def crashing(plugin_name, job, points):
        if any(i == 5 for i, _ in points):
            os._exit(3)
        return real(plugin_name, job, points)

    monkeypatch.setattr(sweep, "run_chunk", crashing)
    spec = load(write_spec(tmp_path, SPEC.format(fmu=fmu_path).replace("[-0.5, 0.3, 1.0]", "[0.3, 1.0]")
                           .replace("num = 3", "num = 4")))
    with dask.config.set({"distributed.scheduler.allowed-failures": 0,
                          "distributed.scheduler.worker-saturation": 1.0}), \
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as c:
        s = sweep.run(spec, tmp_path / "out", scheduler=c.scheduler_address, chunk_size=4, progress=None)
    df = pd.read_parquet(tmp_path / "out").sort_values("point")
    assert (s.computed, s.failed) == (8, 1), df[["point", "error"]].to_string()
    assert list(df["point"]) == list(range(8))
    assert "KilledWorker" in df["error"][df["point"] == 5].iloc[0]
    assert df[df["point"] != 5]["error"].isna().all()


def test_latin_hypercube_sweep(tmp_path, fmu_path):
    """[random]: n points with the sampled values as columns, each equal to a plain fmpy run."""
    text = SPEC.format(fmu=fmu_path).replace(
        "[grid]\ng_amp = { start = 0.8, stop = 2.4, num = 3 }\nalpha = [-0.5, 0.3, 1.0]",
        "[random]\nn = 3\nseed = 7\ng_amp = { low = 0.8, high = 2.4 }\nalpha = { low = 0.2, high = 1.0 }")
    assert "[random]" in text
    spec = write_spec(tmp_path, text)
    r = run_sweep("run", spec, "--out", tmp_path / "out", "--workers", "1")
    assert r.returncode == 0, r.stderr
    df = pd.read_parquet(tmp_path / "out").sort_values("point")
    assert list(df["point"]) == [0, 1, 2] and df["error"].isna().all()
    assert df["g_amp"].between(0.8, 2.4).all() and df["alpha"].between(0.2, 1.0).all()
    assert df["g_amp"].nunique() == 3
    for _, row in df.iterrows():
        res = plain(fmu_path, {"N": 400, "tau": 0.5, "g_amp": row["g_amp"], "alpha": row["alpha"]}, 3.0, 0.01)
        assert_stats_equal(row, res, 1.5)


def test_start_value_refused_before_anything_runs(tmp_path, fmu_path):
    """N = 0 in [start]: the FMU refuses it when set; exit 2 with the FMU's message, no cluster
    started, no folder made."""
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path).replace("N = 400", "N = 0"))
    r = run_sweep("run", spec, "--out", tmp_path / "out", "--workers", "1")
    assert r.returncode == 2, r.stderr
    assert "the FMU refuses the [start] values" in r.stderr
    assert "N = 0: the number of steps per tau must be >= 1" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "out").exists()


def test_help_texts():
    """run --help gives every exit status and says what --restart deletes; the TLS options."""
    import subprocess
    import sys
    from conftest import env_with_package
    r = subprocess.run([sys.executable, "-m", "dmi_sweep", "run", "--help"], capture_output=True,
                       text=True, env=env_with_package(), timeout=60)
    assert r.returncode == 0
    text = " ".join(r.stdout.split())
    for status in ("0 every point of the sweep succeeded", "1 every point was computed, but some failed",
                   "2 nothing was run", "3 the cluster was lost", "130 interrupted"):
        assert status in text, status
    assert "delete the folder's results, whatever spec they came from" in text
    assert "an unchanged spec resumes" in text
    for option in ("--tls-ca-file", "--tls-cert", "--tls-key", "--dashboard"):
        assert option in text
    assert ("3 the cluster was lost or could not be reached, or had no worker for --no-worker-timeout "
            "seconds") in text
    assert "when the cluster has had no worker for this long" in text and "(default: 60)" in text
    for bad in ("0", "-5", "nan", "inf", "soon"):
        r = subprocess.run([sys.executable, "-m", "dmi_sweep", "run", "spec.toml", "--out", "x",
                            "--no-worker-timeout", bad], capture_output=True, text=True,
                           env=env_with_package(), timeout=60)
        assert r.returncode == 2 and f"{bad!r} is not a number of seconds > 0" in r.stderr, r.stderr


def test_quiet_by_default(two_workers):
    """The fixture's run printed its progress and summary, nothing else (no Dask warning, no port
    message): checked on a fresh run's output."""
    d, _ = two_workers
    import shutil
    shutil.rmtree(d / "again", ignore_errors=True)
    r = run_sweep("run", d / "spec.toml", "--out", d / "again", "--workers", "2")
    lines = r.stderr.splitlines()
    assert lines and all(x.startswith("[") or x.startswith("dmi-sweep: 3 of 9 points failed")
                         for x in lines), r.stderr
    assert lines[-2].startswith("[##############################] 9/9 points")
    assert sum(1 for x in lines if " 9/9 points" in x) == 1            # the last line once


def test_two_clients_one_folder(tmp_path, fmu_path):
    """A second client on a folder in use is refused at once (exit 2) naming the first (host, pid,
    start time); after the first, a rerun with another chunk size computes nothing: every point
    once."""
    import socket
    import time
    from conftest import finish_group, start_sweep
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path).replace("num = 3", "num = 6")
                      .replace("[-0.5, 0.3, 1.0]", "[0.3, 1.0, 2.0]"))
    out = tmp_path / "out"
    first = start_sweep("run", spec, "--out", out, "--workers", "1", "--chunk-size", "7")
    try:
        deadline = time.monotonic() + 60
        while str(first.pid) not in ((out / "_lock").read_text() if (out / "_lock").exists() else ""):
            assert first.poll() is None and time.monotonic() < deadline, "the first client never locked"
            time.sleep(0.02)
        t = time.monotonic()
        second = run_sweep("run", spec, "--out", out, "--workers", "1", "--chunk-size", "10")
        assert first.poll() is None, "the first client ended before the second was refused"
        assert second.returncode == 2, second.stderr
        assert f"pid {first.pid} on {socket.gethostname()}, started 20" in second.stderr, second.stderr
        assert "in use by another dmi-sweep client" in second.stderr
        assert time.monotonic() - t < 30
    finally:
        r = finish_group(first)
    assert r.returncode == 0, r.stderr
    r = run_sweep("run", spec, "--out", out, "--workers", "1", "--chunk-size", "10")
    assert r.returncode == 0 and "18 already there, 0 computed" in r.stdout, r.stdout + r.stderr
    assert sorted(pd.read_parquet(out)["point"]) == list(range(18))


def test_sigkilled_client_leaves_the_folder_unlocked(tmp_path, fmu_path):
    """The lock dies with its holder: the client alone is SIGKILLed (its LocalCluster's workers
    still run), and the next client takes the folder and completes exactly the missing points."""
    import os
    import signal
    import time
    from conftest import finish_group, kill_group, start_sweep
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path).replace("num = 3", "num = 10")
                      .replace("[-0.5, 0.3, 1.0]", "[0.3, 1.0]").replace("N = 400", "N = 2000"))
    out = tmp_path / "out"
    first = start_sweep("run", spec, "--out", out, "--workers", "1", "--chunk-size", "1")
    try:
        deadline = time.monotonic() + 120
        while len(list(out.glob("part-*.parquet"))) < 2:
            assert first.poll() is None and time.monotonic() < deadline, "no progress"
            time.sleep(0.05)
        os.kill(first.pid, signal.SIGKILL)
        first.wait(timeout=10)
        done = set(pd.read_parquet(out)["point"])
        assert len(done) < 20
        r = run_sweep("run", spec, "--out", out, "--workers", "1", "--quiet")
    finally:
        kill_group(first.pid)          # the workers the killed client left
        finish_group(first)
    assert r.returncode == 0, r.stderr
    assert f"{len(done)} already there, {20 - len(done)} computed" in r.stdout, r.stdout
    assert sorted(pd.read_parquet(out)["point"]) == list(range(20))


def _small_folder(tmp_path, fmu_path):
    """A finished sweep of 4 points, one chunk file each, and its table."""
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path).replace("num = 3", "num = 2")
                      .replace("[-0.5, 0.3, 1.0]", "[0.3, 1.0]"))
    out = tmp_path / "out"
    r = run_sweep("run", spec, "--out", out, "--workers", "1", "--chunk-size", "1")
    assert r.returncode == 0, r.stderr
    return spec, out, pd.read_parquet(out).sort_values("point").reset_index(drop=True)


def _craft_overlaps(out, table):
    """Chunk files as two older clients (without the lock) would have left them: points 1-2 again,
    point 0 twice in one file, and a failed copy of point 3 in a file read before its good one."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    schema = pq.read_schema(out / "part-000000000.parquet")
    pq.write_table(pa.Table.from_pandas(table.iloc[[1, 2]], schema=schema, preserve_index=False),
                   out / "part-000000001-old.parquet")
    pq.write_table(pa.Table.from_pandas(table.iloc[[0, 0]], schema=schema, preserve_index=False),
                   out / "part-000000000-twice.parquet")
    bad = table.iloc[[3]].copy()
    bad["error"] = "KilledWorker: crafted"
    bad["w_final"] = float("nan")
    pq.write_table(pa.Table.from_pandas(bad, schema=schema, preserve_index=False),
                   out / "part-000000000-error.parquet")
    assert len(pd.read_parquet(out)) == 9


def test_overlapping_chunks_repaired(tmp_path, fmu_path):
    """The next run drops the 5 extra rows (saying so), keeps one row per point, the successful
    one of point 3, and computes nothing: the table equals the one before the crafting."""
    spec, out, table = _small_folder(tmp_path, fmu_path)
    _craft_overlaps(out, table)
    r = run_sweep("run", spec, "--out", out, "--workers", "1")
    assert r.returncode == 0, r.stderr
    assert "held 5 extra copies of points" in r.stderr, r.stderr
    assert "4 already there, 0 computed" in r.stdout
    after = pd.read_parquet(out).sort_values("point").reset_index(drop=True)
    pd.testing.assert_frame_equal(after, table, check_exact=True)
    assert [e["repair"] for e in log_entries(out) if "repair" in e] == [
        {"dropped": 5, "rewritten": 1, "removed": 4}]


def test_repair_interrupted_loses_no_point(tmp_path, fmu_path, monkeypatch):
    """A repair that fails at its first rewrite (disk full) leaves every point in the folder; the
    next repair completes it."""
    from dmi_sweep.spec import load
    from dmi_sweep.store import Store
    spec, out, table = _small_folder(tmp_path, fmu_path)
    _craft_overlaps(out, table)
    store = Store.open(out, load(spec))
    real = store._write_atomic

    def full(name, write):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(store, "_write_atomic", full)
    with pytest.raises(OSError):
        store.repair()
    assert set(pd.read_parquet(out)["point"]) == {0, 1, 2, 3}
    monkeypatch.setattr(store, "_write_atomic", real)
    assert store.repair()[0] > 0
    store.close()
    after = pd.read_parquet(out).sort_values("point").reset_index(drop=True)
    pd.testing.assert_frame_equal(after, table, check_exact=True)


def test_plugin_removed_while_a_point_runs(fmu_path, tmp_path):
    """Runner.close() (the worker plugin's teardown, when the plugin is removed or the worker stops)
    while a point runs in another thread: the point ends with its values (the instance is not freed
    under it: that crashed the worker), the instance is freed right after, a later point is refused
    (an exception, so that the client runs its chunk again, not a failed row)."""
    import threading
    import time
    from dmi_sweep.simulate import Runner, unpack
    job = {"start_time": 0.0, "stop_time": 10.0, "output_interval": 0.01, "transient": 5.0,
           "start": {"N": 40000}, "outputs": OUTPUTS, "poincare": None}
    # (400000 steps, a few tenths of a second: long enough that the loop below sees the point
    # running on a loaded machine; with N = 4000 the point could end between two of its looks)
    runner = Runner(unpack(open(fmu_path, "rb").read(), str(tmp_path)))
    want = Runner(runner.unzipdir).run(job, {"g_amp": 1.5})
    out = {}
    t = threading.Thread(target=lambda: out.update(runner.run(job, {"g_amp": 1.5})))
    t.start()
    deadline = time.monotonic() + 30
    while not runner.lock.locked() or runner.fmu is None:
        assert time.monotonic() < deadline
        time.sleep(0.001)
    runner.close()
    assert runner.fmu is not None            # still in use
    t.join(timeout=60)
    assert out == want
    assert runner.fmu is None                # freed when the point ended
    from dmi_sweep.simulate import PluginClosed
    with pytest.raises(PluginClosed, match="plugin was removed"):   # not a row: run again elsewhere
        runner.run(job, {"g_amp": 1.0})
