# The sweep specification (TOML): parsing and checking against the FMU's model
# description, before anything runs.  The points of the sweep in their order.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import hashlib
import json
import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from fmpy import read_model_description

from . import slurm

TOP_KEYS = {"fmu", "stop_time", "output_interval", "transient", "start", "grid", "outputs",
            "poincare", "random", "slurm"}
DEFAULT_FMU = Path(__file__).resolve().parents[2] / "build" / "fmu" / "DelayFrictionOscillator.fmu"


class SpecError(ValueError):
    """A bad specification: the message says what and where (a ``ValueError``)."""


@dataclass
class Spec:
    """A checked sweep specification, as :func:`load` returns it.

    Attributes
    ----------
    path : Path
        The spec file.
    text : bytes
        Its bytes as read.
    fmu : Path
        The FMU (the spec's ``fmu``, relative to the spec file, or the default build's oscillator).
    sha256 : str
        The FMU's SHA-256, hex.
    model : fmpy.model_description.ModelDescription
        The FMU's model description.
    start_time, stop_time, output_interval, transient : float
        The simulated interval, the communication interval and the start of the recorded window
        (time units of the FMU).
    start : dict
        The fixed start values of ``[start]``, converted to the variables' types.
    params : list of str
        The swept parameters, in the order of the columns of `values`.
    values : numpy.ndarray
        (points, params): the points in full-factorial (``[grid]``) or sampling (``[random]``) order.
    outputs : list of str
        The recorded outputs.
    poincare : float, str or None
        The Poincare period: a number (time units), a parameter name whose value is the angular
        frequency (period 2 pi / value), or None for no section.
    mode : str
        ``"grid"`` or ``"random"``.
    types : dict
        Parameter name to ``"float"``, ``"int"`` or ``"bool"``.
    slurm : dict
        The ``[slurm]`` section (job settings, used with ``--slurm``).
    """
    path: Path
    text: bytes
    fmu: Path
    sha256: str
    model: Any
    start_time: float
    stop_time: float
    output_interval: float
    transient: float
    start: dict[str, Any]
    params: list[str]
    values: np.ndarray                   # (points, params), in full-factorial (or sampling) order
    outputs: list[str]
    poincare: float | str | None = None
    mode: str = "grid"
    types: dict[str, str] = field(default_factory=dict)   # parameter -> "float" | "int" | "bool"
    slurm: dict[str, Any] = field(default_factory=dict)   # the [slurm] section (used with --slurm)

    @property
    def n_points(self) -> int:
        return len(self.values)

    def point(self, i: int) -> dict[str, Any]:
        """The swept values of point `i`, converted to the variables' types.

        Parameters
        ----------
        i : int
            The point's index, 0 <= i < :attr:`n_points`.

        Returns
        -------
        dict
            Parameter name to value.

        Raises
        ------
        IndexError
            If `i` is out of range.
        """
        return {p: _convert(self.types[p], self.values[i, j]) for j, p in enumerate(self.params)}

    def job(self) -> dict[str, Any]:
        """What a worker needs besides the point's values.

        Returns
        -------
        dict
            ``start_time``, ``stop_time``, ``output_interval``, ``transient``, ``start``, ``outputs`` and
            ``poincare``.
        """
        return {"start_time": self.start_time, "stop_time": self.stop_time,
                "output_interval": self.output_interval, "transient": self.transient,
                "start": dict(self.start), "outputs": list(self.outputs), "poincare": self.poincare}

    def identity(self) -> dict[str, Any]:
        """What must not change between a sweep and its resumption.

        Returns
        -------
        dict
            ``spec``: the parsed spec without the FMU's path and the ``[slurm]`` job settings (where it
            runs), key-sorted; ``fmu_sha256``: the FMU's SHA-256.
        """
        data = tomllib.loads(self.text.decode())
        data.pop("fmu", None)
        data.pop("slurm", None)
        return {"spec": json.loads(json.dumps(data, sort_keys=True, default=str)),
                "fmu_sha256": self.sha256}


