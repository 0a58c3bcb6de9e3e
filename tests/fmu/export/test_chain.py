# examples/fmu-chain built from an installed dmi as a user would: both FMUs
# valid (fmpy, fmutool), FMI 2.0 and 3.0 bitwise equal, within 1e-12 of the
# plain libdmi program of the same model (native.c, the independent
# computation: no FMU code), FMU states replaying bitwise, bad parameters
# refused with a logged message naming the value; the Windows DLLs (mingw-w64)
# export the FMI functions only and import only system DLLs.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math
import os
import re
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from conftest import Instance, build, fmus

OUT = ["x1", "x2", "x3", "v1", "v2", "v3", "friction1", "friction2", "friction3"]
NAME = "BurridgeKnopoffChain"


@pytest.fixture(scope="module")
def chain(prefix, source_dir, tmp_path_factory):
    b = tmp_path_factory.mktemp("chain")
    build(os.path.join(source_dir, "examples", "fmu-chain"), b, prefix)
    return {**fmus(b, NAME), "native": str(b / "chain_native")}


def run(inst, stop, dt, t_F=None, F=0.0, stop_time=None):
    """Communication steps of dt to stop; F_in = F set at the communication
    point t_F: the outputs after every step, with the times."""
    inst.start(stop_time)
    rows, t, k = [], 0.0, 0
    while k * dt < stop - 1e-9:
        if t_F is not None and abs(t - t_F) < 1e-9:
            inst.set("F_in", F)
        inst.fmu.doStep(t, dt)
        k += 1
        t = k * dt
        rows.append([t] + inst.get(OUT))
    return rows


@pytest.mark.parametrize("version", ["2", "3"])
def test_valid(chain, version):
    assert validate_fmu(chain[version]) == []
    fmutool = os.path.join(os.path.dirname(sys.executable), "fmutool")
    r = subprocess.run([fmutool, "-input", chain[version], "-check"], capture_output=True,
                       text=True, env=dict(os.environ, QT_QPA_PLATFORM="offscreen"), timeout=120)
    text = r.stdout + r.stderr
    assert r.returncode == 0, text
    assert f"compliant with FMI-{version}.0" in text and "No semantic error" in text, text
    assert "ERROR" not in text, text


def test_variables(chain):
    inst = Instance(chain["3"])
    md = inst.md
    assert md.modelName == NAME and md.defaultExperiment.stopTime == "100.0"
    params = dict(k_p=1, k_c=2, V=0.1, alpha1=1.0, alpha2=1.2, alpha3=0.9, g1=0.3, theta1=0.5,
                  g2=0.1, theta2=3.0, tau=10, N=1000, x0_1=0, x0_2=0, x0_3=0)
    got = {v.name: (v.causality, v.type, v.start) for v in md.modelVariables}
    for name, start in params.items():
        assert got[name][0] == "parameter" and float(got[name][2]) == start, name
    assert got["N"][1] == "Int32" and got["F_in"][:2] == ("input", "Float64")
    assert all(got[n][0] == "output" and got[n][2] is None for n in OUT)
    inst.free()


def test_fmi2_equals_fmi3_bitwise(chain):
    rows = {}
    for v in ("2", "3"):
        inst = Instance(chain[v])
        rows[v] = run(inst, 100.0, 0.1, t_F=30.0, F=0.8)
        inst.free()
    assert len(rows["2"]) == 1000 and rows["2"] == rows["3"]
    assert max(abs(r[1]) for r in rows["2"]) > 0.5  # the blocks moved (stick-slip)


def test_against_native(chain):
    """Communication points off the grid (0.025 = 2.5 h): the interpolant."""
    r = subprocess.run([chain["native"], "100", "0.025", "30", "0.8"], capture_output=True,
                       text=True, check=True)
    native = np.loadtxt(r.stdout.splitlines()[1:], delimiter=",")
    inst = Instance(chain["2"])
    fmu = np.array(run(inst, 100.0, 0.025, t_F=30.0, F=0.8))
    inst.free()
    assert fmu.shape == native.shape == (4000, 10)
    assert np.max(np.abs(fmu[:, 0] - native[:, 0])) < 1e-9
    assert np.max(np.abs(fmu[:, 1:] - native[:, 1:])) <= 1e-12
    assert np.ptp(native[:, 7]) > 0.5  # friction changed sign or size: stick and slip seen


