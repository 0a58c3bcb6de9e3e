# The worker side of dmi-sweep: runs one point of a sweep on a co-simulation
# FMU (FMI 2.0 or 3.0) with the communication points of fmpy.simulate_fmu, and
# reduces the outputs to statistics and Poincare samples.  This module is
# shipped to the workers by value (cloudpickle), so it imports nothing from
# dmi_sweep: workers need fmpy, numpy and distributed, not this package.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import io
import math
import os
import shutil
import tempfile
import threading
from math import isclose
from typing import Any

import numpy as np
from distributed import WorkerPlugin, get_worker
from fmpy import extract, read_model_description
from fmpy.simulation import (apply_start_values, instantiate_fmu, settable_in_initialization_mode,
                             settable_in_instantiated)

STATUS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]


def communication_plan(start_time: float, stop_time: float, interval: float, variable_step: bool,
                       events: list[float]) -> list[tuple[float, bool, bool]]:
    """The communication points after `start_time`, in order: the loop of
    ``fmpy.simulate_fmu`` (co-simulation) with `events` playing the part of its input events.

    Parameters
    ----------
    start_time, stop_time : float
        The simulated interval (time units of the FMU).
    interval : float
        The output interval, > 0.
    variable_step : bool
        Whether the FMU takes variable communication steps (then the steps are cut at the events,
        and the last one ends at `stop_time`).
    events : list of float
        Sorted times at which a point is wanted (the Poincare samples).

    Returns
    -------
    list of (float, bool, bool)
        ``(time, recorded, event)`` per point; `recorded` is False only for an event point that is
        not one of simulate_fmu's own points (``start_time + k interval``, and `stop_time`).
    """
    plan = []
    time = start_time
    n_steps = 0
    events = [e for e in events if e > start_time and not isclose(e, start_time)]
    k = 0
    while not (time > stop_time or isclose(time, stop_time)):
        next_regular = start_time + (n_steps + 1) * interval
        nxt = next_regular
        cut = False
        while k < len(events) and (events[k] < time or isclose(events[k], time)):
            k += 1
        if k < len(events) and variable_step and nxt > events[k] and not isclose(nxt, events[k]):
            nxt = events[k]
            cut = True
        if nxt > stop_time and not isclose(nxt, stop_time):
            if not variable_step:
                break
            nxt = stop_time
            cut = False
        event = k < len(events) and isclose(nxt, events[k])
        plan.append((nxt, not cut, event))
        time = nxt
        if isclose(time, next_regular):
            n_steps += 1
    return plan


def in_window(time: float, transient: float) -> bool:
    """Whether a communication point belongs to the statistics window [`transient`, stop_time].

    Parameters
    ----------
    time : float
        The point's time.
    transient : float
        The window's start.

    Returns
    -------
    bool
        ``time >= transient``, equal within rounding included.
    """
    return time >= transient or isclose(time, transient)