def _convert(kind: str, x: Any) -> Any:
    if kind == "int":
        return int(round(float(x)))
    if kind == "bool":
        return bool(x)
    return float(x)


def _number(where: str, x: Any) -> float:
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        raise SpecError(f"{where}: {x!r} is not a (finite) number")
    return float(x)


def _kind(variable) -> str:
    t = variable.type
    if t in ("Real", "Float64", "Float32"):
        return "float"
    if t == "Boolean":
        return "bool"
    if t in ("String", "Binary", "Clock"):
        return "other"
    return "int"


def _check_value(where: str, variable, x: Any) -> Any:
    kind = _kind(variable)
    if kind == "bool":
        if not isinstance(x, bool):
            raise SpecError(f"{where}: {x!r} is not a Boolean (true or false)")
        return x
    if kind == "other":
        raise SpecError(f"{where}: variables of type {variable.type} cannot be set by dmi-sweep")
    value = _number(where, x)
    if kind == "int":
        if value != round(value):
            raise SpecError(f"{where}: {x!r} is not an integer ({variable.name} is {variable.type})")
        return int(value)
    return value


def load(path: str | os.PathLike) -> Spec:
    """Reads and checks a spec file.

    Parameters
    ----------
    path : str or os.PathLike
        The TOML file.

    Returns
    -------
    Spec
        The checked specification (see :func:`check`).

    Raises
    ------
    SpecError
        If the file cannot be read, is not TOML, or anything in it is wrong (the message says what
        and where).
    """
    path = Path(path)
    try:
        text = path.read_bytes()
    except OSError as e:
        raise SpecError(f"cannot read the spec {path}: {e.strerror}") from None
    try:
        data = tomllib.loads(text.decode())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise SpecError(f"{path}: not valid TOML: {e}") from None
    return check(data, text, path)


