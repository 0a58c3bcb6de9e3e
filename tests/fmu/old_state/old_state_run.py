# The run of the old-state fixtures (make_old_state.py) and of their test
# (test_old_state.py): non-default parameters, the input g_in changed during
# the run, a state saved in step mode at t = 1.23, then 150 communication
# steps of 0.01 from the restored state with g_in = -0.4.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

OUT = ["w", "v", "friction", "delay_force", "sticking"]
PARAMS = dict(b=1.5, alpha=0.7, tau=1.0, w0=0.2, H_c1=0.5, H_lambda=2.0, g_amp=1.1)
N = 200


def open_fmu(path, version):
    md = read_model_description(path)
    unzipdir = extract(path)
    cls = FMU2Slave if version == "2" else FMU3Slave
    fmu = cls(guid=md.guid, unzipDirectory=unzipdir,
              modelIdentifier=md.coSimulation.modelIdentifier, instanceName="old")
    fmu.instantiate()
    return fmu, md


def vrs(md):
    return {v.name: v.valueReference for v in md.modelVariables}


def set_real(fmu, version, vr, x):
    (fmu.setReal if version == "2" else fmu.setFloat64)([vr], [x])


def save_state(fmu, md, version):
    vr = vrs(md)
    if version == "2":
        fmu.setupExperiment(startTime=0.0, stopTime=10.0)
        for k, x in PARAMS.items():
            fmu.setReal([vr[k]], [x])
        fmu.setInteger([vr["N"]], [N])
        fmu.enterInitializationMode()
    else:
        for k, x in PARAMS.items():
            fmu.setFloat64([vr[k]], [x])
        fmu.setInt32([vr["N"]], [N])
        fmu.enterInitializationMode(startTime=0.0, stopTime=10.0)
    fmu.exitInitializationMode()
    t = 0.0
    for k in range(123):
        set_real(fmu, version, vr["g_in"], 0.3 if k < 60 else -0.2)
        fmu.doStep(t, 0.01)
        t += 0.01
    state = fmu.getFMUState() if version == "3" else fmu.getFMUstate()
    data = (fmu.serializeFMUState(state) if version == "3" else fmu.serializeFMUstate(state))
    return bytes(data)


def run_from_state(fmu, md, version, data):
    vr = vrs(md)
    if version == "2":
        state = fmu.deSerializeFMUstate(data)
        fmu.setFMUstate(state)
    else:
        state = fmu.deserializeFMUState(data)
        fmu.setFMUState(state)
    t = fmu.getRealStatus(2) if version == "2" else 1.23  # fmi2LastSuccessfulTime
    rows = []
    set_real(fmu, version, vr["g_in"], -0.4)
    for _ in range(150):
        fmu.doStep(t, 0.01)
        t += 0.01
        reals = [vr[k] for k in OUT[:-1]]
        r = fmu.getReal(reals) if version == "2" else fmu.getFloat64(reals)
        b = fmu.getBoolean([vr["sticking"]])
        rows.append(list(r) + [1.0 if b[0] else 0.0])
    return rows


def fresh_run(fmu, md, version, steps=500):
    """The default experiment's first steps (Example 4.3, N = 1000) from a
    fresh instance: the outputs after every communication step of 0.01."""
    vr = vrs(md)
    if version == "2":
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    else:
        fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    rows, t = [], 0.0
    for _ in range(steps):
        fmu.doStep(t, 0.01)
        t += 0.01
        reals = [vr[k] for k in OUT[:-1]]
        r = fmu.getReal(reals) if version == "2" else fmu.getFloat64(reals)
        rows.append(list(r) + [1.0 if fmu.getBoolean([vr["sticking"]])[0] else 0.0])
    return rows