class Runner:
    """One instance of an unpacked co-simulation FMU, instantiated on first use and reset between
    points.

    Parameters
    ----------
    unzipdir : str
        The folder of the unpacked FMU (:func:`unpack`).
    """

    def __init__(self, unzipdir: str):
        self.unzipdir = unzipdir
        self.md = read_model_description(unzipdir)
        self.fmi3 = self.md.fmiVersion.startswith("3")
        self.variable_step = bool(self.md.coSimulation.canHandleVariableCommunicationStepSize)
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.fmu: Any = None
        self.used = False
        self.messages: list[str] = []
        self.plans: dict[tuple, tuple] = {}  # key: (plan, in window, read) per point
        self.instantiations = 0
        self.lock = threading.Lock()         # held while a point runs
        self.closing = False                 # the plugin is being removed: free after this point

    def _logger2(self, env, instance, status, category, message):
        self._log(status, message)

    def _logger3(self, env, status, category, message):
        self._log(status, message)

    def _log(self, status, message):
        if status >= 1:  # warnings and worse explain a failing point
            text = message.decode(errors="replace") if isinstance(message, bytes) else str(message)
            self.messages.append(f"[{STATUS[status] if status < len(STATUS) else status}] {text}")

    def _fresh(self):
        logger = self._logger3 if self.fmi3 else self._logger2
        self.fmu = instantiate_fmu(self.unzipdir, self.md, fmi_type="CoSimulation", logger=logger)
        self.used = False
        self.instantiations += 1

    def discard(self) -> None:
        """Frees the instance (after a failure; the next point gets a new one). Never raises."""
        if self.fmu is not None:
            try:
                self.fmu.freeInstance()
            except Exception:
                pass
        self.fmu = None

    def _getters(self, names):
        groups: dict[str, tuple[list[str], list[int]]] = {}
        for name in names:
            v = self.variables[name]
            t = v.type
            if t == "Enumeration":
                t = "Int64" if self.fmi3 else "Integer"
            groups.setdefault(t, ([], []))
            groups[t][0].append(name)
            groups[t][1].append(v.valueReference)
        order = [n for ns, _ in groups.values() for n in ns]
        getters = [(getattr(self.fmu, "get" + t), vrs) for t, (_, vrs) in groups.items()]
        return order, getters

    def run(self, job: dict, values: dict) -> dict:
        """Simulates one point.

        Parameters
        ----------
        job : dict
            :meth:`dmi_sweep.spec.Spec.job`: the interval, start values, outputs and Poincare period.
        values : dict
            The point's swept values, over the job's start values.

        Returns
        -------
        dict
            Per output its statistics (``<name>_final``, ``_min``, ``_max``, ``_mean``, and with a
            Poincare period ``_poincare``, the samples), or ``{"error": message}`` if the FMU failed
            (with its logged messages).

        Raises
        ------
        PluginClosed
            If the runner was closed while the point waited (not a result: the client runs the chunk
            again elsewhere).
        """
        with self.lock:
            if self.closing:   # not a result: the client runs the chunk again elsewhere
                raise PluginClosed("the worker plugin was removed while the point waited")
            try:
                return self._run(job, values)
            finally:
                if self.closing:      # close() came while this point ran: free the instance now
                    self.discard()

    def _run(self, job: dict, values: dict) -> dict:
        self.messages.clear()
        try:
            if self.fmu is None:
                self._fresh()
            elif self.used:
                self.fmu.reset()
            self.used = True
            return self._simulate(job, values)
        except Exception as e:  # the FMU rejected something: record it, start afresh next time
            self.discard()
            reason = "; ".join(self.messages)
            return {"error": f"{type(e).__name__}: {e}" + (f" (FMU log: {reason})" if reason else "")}

    def _simulate(self, job, values):
        fmu = self.fmu
        t0, stop, interval = job["start_time"], job["stop_time"], job["output_interval"]
        transient = job["transient"]
        start = dict(job["start"])
        start.update(values)
        if self.fmi3:
            rest = apply_start_values(fmu, self.md, start, settable=settable_in_instantiated)
            fmu.enterInitializationMode(startTime=t0, stopTime=stop)
        else:
            fmu.setupExperiment(startTime=t0, stopTime=stop)
            rest = apply_start_values(fmu, self.md, start, settable=settable_in_instantiated)
            fmu.enterInitializationMode()
        rest = apply_start_values(fmu, self.md, rest, settable=settable_in_initialization_mode)
        fmu.exitInitializationMode()
        if rest:
            raise ValueError("could not set the start values of " + ", ".join(rest))

        period = job["poincare"]
        if isinstance(period, str):
            period = 2 * math.pi / float(self._value(period, start))
        if period is not None and not (period > 0 and math.isfinite(period)):
            raise ValueError(f"the Poincare period {period!r} is not a positive number")
        key = (t0, stop, interval, period, transient)
        cached = self.plans.get(key)
        if cached is None:
            events: list[float] = []    # the Poincare section's times
            if period is not None:
                # t = k period for the integers k with t in [transient, stop]: the same phase of a
                # forcing of that period at every sample and for every period swept
                k = math.ceil(transient / period)
                if isclose((k - 1) * period, transient):
                    k -= 1
                while True:
                    t = k * period
                    if t > stop and not isclose(t, stop):
                        break
                    events.append(t)
                    k += 1
            plan = communication_plan(t0, stop, interval, self.variable_step, events)
            # per communication point: in the statistics window; read (in the window, or the last)
            window = [in_window(t, transient) for t, _, _ in plan]
            read = [recorded and (w or i == len(plan) - 1)
                    for i, ((_, recorded, _), w) in enumerate(zip(plan, window))]
            at_start = bool(events) and isclose(events[0], t0)   # a sample before the first step
            cached = plan, window, read, at_start
            if len(self.plans) > 64:
                self.plans.clear()
            self.plans[key] = cached
        plan, window, read, at_start = cached
        names, getters = self._getters(job["outputs"])

        def sample():
            row = []
            for get, vrs in getters:
                row.extend(get(vrs))
            return row

        rows = []
        poincare = []
        last = sample() if not plan else None
        if in_window(t0, transient):
            rows.append(sample())
        if at_start:
            poincare.append(sample())
        time = t0
        step = fmu.doStep
        for (t, _, event), w, r in zip(plan, window, read):
            step(time, t - time)
            time = t
            if r:
                last = sample()
                if w:
                    rows.append(last)
            if event:
                poincare.append(sample())
        fmu.terminate()

        data = np.asarray(rows, dtype=float).reshape(len(rows), len(names))
        result: dict[str, Any] = {"error": None}
        final = np.asarray(last, dtype=float)
        for j, name in enumerate(names):
            col = data[:, j]
            result[name + "_final"] = float(final[j])
            result[name + "_min"] = float(col.min()) if len(col) else math.nan
            result[name + "_max"] = float(col.max()) if len(col) else math.nan
            result[name + "_mean"] = float(col.mean()) if len(col) else math.nan
            if period is not None:
                result[name + "_poincare"] = [float(r[j]) for r in poincare]
        return result

    def _value(self, name, start):
        if name in start:
            return start[name]
        v = self.variables[name]
        if v.start is None:
            raise ValueError(f"{name} has no value")
        return v.start

    def check_start(self, job: dict) -> str | None:
        """Whether the FMU takes the job's ``[start]`` values.

        Instantiates the FMU, sets the values (in the modes fmpy sets them) and leaves initialization
        mode (where a model may check its parameters together), the swept parameters at their start
        values, without stepping.

        Parameters
        ----------
        job : dict
            :meth:`dmi_sweep.spec.Spec.job`.

        Returns
        -------
        str or None
            None if the FMU takes them, else its reason with its logged messages.
        """
        self.messages.clear()
        try:
            self._fresh()
            fmu, t0, stop = self.fmu, job["start_time"], job["stop_time"]
            if self.fmi3:
                rest = apply_start_values(fmu, self.md, job["start"], settable=settable_in_instantiated)
                fmu.enterInitializationMode(startTime=t0, stopTime=stop)
            else:
                fmu.setupExperiment(startTime=t0, stopTime=stop)
                rest = apply_start_values(fmu, self.md, job["start"], settable=settable_in_instantiated)
                fmu.enterInitializationMode()
            rest = apply_start_values(fmu, self.md, rest, settable=settable_in_initialization_mode)
            if rest:
                return "cannot set " + ", ".join(rest)
            fmu.exitInitializationMode()
            return None
        except Exception as e:
            reason = "; ".join(self.messages)
            return f"{type(e).__name__}: {e}" + (f" (FMU log: {reason})" if reason else "")
        finally:
            self.discard()

    def close(self) -> None:
        """Frees the instance now, or, if a point is running in another thread, when it ends."""
        self.closing = True
        if self.lock.acquire(blocking=False):
            try:
                self.discard()
            finally:
                self.lock.release()