def check(data: dict[str, Any], text: bytes, path: Path) -> Spec:
    """Checks parsed spec data against its FMU's model description.

    Parameters
    ----------
    data : dict
        The parsed TOML.
    text : bytes
        The file's bytes (kept in the Spec; its identity for resumption).
    path : Path
        The spec file (a relative ``fmu`` is taken relative to its folder).

    Returns
    -------
    Spec
        The checked specification with its points.

    Raises
    ------
    SpecError
        For an unknown key, a missing or unreadable FMU or one without co-simulation, a bad time
        interval, an unknown or unsettable variable, a value of the wrong type or range, an empty or
        duplicated output list, a parameter both fixed and swept, a bad ``[grid]``, ``[random]``,
        ``[poincare]`` or ``[slurm]`` section.
    """
    unknown = sorted(set(data) - TOP_KEYS)
    if unknown:
        raise SpecError(f"unknown entries {', '.join(unknown)}; valid: {', '.join(sorted(TOP_KEYS))}")

    # the FMU
    if "fmu" in data:
        if not isinstance(data["fmu"], str):
            raise SpecError(f"fmu: {data['fmu']!r} is not a path")
        fmu = Path(data["fmu"])
        if not fmu.is_absolute():
            fmu = path.resolve().parent / fmu
    else:
        fmu = Path(os.environ.get("DMI_FMU", DEFAULT_FMU))
    if not fmu.is_file():
        raise SpecError(f"fmu: {fmu} does not exist" + ("" if "fmu" in data else
                        " (the default: build the project first, or give fmu = \"...\")"))
    try:
        model = read_model_description(str(fmu))
    except Exception as e:
        raise SpecError(f"fmu: {fmu} is not an FMU fmpy can read: {e}") from None
    if model.coSimulation is None:
        raise SpecError(f"fmu: {fmu} has no co-simulation interface")
    sha256 = hashlib.sha256(fmu.read_bytes()).hexdigest()
    variables = {v.name: v for v in model.modelVariables}
    settable = {n: v for n, v in variables.items()
                if v.causality in ("parameter", "input", "structuralParameter")
                and v.variability != "constant" and not v.dimensions}
    outputs_all = [v.name for v in model.modelVariables if v.causality == "output"]

    def param(where: str, name: str):
        if name not in settable:
            what = "is not a parameter or input of the FMU" if name in variables else "is not a variable of the FMU"
            raise SpecError(f"{where}: {name!r} {what}; valid names: {', '.join(settable)}")
        return settable[name]

    # times
    de = model.defaultExperiment
    start_time = float(de.startTime) if de is not None and de.startTime is not None else 0.0
    if "stop_time" not in data:
        raise SpecError("stop_time is missing")
    stop_time = _number("stop_time", data["stop_time"])
    if stop_time <= start_time:
        raise SpecError(f"stop_time = {stop_time:g} is not after the FMU's start time {start_time:g}")
    if "output_interval" not in data:
        raise SpecError("output_interval is missing")
    interval = _number("output_interval", data["output_interval"])
    if interval <= 0:
        raise SpecError(f"output_interval = {interval:g} is not positive")
    transient = _number("transient", data.get("transient", start_time))
    if transient >= stop_time:
        raise SpecError(f"transient = {transient:g} is not before stop_time = {stop_time:g}")
    if transient < start_time:
        raise SpecError(f"transient = {transient:g} is before the start time {start_time:g}")

    # start values
    start_tab = data.get("start", {})
    if not isinstance(start_tab, dict):
        raise SpecError("start must be a table: [start] NAME = value")
    start = {n: _check_value(f"start.{n}", param(f"start.{n}", n), x) for n, x in start_tab.items()}

    # outputs
    outputs = data.get("outputs", outputs_all)
    if not isinstance(outputs, list) or not outputs:
        raise SpecError(f"outputs must be a non-empty list of names; valid: {', '.join(outputs_all)}")
    for name in outputs:
        if name not in outputs_all:
            raise SpecError(f"outputs: {name!r} is not an output of the FMU; valid: {', '.join(outputs_all)}")
        if variables[name].dimensions or _kind(variables[name]) == "other":
            raise SpecError(f"outputs: {name!r} is not a scalar number or Boolean")
    if len(set(outputs)) != len(outputs):
        raise SpecError("outputs: a name appears twice")

    # the points
    grid = data.get("grid", {})
    rand = data.get("random")
    if not isinstance(grid, dict):
        raise SpecError("grid must be a table: [grid] NAME = [values] or { start, stop, num }")
    if rand is not None:
        params, values, types = _random(rand, grid, param)
        mode = "random"
    else:
        params, columns, types = [], [], {}
        for name, entry in grid.items():
            v = param(f"grid.{name}", name)
            params.append(name)
            types[name] = _kind(v)
            columns.append(_grid_values(f"grid.{name}", v, entry))
        if not params:
            raise SpecError("grid: no parameter to sweep (give [grid] or [random])")
        mesh = np.meshgrid(*columns, indexing="ij")       # last parameter fastest
        values = np.stack([m.ravel() for m in mesh], axis=1)
        mode = "grid"
    for name in params:
        if name in start:
            raise SpecError(f"{name} is both in [start] and swept")

    # Poincare section
    poincare = None
    if "poincare" in data:
        tab = data["poincare"]
        if not isinstance(tab, dict) or set(tab) != {"period"}:
            raise SpecError("poincare must be a table with one entry: [poincare] period = 0.785 or \"g_omega\"")
        period = tab["period"]
        if isinstance(period, str):
            v = param("poincare.period", period)
            if _kind(v) not in ("float", "int"):
                raise SpecError(f"poincare.period: {period!r} is not a number variable")
            if period not in params and period not in start and v.start is None:
                raise SpecError(f"poincare.period: {period!r} has no value (give it in [start])")
            poincare = period
        else:
            poincare = _number("poincare.period", period)
            if poincare <= 0:
                raise SpecError(f"poincare.period = {poincare:g} is not positive")
        if not model.coSimulation.canHandleVariableCommunicationStepSize:
            raise SpecError("poincare: the FMU cannot handle variable communication step sizes, "
                            "so it cannot be sampled at the section's times")

    # SLURM job settings (dmi-sweep run --slurm)
    section = data.get("slurm", {})
    if not isinstance(section, dict):
        raise SpecError("slurm must be a table: [slurm] partition = \"compute\", cores = 32, ...")
    try:
        slurm_settings = slurm.check(section, "slurm.")
    except slurm.SlurmSettingError as e:
        raise SpecError(str(e)) from None

    return Spec(path=path, text=text, fmu=fmu, sha256=sha256, model=model, start_time=start_time,
                stop_time=stop_time, output_interval=interval, transient=transient, start=start,
                params=params, values=values, outputs=list(outputs), poincare=poincare, mode=mode,
                types=types, slurm=slurm_settings)