@pytest.mark.parametrize("version", ["2", "3"])
def test_state_replay_bitwise(chain, version):
    inst = Instance(chain[version])
    inst.start()
    t = 0.0
    for k in range(200):
        inst.fmu.doStep(t, 0.1)
        t = (k + 1) * 0.1
    data = inst.save()

    def go(i):
        out = []
        for k in range(200, 300):
            i.fmu.doStep(k * 0.1, 0.1)
            out.append(i.get(OUT))
        return out

    first = go(inst)
    inst.restore(data)
    assert go(inst) == first
    other = Instance(chain[version], "other")  # a fresh instance from the bytes
    other.restore(data)
    assert go(other) == first
    inst.free()
    other.free()


BAD = [("tau", 0.0), ("tau", -1.0), ("N", 0), ("N", -5), ("alpha1", -0.5), ("alpha3", -1e-300),
       ("theta1", 0.0), ("theta2", -3.0), ("g1", math.nan), ("k_p", math.inf), ("V", -math.inf)]


@pytest.mark.parametrize("version", ["2", "3"])
@pytest.mark.parametrize("name,value", BAD)
def test_bad_parameter_refused(chain, version, name, value):
    inst = Instance(chain[version])
    with pytest.raises(FMICallException):
        inst.set(name, value)
    errors = [m for st, c, m in inst.log if c == "logStatusError"]
    assert len(errors) == 1, inst.log
    shown = "%g" % value if not isinstance(value, int) else str(value)
    assert f"{name} = " in errors[0], errors
    assert (shown in errors[0] or repr(value) in errors[0]
            or ("%.17g" % value) in errors[0]), errors
    # refused: the start value stays, the FMU runs
    assert float(inst.md.modelVariables[inst.vr[name]].start) != value
    inst.start()
    inst.fmu.doStep(0.0, 0.5)
    inst.free()


@pytest.mark.parametrize("version,platform", [("2", "win64"), ("3", "x86_64-windows")])
def test_windows_dll(chain, version, platform, tmp_path):
    objdump = shutil.which("x86_64-w64-mingw32-objdump")
    assert objdump, "mingw-w64's objdump not found (scripts/deps.sh installs it)"
    with zipfile.ZipFile(chain[version]) as z:
        z.extractall(tmp_path)
    dump = subprocess.run([objdump, "-p", str(tmp_path / "binaries" / platform / f"{NAME}.dll")],
                          capture_output=True, text=True, check=True).stdout
    imports = set(re.findall(r"DLL Name: (\S+)", dump))
    assert imports and all(re.match(r"(kernel32|msvcrt|api-ms-win-crt-[a-z0-9-]+)\.dll", d, re.I)
                           for d in imports), imports
    exports = re.findall(r"^\s+\[\s*\d+\] (\S+)$", dump.split("[Ordinal/Name Pointer] Table")[1],
                         re.M)
    assert f"fmi{version}DoStep" in exports and all(e.startswith(f"fmi{version}") for e in exports)


def test_state_of_another_model_refused(chain):
    """The chain's state bytes given to the oscillator FMU (and back): refused
    by the state's identity (format 3), the logged reason naming
    both models.  (One instance at a time: fmpy's FMI 2.0 logger proxy is
    shared.)"""
    paths = {"chain": chain["2"],
             "osc": os.path.join(os.environ["DMI_BUILD_DIR"], "fmu", "DelayFrictionOscillator.fmu")}
    states = {}
    for name, path in paths.items():
        inst = Instance(path, name)
        inst.start()
        states[name] = inst.save()
        inst.free()
    for name, other in (("chain", "osc"), ("osc", "chain")):
        inst = Instance(paths[name], name)
        inst.start()
        with pytest.raises(FMICallException):
            inst.restore(states[other])
        model = {"chain": "BurridgeKnopoffChain", "osc": "DelayFrictionOscillator"}
        msg = inst.log[-1][2]
        assert (f'the state is of model "{model[other]}"' in msg
                and f'this FMU is model "{model[name]}"' in msg), inst.log
        inst.restore(states[name])  # its own state still restores
        inst.free()