def unpack(fmu_bytes: bytes, directory: str) -> str:
    """Extracts an FMU into a new folder.

    Parameters
    ----------
    fmu_bytes : bytes
        The FMU (zip) file's bytes.
    directory : str
        Where the new folder is made.

    Returns
    -------
    str
        The new folder (``fmpy.extract``, which refuses absolute and backslash paths).

    Raises
    ------
    Exception
        fmpy's and zipfile's errors for a file that is not an FMU or has unsafe paths.
    """
    return str(extract(io.BytesIO(fmu_bytes), tempfile.mkdtemp(prefix="dmi-sweep-fmu-", dir=directory)))


class PluginClosed(RuntimeError):
    """A chunk reached a worker whose FMU plugin is gone (removed, or the worker closing): no point of
    it was computed, and the client runs it again."""


class FMUPlugin(WorkerPlugin):
    """Carries the FMU's bytes to each worker once (Dask sends registered plugins to every worker,
    also to workers that join later), unpacks them there once, and keeps one Runner per thread."""

    idempotent = True

    def __init__(self, fmu_bytes: bytes, sha256: str, run_id: str = ""):
        """The plugin of an FMU.

        Parameters
        ----------
        fmu_bytes : bytes
            The FMU's bytes, sent to each worker once.
        sha256 : str
            Their SHA-256: the plugin's name is ``dmi-sweep-<sha256[:16]>``, a plugin a caller may
            register to keep the FMU on the workers across runs.
        run_id : str, optional
            With it, the name is that of one run (``-<run_id>`` appended), which removes it at its end.
        """
        self.fmu_bytes = fmu_bytes
        self.name = "dmi-sweep-" + sha256[:16] + (f"-{run_id}" if run_id else "")

    def setup(self, worker: Any = None) -> None:
        """Unpacks the FMU into the worker's local directory (Dask calls it on each worker).

        Parameters
        ----------
        worker : distributed.Worker, optional
            The worker (its ``local_directory``; else the system's temporary folder).
        """
        base = getattr(worker, "local_directory", None) or tempfile.gettempdir()
        self.unzipdir = unpack(self.fmu_bytes, base)
        self.local = threading.local()
        self.runners: list[Runner] = []
        self.lock = threading.Lock()

    def runner(self) -> Runner:
        """This thread's Runner, made on first use.

        Returns
        -------
        Runner
            The runner of the calling thread.
        """
        r = getattr(self.local, "runner", None)
        if r is None:
            r = Runner(self.unzipdir)
            self.local.runner = r
            with self.lock:
                self.runners.append(r)
        return r

    def teardown(self, worker: Any = None) -> None:
        """Closes every runner and removes the unpacked FMU (Dask calls it when the plugin is removed
        or the worker closes).

        Parameters
        ----------
        worker : distributed.Worker, optional
            The worker.
        """
        for r in self.runners:
            r.close()
        shutil.rmtree(self.unzipdir, ignore_errors=True)