def _grid_values(where: str, variable, entry: Any) -> np.ndarray:
    if isinstance(entry, list):
        if not entry:
            raise SpecError(f"{where}: the list of values is empty")
        vals = [_check_value(f"{where}[{i}]", variable, x) for i, x in enumerate(entry)]
    elif isinstance(entry, dict):
        if set(entry) != {"start", "stop", "num"}:
            raise SpecError(f"{where}: expected {{ start, stop, num }}, got {{ {', '.join(entry)} }}")
        a = _number(f"{where}.start", entry["start"])
        b = _number(f"{where}.stop", entry["stop"])
        num = entry["num"]
        if isinstance(num, bool) or not isinstance(num, int):
            raise SpecError(f"{where}.num: {num!r} is not an integer")
        if num < 1:
            raise SpecError(f"{where}.num = {num} is less than 1")
        vals = [_check_value(where, variable, float(x)) for x in np.linspace(a, b, num)]
    else:
        raise SpecError(f"{where}: {entry!r} is neither a list of values nor {{ start, stop, num }}")
    return np.asarray(vals, dtype=float)


def _random(rand: Any, grid: dict, param) -> tuple[list[str], np.ndarray, dict[str, str]]:
    """A Latin hypercube: n points, ranges { low, high } in [random] or [grid]."""
    if not isinstance(rand, dict):
        raise SpecError("random must be a table: [random] n = 1000, seed = 1, NAME = { low, high }")
    n = rand.get("n")
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise SpecError(f"random.n = {n!r} is not an integer >= 1")
    seed = rand.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise SpecError(f"random.seed = {seed!r} is not an integer >= 0")
    ranges = {k: v for k, v in rand.items() if k not in ("n", "seed")}
    for k, v in grid.items():
        if k in ranges:
            raise SpecError(f"{k} has a range both in [random] and [grid]")
        ranges[k] = v
    if not ranges:
        raise SpecError("random: no parameter range { low, high } given")
    params, lows, highs, types = [], [], [], {}
    for name, r in ranges.items():
        v = param(f"random.{name}", name)
        if not isinstance(r, dict) or set(r) != {"low", "high"}:
            raise SpecError(f"random.{name}: expected {{ low, high }}, got {r!r}")
        lo, hi = _number(f"{name}.low", r["low"]), _number(f"{name}.high", r["high"])
        if hi < lo:
            raise SpecError(f"random.{name}: high = {hi:g} is below low = {lo:g}")
        kind = _kind(v)
        if kind not in ("float", "int"):
            raise SpecError(f"random.{name}: a range needs a number variable")
        params.append(name)
        lows.append(lo)
        highs.append(hi)
        types[name] = kind
    rng = np.random.default_rng(seed)
    d = len(params)
    u = (np.stack([rng.permutation(n) for _ in range(d)], axis=1) + rng.random((n, d))) / n
    values = np.asarray(lows) + u * (np.asarray(highs) - np.asarray(lows))
    for j, name in enumerate(params):
        if types[name] == "int":
            values[:, j] = np.round(values[:, j])
    return params, values, types