def has_worker_plugin(dask_scheduler: Any, name: str) -> bool:
    """On the scheduler (``Client.run_on_scheduler``): whether a worker plugin is registered.

    Parameters
    ----------
    dask_scheduler : distributed.Scheduler
        The scheduler (passed by Dask).
    name : str
        The plugin's name.

    Returns
    -------
    bool
        Whether it is registered.
    """
    return name in dask_scheduler.worker_plugins


def check_start(fmu_bytes: bytes, job: dict) -> str | None:
    """:meth:`Runner.check_start` on the FMU unpacked into a temporary folder (removed after).

    Parameters
    ----------
    fmu_bytes : bytes
        The FMU's bytes.
    job : dict
        :meth:`dmi_sweep.spec.Spec.job`.

    Returns
    -------
    str or None
        None if the FMU takes the ``[start]`` values, else its reason.
    """
    with tempfile.TemporaryDirectory(prefix="dmi-sweep-check-") as d:
        runner = Runner(unpack(fmu_bytes, d))
        return runner.check_start(job)


def run_chunk(plugin_name: str, job: dict, points: list[tuple[int, dict]]) -> list[dict]:
    """A Dask task: simulates points with this worker's FMU instance.

    Parameters
    ----------
    plugin_name : str
        The name of the registered :class:`FMUPlugin`.
    job : dict
        :meth:`dmi_sweep.spec.Spec.job`.
    points : list of (int, dict)
        ``(index, {name: value})`` per point.

    Returns
    -------
    list of dict
        One :meth:`Runner.run` result per point, each with ``point`` (its index), ``pid`` (the
        worker's) and ``instantiations`` (how many times this worker has instantiated the FMU so far).

    Raises
    ------
    PluginClosed
        If the worker has no plugin of that name, or it was removed while the chunk waited.
    """
    plugin = get_worker().plugins.get(plugin_name)
    if plugin is None:
        raise PluginClosed(f"the worker has no plugin {plugin_name}")
    runner = plugin.runner()
    out = []
    for index, values in points:
        r = runner.run(job, values)
        r["point"] = index
        r["pid"] = os.getpid()
        r["instantiations"] = runner.instantiations
        out.append(r)
    return out
