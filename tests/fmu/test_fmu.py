# The FMUs DelayFrictionOscillator.fmu (FMI 2.0) and fmi3/DelayFrictionOscillator.fmu
# (FMI 3.0) against the contract, driven by fmpy: validation, outputs
# against a native libdmi run and against each other, input, FMU states, reset,
# several instances, errors, logging, binary.  Tests taking fmu_path (or a
# fixture built on it) run on both FMUs.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import ctypes
import math
import os
import re
import struct
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from native import START, Run

OUT = ["w", "v", "friction", "delay_force", "sticking"]
EVENT_OUT = ["stick_slip_events", "last_event_time"]  # the events for an FMI 2.0 master
REALS = ["b", "alpha", "tau", "w0", "v0", "H_c0", "H_c1", "H_lambda", "H_a1", "H_omega1", "H_a2",
         "H_omega2", "H_a3", "H_omega3", "g_offset", "g_amp", "g_omega", "g_phase"]
T = 30.0


@pytest.fixture(scope="module")
def native43(libdmi):
    """Example 4.3 natively to T = 30 (plus a margin for the last interpolant)."""
    return Run(libdmi, 30001)


def outputs(s, vr):
    f = s.fmu
    real = f.getReal([vr[n] for n in OUT[:4]])
    return tuple(real) + (bool(f.getBoolean([vr["sticking"]])[0]),)


def start(s, t0=0.0, **params):
    f = s.fmu
    f.setupExperiment(startTime=t0)
    f.enterInitializationMode()
    for name, value in params.items():
        if name == "N":
            f.setInteger([s.vr["N"]], [value])
        else:
            f.setReal([s.vr[name]], [value])
    f.exitInitializationMode()


@pytest.fixture
def sl(slave, vr):
    def make(**kw):
        s = slave(**kw)
        s.vr = vr
        return s
    return make


def assert_close(got, want, tol=1e-12):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert got.shape == want.shape
    err = np.max(np.abs(got - want))
    assert err <= tol, f"max deviation {err:.3g} > {tol:g}"


# ---- the FMU as a file ----

def test_validate_fmu(fmu_path):
    assert validate_fmu(fmu_path) == []


def test_fmutool_check(fmu_path, fmi_version):
    if fmi_version == "3":
        pytest.skip("fmutool checks FMI 2.0 FMUs")
    fmutool = os.path.join(os.path.dirname(sys.executable), "fmutool")
    r = subprocess.run([fmutool, "-input", fmu_path, "-check"], capture_output=True, text=True,
                       env=dict(os.environ, QT_QPA_PLATFORM="offscreen"), timeout=120)
    text = r.stdout + r.stderr
    assert r.returncode == 0, text
    assert "compliant with FMI-2.0" in text, text
    assert "No semantic error" in text, text
    assert "ERROR" not in text, text


def test_model_description_contract(md, fmi_version):
    cs = md.coSimulation
    assert md.fmiVersion == fmi_version + ".0" and cs.modelIdentifier == "DelayFrictionOscillator"
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate
    var = {v.name: v for v in md.modelVariables}
    # the variables (written from config.h's table) are exactly the contract's, value references 0, 1, ...
    # FMI 3.0 asks for the independent variable, time
    assert sorted(var) == sorted(REALS + ["N", "g_in"] + OUT + EVENT_OUT +
                                 (["time"] if fmi_version == "3" else []))
    assert sorted(v.valueReference for v in md.modelVariables) == list(range(len(var)))
    for n in REALS + ["N"]:
        assert var[n].causality == "parameter", n
        assert float(var[n].start) == START[n], n
    real, integer = ("Real", "Integer") if fmi_version == "2" else ("Float64", "Int32")
    assert var["N"].type == integer
    assert var["g_in"].causality == "input" and var["g_in"].type == real
    assert all(var[n].type == real for n in REALS + OUT[:4])
    for n in OUT:
        assert var[n].causality == "output", n
    assert var["sticking"].type == "Boolean"
    # the events for an FMI 2.0 master: their count and the last one's time
    assert var["stick_slip_events"].type == integer and var["last_event_time"].type == real
    # Outputs at a communication point come from the steps before it: no direct feedthrough of g_in.
    assert sorted(o.variable.name for o in md.outputs) == sorted(OUT + EVENT_OUT)
    assert all(o.dependencies == [] for o in md.outputs)
    assert [c.name for c in md.logCategories] == ["logStatusError", "logStatusWarning", "logCalls",
                                                  "logMemory"]
    if fmi_version == "2":
        # libdmi allocates with the C library: the FMU must not be given allocateMemory to honour.
        assert md.coSimulation.canNotUseMemoryManagementFunctions is True
    else:
        # events: event mode, early return, intermediateUpdate at the events
        assert cs.hasEventMode is True and cs.canReturnEarlyAfterIntermediateUpdate is True
        assert cs.providesIntermediateUpdate is True and cs.mightReturnEarlyFromDoStep is True
        assert var["time"].causality == "independent"
    de = md.defaultExperiment
    assert float(de.stopTime) == 30.0
    k = float(de.stepSize) / (START["tau"] / START["N"])
    assert abs(k - round(k)) < 1e-9 and round(k) >= 1


def test_start_values_inside_binary(md, sl):
    """The binary's own start values equal the modelDescription's."""
    s = sl()
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    var = {v.name: v for v in md.modelVariables}
    got = s.fmu.getReal([s.vr[n] for n in REALS])
    assert got == [float(var[n].start) for n in REALS]
    assert s.fmu.getInteger([s.vr["N"]]) == [int(var["N"].start)]


def test_binary_needs_libc_libm_and_exports_fmi_only(unzipdir, fmi_version):
    folder = "linux64" if fmi_version == "2" else "x86_64-linux"
    so = os.path.join(unzipdir, "binaries", folder, "DelayFrictionOscillator.so")
    dyn = subprocess.run(["readelf", "-d", so], capture_output=True, text=True, check=True).stdout
    needed = {line.split("[")[1].split("]")[0] for line in dyn.splitlines() if "(NEEDED)" in line}
    assert needed and needed <= {"libc.so.6", "libm.so.6"}, needed
    syms = subprocess.run(["nm", "-D", "--defined-only", so], capture_output=True, text=True,
                          check=True).stdout.split("\n")
    names = [line.split()[-1] for line in syms if line.strip()]
    prefix = "fmi" + fmi_version
    assert prefix + "DoStep" in names
    assert prefix + ("Instantiate" if fmi_version == "2" else "InstantiateCoSimulation") in names
    assert [n for n in names if not n.startswith(prefix)] == []


# ---- outputs against a native libdmi run ----

@pytest.mark.parametrize("interval", [0.01, 0.0123])
def test_simulate_matches_native(fmu_path, native43, interval):
    r = simulate_fmu(fmu_path, stop_time=T, output_interval=interval, output=OUT)
    t = r["time"]
    assert t[0] == 0.0 and abs(t[-1] - T) < 1e-9 and len(t) == math.ceil(T / interval - 1e-9) + 1
    want = native43.table(t)
    got = np.column_stack([r[n] for n in OUT]).astype(float)
    assert_close(got[:, :4], want[:, :4])
    assert np.array_equal(got[:, 4], want[:, 4])
    # the run is not trivial: it slides and sticks
    assert got[:, 4].any() and not got[:, 4].all()


def test_varying_steps_match_native(sl, native43):
    """Uneven FMU2Slave steps; a zero step among them is a bad input:
    fmi2Error with a logged reason, and the instance goes on unchanged."""
    s = sl()
    start(s)
    h = START["tau"] / START["N"]
    pattern = [0.01, 0.0123, h, 0.3 * h, 0.7 * h, 5 * h, 0.0, 0.25, 1e-9, 0.1, 2.5 * h, 0.05]
    t, rows, times = 0.0, [], []
    i = zero_steps = 0
    while t < 12.0:
        dt = pattern[i % len(pattern)]
        i += 1
        if dt == 0.0:
            n = len(s.errors())
            with pytest.raises(FMICallException) as e:
                s.fmu.doStep(t, dt)
            assert e.value.status == 3
            assert len(s.errors()) == n + 1 and "step" in s.errors()[-1], s.errors()[-1:]
            zero_steps += 1
        else:
            s.fmu.doStep(t, dt)
            t += dt
        times.append(t)  # after a refused step: the outputs at t are still those of t
        rows.append(outputs(s, s.vr))
    assert zero_steps > 10
    got = np.array(rows, dtype=float)
    want = native43.table(times)
    assert_close(got[:, :4], want[:, :4])
    assert np.array_equal(got[:, 4], want[:, 4])


def test_g_in_from_an_input_signal(fmu_path, libdmi):
    sig_t = np.array([0.0, 1.0, 2.0, 3.0, 4.5, 6.0])
    sig_v = np.array([0.0, 0.8, -0.5, 1.5, -1.0, 0.2])
    signal = np.array(list(zip(sig_t, sig_v)), dtype=[("time", np.float64), ("g_in", np.float64)])
    r = simulate_fmu(fmu_path, stop_time=6.0, output_interval=0.01, input=signal, output=OUT)
    cps = r["time"]
    h = START["tau"] / START["N"]

    def g_in(p):  # the value set at the last communication point at or before t_p
        k = np.searchsorted(cps, p * h + 1e-6 * h, side="right") - 1
        return float(np.interp(cps[k], sig_t, sig_v))

    native = Run(libdmi, 6001, g_in=g_in)
    want = native.table(cps)
    got = np.column_stack([r[n] for n in OUT]).astype(float)
    assert_close(got[:, :4], want[:, :4])
    # and the input mattered
    plain = Run(libdmi, 6001).table(cps)
    assert np.max(np.abs(plain[:, 0] - got[:, 0])) > 1e-3


def test_parameters_and_start_time_match_native(sl, libdmi):
    params = dict(b=2.0, alpha=0.3, tau=0.5, N=400, w0=0.2, v0=-0.1, H_c0=0.5, H_c1=-1.0,
                  H_lambda=2.0, H_a1=0.3, H_omega1=3.0, H_a2=0.0, H_omega2=1.0, H_a3=-0.2,
                  H_omega3=7.0, g_offset=0.1, g_amp=0.9, g_omega=3.0, g_phase=0.4)
    t0 = 1.5
    s = sl()
    start(s, t0, **params)
    times, rows, t = [t0], [outputs(s, s.vr)], t0
    assert rows[0] == (0.2, -0.1, 0.0, 0.0, False)  # before any step: the history's end
    for k in range(1, 301):
        s.fmu.doStep(t, 0.0137)
        t = t0 + k * 0.0137
        times.append(t)
        rows.append(outputs(s, s.vr))
    native = Run(libdmi, int(300 * 0.0137 / (0.5 / 400)) + 2, t_start=t0, **params)
    assert_close(np.array(rows, dtype=float)[:, :4], native.table(times)[:, :4])


def test_g_in_set_between_uneven_steps(sl, libdmi):
    """Step p uses the g_in set at the last communication point at or before t_p."""
    s = sl()
    start(s)
    h = START["tau"] / START["N"]
    pattern = [0.0123, 3 * h, 0.4 * h, 0.05, 7.5 * h]
    cps, values, rows, t = [0.0], [], [], 0.0
    for k in range(400):
        g = math.sin(0.7 * k)
        s.fmu.setReal([s.vr["g_in"]], [g])
        values.append(g)
        dt = pattern[k % len(pattern)]
        s.fmu.doStep(t, dt)
        t += dt
        cps.append(t)
        rows.append(outputs(s, s.vr))
    cps = np.array(cps)

    def g_in(p):
        k = np.searchsorted(cps, p * h + 1e-6 * h, side="right") - 1
        return values[min(k, len(values) - 1)]  # (steps after the last point: not compared)

    native = Run(libdmi, int(t / h) + 2, g_in=g_in)
    assert_close(np.array(rows, dtype=float)[:, :4], native.table(cps[1:])[:, :4])


# ---- FMU states ----

def run_steps(s, t, n, dt=0.0123):
    rows = []
    for _ in range(n):
        s.fmu.doStep(t, dt)
        t += dt
        rows.append(outputs(s, s.vr))
    return t, rows


def test_state_get_set_replays_bitwise(sl):
    s = sl()
    start(s)
    t, _ = run_steps(s, 0.0, 200)
    state = s.fmu.getFMUstate()
    _, first = run_steps(s, t, 150)
    s.fmu.setFMUstate(state)
    _, again = run_steps(s, t, 150)
    assert first == again
    # serialized and deserialized in the same process
    data = s.fmu.serializeFMUstate(state)
    s.fmu.freeFMUstate(state)
    back = s.fmu.deSerializeFMUstate(data)
    s.fmu.setFMUstate(back)
    _, third = run_steps(s, t, 150)
    assert third == first
    s.fmu.freeFMUstate(back)


def test_state_before_initialization_restores_phase(sl):
    s = sl()
    s.fmu.setupExperiment(startTime=0.0)
    state = s.fmu.getFMUstate()  # instantiated, no history yet
    s.fmu.enterInitializationMode()
    s.fmu.exitInitializationMode()
    run_steps(s, 0.0, 10)
    s.fmu.setFMUstate(state)
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.123, 0.01)  # back in the instantiated state
    assert any("not allowed" in m for m in s.errors())
    s.fmu.enterInitializationMode()
    s.fmu.exitInitializationMode()
    s.fmu.freeFMUstate(state)


CHILD = textwrap.dedent("""
    import sys, json
    sys.path.insert(0, {here!r})
    import conftest, test_fmu
    from fmpy import read_model_description
    md = read_model_description({fmu!r})
    s = conftest.Slave(md, {unzip!r})
    s.vr = {{v.name: v.valueReference for v in md.modelVariables}}
    test_fmu.start(s)
    t, _ = test_fmu.run_steps(s, 0.0, 200)
    st = s.fmu.getFMUstate()
    open({path!r}, "wb").write(s.fmu.serializeFMUstate(st))
    _, rows = test_fmu.run_steps(s, t, 150)
    print(json.dumps([t, [[float(x) for x in r] for r in rows]]))
""")


def test_state_serialized_in_another_process(sl, fmu_path, unzipdir, tmp_path):
    path = str(tmp_path / "state.bin")
    code = CHILD.format(here=os.path.dirname(__file__), fmu=fmu_path, unzip=str(unzipdir), path=path)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    import json
    t, rows = json.loads(out.strip().splitlines()[-1])
    s = sl()
    start(s, N=7)  # another experiment; the state replaces it all
    st = s.fmu.deSerializeFMUstate(open(path, "rb").read())
    s.fmu.setFMUstate(st)
    _, mine = run_steps(s, t, 150)
    assert [[float(x) for x in r] for r in mine] == rows
    s.fmu.freeFMUstate(st)


def test_bad_state_bytes_are_rejected(sl):
    s = sl()
    start(s)
    t, _ = run_steps(s, 0.0, 50)
    st = s.fmu.getFMUstate()
    data = s.fmu.serializeFMUstate(st)
    s.fmu.freeFMUstate(st)
    t, _ = run_steps(s, t, 20)
    before = outputs(s, s.vr)
    bad = [b"", data[:10], data[:-1], data[: len(data) // 2], data + b"\0",
           b"X" + data[1:]]
    at_dmi = state_at_real(state_field(data, "nreal") + 2)
    for pos in (STATE_AT["VERSION"] + 1, STATE_AT["TAG"] + 1, STATE_AT["N"], STATE_AT["REAL"] + 12,
                at_dmi + 24, len(data) // 2, len(data) - 3):  # header, variables, history, checksum
        b = bytearray(data)
        b[pos] ^= 0x10
        bad.append(bytes(b))
    for k, b in enumerate(bad):
        n = len(s.errors())
        with pytest.raises(FMICallException):
            st = s.fmu.deSerializeFMUstate(b)
        assert len(s.errors()) == n + 1 and "state" in s.errors()[-1], (k, s.errors()[-1:])
    assert outputs(s, s.vr) == before
    # the instance goes on as if nothing happened
    ref = sl(name="ref")
    start(ref)
    tr, _ = run_steps(ref, 0.0, 70)
    assert outputs(ref, ref.vr) == before
    assert run_steps(s, t, 30)[1] == run_steps(ref, tr, 30)[1]


# The saved state's layout: the byte offsets MODEL_STATE_AT_* are read from
# fmu/model.h, the one place that states them (the FMU and the C tests compile
# them); the types are those its comments give: format version u32, phase tag
# u32, total size u64, number of Reals u64, size of libdmi's part u64, N i64,
# then the Reals, t_start, t_comm (doubles), libdmi's state bytes, and the
# FNV-1a 64 checksum of all bytes before it (src/bytes.h; fnv1a64 below is
# checked against the published test vectors).  The phase tags are the FMU's
# state bits: instantiated 1, initialization mode 2, step complete 4,
# terminated 8.
def _model_state_layout():
    path = os.path.join(os.path.dirname(__file__), "..", "..", "fmu", "model.h")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    at = {k: int(v) for k, v in re.findall(r"\bMODEL_STATE_AT_(\w+) = (\d+)", text)}
    magic = re.search(r'#define MODEL_STATE_MAGIC "(\w{8})"', text).group(1).encode()
    return at, magic


STATE_AT, STATE_MAGIC = _model_state_layout()
STATE_FIELD = dict(version="I", tag="I", total="Q", nreal="Q", ndmi="Q", N="q", hash="Q",
                   nevents="Q", event_p="Q", name="64s")
PHASE = dict(instantiated=1, init=2, step_complete=4, terminated=8)


def state_field(data, name):
    return struct.unpack_from("=" + STATE_FIELD[name], data, STATE_AT[name.upper()])[0]


def state_at_real(k):
    """Offset of Real k (k = nreal: t_start, nreal + 1: t_comm, nreal + 2: libdmi's part)."""
    return STATE_AT["REAL"] + 8 * k


def fnv1a64(data):
    x = 14695981039346656037
    for byte in data:
        x = ((x ^ byte) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return x


def test_state_layout_helpers():
    """fnv1a64 gives the FNV reference vectors, and every offset read from
    fmu/model.h has its type here (edit_state re-encoding the FMU's own states
    bitwise is checked in test_state_phase_and_history_must_agree)."""
    assert [fnv1a64(t) for t in (b"", b"a", b"foobar")] == [
        0xCBF29CE484222325, 0xAF63DC4C8601EC8C, 0x85944171F73967E8]
    assert sorted(STATE_AT) == sorted(["REAL"] + [k.upper() for k in STATE_FIELD])


def edit_state(data, tag=None, N=None, dmi=None, t_comm=None):
    """The state bytes with the phase tag, N, libdmi's part or the
    communication point replaced, the sizes and the checksum made consistent
    again."""
    assert data[:8] == STATE_MAGIC and state_field(data, "total") == len(data)
    nreal = state_field(data, "nreal")
    at_dmi = state_at_real(nreal + 2)
    part = data[at_dmi:len(data) - 8]
    assert len(part) == state_field(data, "ndmi")
    b = bytearray(data[:at_dmi]) + (part if dmi is None else dmi)
    edits = dict(tag=tag, N=N, ndmi=len(b) - at_dmi, total=len(b) + 8)
    for name, value in edits.items():
        if value is not None:
            struct.pack_into("=" + STATE_FIELD[name], b, STATE_AT[name.upper()], value)
    if t_comm is not None:
        struct.pack_into("=d", b, state_at_real(nreal + 1), t_comm)
    return bytes(b) + struct.pack("=Q", fnv1a64(b))


def saved_bytes(s):
    st = s.fmu.getFMUstate()
    data = s.fmu.serializeFMUstate(st)
    s.fmu.freeFMUstate(st)
    return data


def assert_refused(s, data, *words):
    """fmi2DeSerializeFMUstate refuses data with one logged error holding words."""
    n = len(s.errors())
    with pytest.raises(FMICallException) as e:
        s.fmu.deSerializeFMUstate(data)
    assert e.value.status == 3
    assert len(s.errors()) == n + 1, s.errors()[n:]
    assert all(w in s.errors()[-1] for w in words), s.errors()[-1]


def test_state_phase_and_history_must_agree(sl):
    """A phase with a solver (step complete, terminated) needs libdmi's history
    in the state; a phase before initialization must not have one."""
    s = sl()
    s.fmu.setupExperiment(startTime=0.0)
    before_init = saved_bytes(s)  # instantiated: no history
    s.fmu.enterInitializationMode()
    s.fmu.exitInitializationMode()
    t, _ = run_steps(s, 0.0, 20)
    stepping = saved_bytes(s)
    assert state_field(before_init, "tag") == PHASE["instantiated"]
    assert state_field(before_init, "ndmi") == 0
    assert state_field(stepping, "tag") == PHASE["step_complete"]
    assert state_field(stepping, "ndmi") > 0
    # the helper re-encodes a state bitwise, and what it writes is read back
    assert edit_state(before_init) == before_init and edit_state(stepping) == stepping
    s.fmu.freeFMUstate(s.fmu.deSerializeFMUstate(edit_state(stepping, tag=PHASE["terminated"])))
    s.fmu.freeFMUstate(s.fmu.deSerializeFMUstate(edit_state(before_init, tag=PHASE["init"])))
    now = outputs(s, s.vr)
    for data, phase in [(before_init, "step_complete"), (before_init, "terminated"),
                        (stepping, "instantiated"), (stepping, "init")]:
        assert_refused(s, edit_state(data, tag=PHASE[phase]), "state", "history")
    # the instance is unchanged and steps on
    assert outputs(s, s.vr) == now
    ref = sl(name="ref")
    start(ref)
    tr, _ = run_steps(ref, 0.0, 20)
    assert run_steps(s, t, 10)[1] == run_steps(ref, tr, 10)[1]


def test_state_history_size_must_match_N(sl):
    """libdmi's part of the state must be the history of exactly the saved N."""
    s = sl()
    start(s, N=100)
    t, _ = run_steps(s, 0.0, 30)
    data = saved_bytes(s)
    now = outputs(s, s.vr)
    for N in (99, 101, 50, 200, 2 ** 31 - 1):
        assert_refused(s, edit_state(data, N=N), "state", "history", f"N = {N}")
    part = data[state_at_real(state_field(data, "nreal") + 2):-8]
    for other in (part[:-16], part + bytes(16), part[:16]):  # libdmi's part of another size
        assert_refused(s, edit_state(data, dmi=other), "state", "history")
    assert outputs(s, s.vr) == now
    ref = sl(name="ref")
    start(ref, N=100)
    tr, _ = run_steps(ref, 0.0, 30)
    assert run_steps(s, t, 5)[1] == run_steps(ref, tr, 5)[1]


def test_state_time_must_agree_with_history(sl):
    """The communication point of a state is never beyond the step its
    history has reached (else the next doStep would take every step up to it),
    and it is the start time before initialization."""
    s = sl()
    s.fmu.setupExperiment(startTime=0.5)
    before_init = saved_bytes(s)
    s.fmu.enterInitializationMode()
    s.fmu.exitInitializationMode()
    t, _ = run_steps(s, 0.5, 10)  # t = 0.623: p = 123
    data = saved_bytes(s)
    now = outputs(s, s.vr)
    h = START["tau"] / START["N"]
    # the state's own time, and a time inside the last step, are accepted
    for ok in (t, 0.5 + 122.5 * h):
        s.fmu.freeFMUstate(s.fmu.deSerializeFMUstate(edit_state(data, t_comm=ok)))
    for far in (0.5 + 123.01 * h, 0.5 + 124 * h, 1e9, 1.5e10):
        assert_refused(s, edit_state(data, t_comm=far), "state", "communication point")
    assert_refused(s, edit_state(before_init, t_comm=0.6), "state", "times")
    assert outputs(s, s.vr) == now
    s.fmu.doStep(t, 0.01)


CHILD_HUGE_N = textwrap.dedent("""
    import sys, json, resource
    sys.path.insert(0, {here!r})
    import conftest, test_fmu
    from fmpy import read_model_description
    from fmpy.fmi1 import FMICallException
    md = read_model_description({fmu!r})
    s = conftest.Slave(md, {unzip!r})
    s.vr = {{v.name: v.valueReference for v in md.modelVariables}}
    test_fmu.start(s, N=100)
    test_fmu.run_steps(s, 0.0, 10)
    bad = test_fmu.edit_state(test_fmu.saved_bytes(s), N={N})
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    try:
        s.fmu.freeFMUstate(s.fmu.deSerializeFMUstate(bad))
        status = 0
    except FMICallException as e:
        status = e.status
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak
    print(json.dumps([status, grown, len(bad), s.errors()]))
""")


def test_state_claiming_a_huge_N_costs_no_memory(fmu_path, unzipdir):
    """A state of a few KB claiming N = 2^22 is refused before anything of the
    size of N is allocated (in a fresh process, so that its peak memory tells)."""
    code = CHILD_HUGE_N.format(here=os.path.dirname(__file__), fmu=fmu_path, unzip=str(unzipdir),
                               N=2 ** 22)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    import json
    status, grown_kib, size, errors = json.loads(out.strip().splitlines()[-1])
    assert size < 4096
    assert grown_kib < 16 * 1024, f"peak resident memory grew by {grown_kib} KiB"
    assert status == 3 and len(errors) == 1 and "N = 4194304" in errors[0], errors


def test_reset_allows_a_new_experiment(sl):
    s = sl()
    start(s, alpha=0.5, N=500)
    _, first = run_steps(s, 0.0, 100)
    s.fmu.reset()
    s.fmu.enterInitializationMode()
    assert s.fmu.getReal([s.vr["alpha"]]) == [START["alpha"]]
    assert s.fmu.getInteger([s.vr["N"]]) == [START["N"]]
    s.fmu.exitInitializationMode()
    _, default = run_steps(s, 0.0, 100)
    s.fmu.reset()
    start(s, alpha=0.5, N=500)
    _, again = run_steps(s, 0.0, 100)
    assert again == first and default != first
    fresh = sl(name="fresh")
    start(fresh)
    assert run_steps(fresh, 0.0, 100)[1] == default


def test_two_instances_are_independent(sl):
    a, b = sl(name="a"), sl(name="b")
    start(a)
    start(b, alpha=0.2, g_amp=2.0)
    ta = tb = 0.0
    ra, rb = [], []
    for _ in range(100):  # interleaved, different steps
        ta, x = run_steps(a, ta, 1, 0.0123)
        tb, y = run_steps(b, tb, 2, 0.005)
        ra += x
        rb += y
    a2, b2 = sl(name="a2"), sl(name="b2")
    start(a2)
    start(b2, alpha=0.2, g_amp=2.0)
    assert run_steps(a2, 0.0, 100, 0.0123)[1] == ra
    assert run_steps(b2, 0.0, 200, 0.005)[1] == rb


# ---- errors and logging ----

@pytest.mark.parametrize("name,value", [("tau", 0.0), ("tau", -1.0), ("alpha", -0.1), ("N", 0),
                                        ("N", -3)] + [(n, math.nan) for n in REALS]
                         + [("g_in", math.inf), ("tau", math.inf), ("b", -math.inf)])
def test_invalid_parameter_is_an_error(sl, name, value):
    s = sl()
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    with pytest.raises(FMICallException) as e:
        if name == "N":
            s.fmu.setInteger([s.vr[name]], [value])
        else:
            s.fmu.setReal([s.vr[name]], [value])
    assert e.value.status == 3
    assert len(s.errors()) == 1 and name in s.errors()[0]
    # unchanged, and the experiment still runs
    if name == "N":
        assert s.fmu.getInteger([s.vr["N"]]) == [START["N"]]
    else:
        assert s.fmu.getReal([s.vr[name]]) == [START.get(name, 0.0)]
    s.fmu.exitInitializationMode()
    s.fmu.doStep(0.0, 0.01)


def test_step_size_h_not_representable_is_an_error(sl):
    s = sl()
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    s.fmu.setReal([s.vr["tau"]], [1e-310])  # finite and > 0, but h = tau/N is subnormal
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    assert "solver" in s.errors()[-1]


def test_illegal_call_sequence(sl):
    s = sl()
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.0, 0.01)  # before initialization
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    start(s)
    s.fmu.doStep(0.0, 0.01)
    with pytest.raises(FMICallException):
        s.fmu.setReal([s.vr["alpha"]], [2.0])  # a parameter after initialization
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.5, 0.01)  # not the FMU's time
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.01, -0.01)
    with pytest.raises(FMICallException):
        s.fmu.setReal([s.vr["w"]], [1.0])  # an output
    assert len(s.errors()) == 6
    # a time equal to the FMU's up to a tiny fraction of h is accepted
    s.fmu.doStep(0.01 + 1e-12, 0.01)
    s.fmu.setReal([s.vr["g_in"]], [0.5])  # the input may be set between steps
    s.fmu.terminate()
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.02, 0.01)
    assert len(s.errors()) == 7 and "terminated" in s.errors()[-1]


def test_solver_failure_is_an_error_state(sl):
    s = sl()
    start(s)
    saved = s.fmu.getFMUstate()
    s.fmu.setReal([s.vr["g_in"]], [1e308])  # v overflows after about 1800 steps
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.0, 5.0)
    assert s.prefix + "DoStep" in s.errors()[-1] and "inf" in s.errors()[-1]
    with pytest.raises(FMICallException):
        s.fmu.doStep(5.0, 0.01)  # error state: no more steps
    assert "not allowed in state error" in s.errors()[-1]
    s.fmu.setFMUstate(saved)  # a state saved before brings it back
    s.fmu.setReal([s.vr["g_in"]], [0.0])
    _, rows = run_steps(s, 0.0, 20)
    ref = sl(name="ref")
    start(ref)
    assert run_steps(ref, 0.0, 20)[1] == rows
    s.fmu.freeFMUstate(saved)
    s.fmu.reset()
    start(s)
    s.fmu.doStep(0.0, 0.01)


def test_logging_honours_flags_and_categories(sl):
    quiet = sl(name="quiet", logging_on=False)
    start(quiet)
    quiet.fmu.doStep(0.0, 0.01)
    assert quiet.log == []
    loud = sl(name="loud", logging_on=True)
    start(loud)
    loud.fmu.doStep(0.0, 0.01)
    calls = [m for st, c, m in loud.log if c == "logCalls"]
    assert loud.prefix + "DoStep" in calls and loud.prefix + "ExitInitializationMode" in calls
    loud.fmu.setDebugLogging(True, ["logStatusError"])  # calls no longer traced
    n = len(loud.log)
    loud.fmu.doStep(0.01, 0.01)
    assert len(loud.log) == n
    with pytest.raises(FMICallException):
        loud.fmu.setDebugLogging(True, ["noSuchCategory"])
    assert "noSuchCategory" in loud.errors()[-1]
    loud.fmu.setDebugLogging(False, [])
    with pytest.raises(FMICallException):
        loud.fmu.doStep(5.0, 0.01)
    assert loud.log[-1][1] == "logStatusError"  # errors are reported all the same


def test_runs_without_memory_callbacks(sl, fmi_version):
    """allocateMemory = freeMemory = NULL (canNotUseMemoryManagementFunctions): a whole run, an FMU
    state and its serialization work as with the callbacks."""
    if fmi_version == "3":
        pytest.skip("FMI 3.0 has no memory callbacks")
    bare, full = sl(name="bare", memory_callbacks=False), sl(name="full")
    for s in (bare, full):
        start(s)
        s.fmu.doStep(0.0, 0.5)
    state = bare.fmu.getFMUstate()
    data = bare.fmu.serializeFMUstate(state)
    bare.fmu.doStep(0.5, 0.5)
    full.fmu.doStep(0.5, 0.5)
    assert outputs(bare, bare.vr) == outputs(full, full.vr)
    restored = bare.fmu.deSerializeFMUstate(data)
    bare.fmu.setFMUstate(restored)
    bare.fmu.doStep(0.5, 0.5)
    assert outputs(bare, bare.vr) == outputs(full, full.vr)
    bare.fmu.freeFMUstate(state)
    bare.fmu.freeFMUstate(restored)
    assert bare.errors() == []


def test_reset_restores_the_logging_of_instantiate(sl):
    """fmi2Reset puts the FMU into the state fmi2Instantiate left it in, logging settings included."""
    s = sl(name="quiet", logging_on=False)
    s.fmu.setDebugLogging(True, ["logCalls"])
    start(s)
    assert any(c == "logCalls" for st, c, m in s.log)
    s.fmu.reset()
    n = len(s.log)
    start(s)
    s.fmu.doStep(0.0, 0.01)
    assert s.log[n:] == []


def test_instantiate_rejects_wrong_guid(md, unzipdir):
    from types import SimpleNamespace
    from conftest import Slave
    wrong = SimpleNamespace(guid="{00000000-0000-0000-0000-000000000000}", coSimulation=md.coSimulation,
                            fmiVersion=md.fmiVersion)
    with pytest.raises(Exception, match="instantiate"):
        Slave(wrong, unzipdir)


# ---- the main-job script ----

def test_fmu_run_script_writes_the_csv(source_dir, fmu_paths, native43, tmp_path):
    fmu_path = fmu_paths["2"]  # the script's FMU (it reads "Integer" start values: FMI 2.0)
    out = tmp_path / "run.csv"
    subprocess.run([sys.executable, os.path.join(source_dir, "scripts", "fmu_run.py"), "--fmu",
                    fmu_path, "--out", str(out)], check=True, timeout=120)
    lines = out.read_text().splitlines()
    assert lines[0] == "t,w,v,friction,delay_force,sticking"
    rows = np.array([[float(x) for x in l.split(",")] for l in lines[1:]])
    assert rows[0, 0] == 0.0 and abs(rows[-1, 0] - T) < 1e-9
    assert_close(rows[:, 1:5], native43.table(rows[:, 0])[:, :4])


def test_fmu_run_script_start_values(source_dir, fmu_paths, libdmi, tmp_path):
    """--start NAME=VALUE (repeatable) sets start values: the run equals a
    native run with those parameters; an unknown name is refused."""
    fmu_path = fmu_paths["2"]
    script = os.path.join(source_dir, "scripts", "fmu_run.py")
    out = tmp_path / "run.csv"
    subprocess.run([sys.executable, script, "--fmu", fmu_path, "--out", str(out), "--stop-time",
                    "2", "--interval", "0.0123", "--start", "N=997", "--start", "alpha=0.5",
                    "--start", "g_amp=2"], check=True, timeout=120)
    rows = np.array([[float(x) for x in l.split(",")] for l in out.read_text().splitlines()[1:]])
    assert abs(rows[-1, 0] - 2.0) < 1e-9 and len(rows) == math.ceil(2 / 0.0123) + 1
    native = Run(libdmi, 2 * 997 + 2, N=997, alpha=0.5, g_amp=2.0)
    assert_close(rows[:, 1:5], native.table(rows[:, 0])[:, :4])
    assert np.array_equal(rows[:, 5], native.table(rows[:, 0])[:, 4])
    for bad in ("nosuch=1", "N=1.5", "alpha"):
        r = subprocess.run([sys.executable, script, "--fmu", fmu_path, "--out",
                            str(tmp_path / "bad.csv"), "--start", bad],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode != 0 and "--start" in r.stderr, (bad, r.stderr)
    r = subprocess.run([sys.executable, script, "--fmu", fmu_path, "--out", str(tmp_path / "bad.csv"),
                        "--start", "tau=-1"], capture_output=True, text=True, timeout=120)
    assert r.returncode != 0 and "the delay must be > 0" in r.stdout + r.stderr, r.stdout + r.stderr
    assert not (tmp_path / "bad.csv").exists()


def test_status_queries_and_unsupported_functions(sl, fmi_version):
    if fmi_version == "3":
        pytest.skip("FMI 2.0's status functions: see test_fmi3_do_step_flags_and_unsupported_functions")
    from fmpy.fmi2 import (fmi2LastSuccessfulTime, fmi2Terminated, fmi2DoStepStatus,
                           fmi2PendingStatus, fmi2Discard)
    s = sl()
    start(s)
    s.fmu.doStep(0.0, 0.0123)
    s.fmu.doStep(0.0123, 0.0123)
    assert s.fmu.getRealStatus(fmi2LastSuccessfulTime) == 0.0123 + 0.0123
    assert not s.fmu.getBooleanStatus(fmi2Terminated)
    # Status the FMU cannot give: fmi2Discard (FMI 2.0, 4.2.3), not an error.
    for call in (lambda: s.fmu.getStatus(fmi2DoStepStatus),
                 lambda: s.fmu.getRealStatus(fmi2DoStepStatus),
                 lambda: s.fmu.getIntegerStatus(fmi2DoStepStatus),
                 lambda: s.fmu.getBooleanStatus(fmi2DoStepStatus),
                 lambda: s.fmu.getStringStatus(fmi2PendingStatus)):
        n = len(s.errors())
        with pytest.raises(FMICallException) as e:
            call()
        assert e.value.status == fmi2Discard
        assert len(s.errors()) == n
    for call in (s.fmu.cancelStep,
                 lambda: s.fmu.setRealInputDerivatives([s.vr["g_in"]], [1], [0.0]),
                 lambda: s.fmu.getDirectionalDerivative([s.vr["w"]], [s.vr["g_in"]], [1.0])):
        n = len(s.errors())
        with pytest.raises(FMICallException):
            call()
        assert len(s.errors()) == n + 1
    s.fmu.doStep(0.0246, 0.01)  # still usable


# ---- FMI 3.0 beside FMI 2.0 ----

def slave_of(path, tmp_path, name):
    from fmpy import extract, read_model_description
    from conftest import Slave
    md = read_model_description(path)
    s = Slave(md, extract(path, str(tmp_path / name)), name=name)
    s.vr = {v.name: v.valueReference for v in md.modelVariables}
    return s


def test_fmi3_outputs_equal_fmi2_bitwise(fmu_paths):
    """The same settings (parameters, an input signal, an uneven output
    interval) give bitwise the same outputs in both FMUs (plain fmpy runs)."""
    sig = np.array([(0.0, 0.0), (1.0, 0.8), (2.0, -0.5), (3.0, 1.5)],
                   dtype=[("time", np.float64), ("g_in", np.float64)])
    kw = dict(stop_time=3.0, output_interval=0.0123, input=sig, output=OUT,
              start_values={"N": 997, "alpha": 0.5, "g_amp": 2.0, "tau": 0.8, "H_c1": 0.3,
                            "H_lambda": 2.0})
    r2 = simulate_fmu(fmu_paths["2"], **kw)
    r3 = simulate_fmu(fmu_paths["3"], **kw)
    assert len(r2) == len(r3) == math.ceil(3.0 / 0.0123) + 1
    for n in ["time"] + OUT:
        assert np.array_equal(r2[n], r3[n]), n
    assert np.ptp(r3["w"]) > 0.1 and r3["sticking"].any() and not r3["sticking"].all()


def test_state_bytes_cross_versions(fmu_paths, tmp_path):
    """Both FMUs write the same checked bytes: a state saved by one restores
    into the other, which then steps on bitwise like the first."""
    s2, s3 = slave_of(fmu_paths["2"], tmp_path, "two"), slave_of(fmu_paths["3"], tmp_path, "three")
    for a, b in ((s2, s3), (s3, s2)):
        start(a, N=500)
        start(b)
        t, _ = run_steps(a, 0.0, 40)
        data = saved_bytes(a)
        st = b.fmu.deSerializeFMUstate(data)
        b.fmu.setFMUstate(st)
        b.fmu.freeFMUstate(st)
        assert saved_bytes(b) == data
        assert run_steps(b, t, 30)[1] == run_steps(a, t, 30)[1]
        a.fmu.reset()
        b.fmu.reset()
    for s in (s2, s3):
        s.fmu.freeInstance()


def test_fmi3_do_step_flags_and_unsupported_functions(fmu_paths, tmp_path):
    """fmi3DoStep reports no event, no termination, no early return and the
    time reached; the functions of event mode, clocks and derivatives refuse
    with fmi3Error and a logged reason; the instance steps on."""
    s = slave_of(fmu_paths["3"], tmp_path, "flags")
    start(s)
    f3 = s.fmu.fmu3
    assert f3.doStep(0.0, 0.0123) == (False, False, False, 0.0123)
    assert f3.doStep(0.0123, 0.5) == (False, False, False, 0.0123 + 0.5)
    assert f3.getFloat64([s.vr["time"]]) == [0.0123 + 0.5]
    for call in (f3.enterEventMode, f3.enterStepMode,
                 lambda: f3.getOutputDerivatives([s.vr["w"]], [1]),
                 lambda: f3.getDirectionalDerivative([s.vr["w"]], [s.vr["g_in"]], [1.0]),
                 lambda: f3.getFloat32([s.vr["w"]]), lambda: f3.setInt8([0], [1])):
        n = len(s.errors())
        with pytest.raises(FMICallException) as e:
            call()
        assert e.value.status == 3 and len(s.errors()) == n + 1, s.errors()[n:]
    # a Float64 array whose length is not the number of scalar variables
    with pytest.raises(FMICallException):
        f3.fmi3GetFloat64(f3.component, (ctypes.c_uint32 * 2)(19, 20), 2, (ctypes.c_double * 3)(), 3)
    assert "3 values for 2 value references" in s.errors()[-1]
    f3.doStep(0.5123, 0.01)
    s.fmu.freeInstance()


def test_time_is_a_variable_of_fmi3_only(sl, md, fmi_version):
    s = sl()
    start(s)
    s.fmu.doStep(0.0, 0.25)
    time_vr = len(md.modelVariables) - (1 if fmi_version == "3" else 0)  # the next free one for FMI 2.0
    if fmi_version == "3":
        assert s.fmu.getReal([time_vr]) == [0.25]
    else:
        with pytest.raises(FMICallException):
            s.fmu.getReal([time_vr])
        assert f"value reference {time_vr}" in s.errors()[-1]


def test_fmi3_refuses_intermediate_variables(fmu_paths, tmp_path):
    """Event mode is accepted (tests/fmu/events); intermediate variables are not."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave
    md = read_model_description(fmu_paths["3"])
    unzip = extract(fmu_paths["3"], str(tmp_path / "u"))
    log = []
    f = FMU3Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="DelayFrictionOscillator",
                  instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        f.instantiate(logMessage=lambda env, st, cat, msg: log.append((st, msg.decode())),
                      requiredIntermediateVariables=[19])
    assert len(log) == 1 and log[0][0] == 3 and "intermediate" in log[0][1], log


# ---- what a new user hit ----

def coarse(N, T, b=1.0, tau=1.0):
    """The criterion, computed here: (1 + h^2 b)^(T/h) > 2."""
    h = tau / N
    return (1 + h * h * b) ** (T / h) > 2


def test_coarse_step_warns_at_initialization(sl, fmu_path):
    """ExitInitializationMode returns Warning, with a logged reason, when the
    explicit part's growth (1 + h^2 b)^(T/h) exceeds 2; not for N = 1000."""
    assert coarse(43, 30.0) and not coarse(44, 30.0) and coarse(10, 30.0) and not coarse(10, 3.0)
    for N, stop, b in [(1000, None, 1.0), (1, None, 1.0), (43, None, 1.0), (44, None, 1.0),
                       (10, 30.0, 1.0), (10, 3.0, 1.0), (10, None, -1.0), (44, None, 1.1)]:
        s = sl()
        s.fmu.setupExperiment(startTime=0.0, **({} if stop is None else dict(stopTime=stop)))
        s.fmu.enterInitializationMode()
        s.fmu.setInteger([s.vr["N"]], [N])
        s.fmu.setReal([s.vr["b"]], [b])
        status = s.fmu.exitInitializationMode()
        warned = [m for st, c, m in s.log if st == 1 and c == "logStatusWarning"]
        want = b > 0 and coarse(N, 30.0 if stop is None else stop, b)
        assert status == (1 if want else 0), (N, stop, b, status, s.log)
        assert len(warned) == (1 if want else 0), (N, stop, b, s.log)
        if want:
            assert f"N = {N}" in warned[0] and "coarse" in warned[0] and "1 + h^2 b" in warned[0]
            # the growth as a factor, "\u00d754 over T = 40", computed here
            T = 30.0 if stop is None else stop
            h = 1.0 / N
            factor = re.search("\u00d7(\\S+) over T = ", warned[0])
            assert factor, warned[0]
            assert float(factor.group(1)) == pytest.approx((1 + h * h * b) ** (T / h), rel=5e-3)
        s.fmu.doStep(0.0, 0.5)  # and it runs on
    # what the warning is about: the coarse run explodes
    r = simulate_fmu(fmu_path, stop_time=30.0, output_interval=1.0, start_values={"N": 1},
                     output=["w"])
    assert np.max(np.abs(r["w"])) > 1e6


def test_friction_lies_in_minus_alpha_alpha(fmu_path, native43):
    """friction is an element of alpha sigma(v): in [-alpha, alpha] at every
    step, although (X - U)/h rounds beyond alpha at thousands of them."""
    unclamped = (native43.X[1:, 1] - native43.U[1:, 1]) / native43.h
    assert np.sum(np.abs(unclamped) > 1.0) > 100
    r = simulate_fmu(fmu_path, stop_time=T, output_interval=0.001, output=["friction"])
    assert np.max(np.abs(r["friction"])) <= 1.0
    assert np.sum(np.abs(r["friction"]) == 1.0) > 1000  # sliding: the bound itself
    r = simulate_fmu(fmu_path, stop_time=5.0, output_interval=0.001, output=["friction"],
                     start_values={"alpha": 0.3})
    assert np.max(np.abs(r["friction"])) <= 0.3 and np.max(np.abs(r["friction"])) == 0.3


def solver_bytes(N, nonzero_terms=3):
    """(allocated while initialising, kept after) in bytes, from libdmi's
    documented layout (src/delay.h: the history ring holds 2(N+1) states of
    n doubles, the series and its mirror; src/exp.h: a complex sum per
    exponential term and column; dmi_init allocates its ring while
    dmi_create's is still held; under the recursion, the default method for
    the default kernel's three cosine terms once |omega| h <= pi, it takes no
    kernel samples, include/dmi.h): n = 2."""
    n, d = 2, 8
    ring = 2 * (N + 1) * n * d
    return 2 * ring, ring + 2 * nonzero_terms * d


CHILD_OUT_OF_MEMORY = textwrap.dedent("""
    import sys, json, resource
    sys.path.insert(0, {here!r})
    import conftest
    from fmpy import read_model_description
    md = read_model_description({fmu!r})
    s = conftest.Slave(md, {unzip!r})
    s.vr = {{v.name: v.valueReference for v in md.modelVariables}}
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    s.fmu.setInteger([s.vr["N"]], [{N}])
    # at most 512 MB more address space than now: the solver's allocation fails, nothing big is touched
    size = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
    resource.setrlimit(resource.RLIMIT_AS, (size + (512 << 20), resource.RLIM_INFINITY))
    try:
        status = s.fmu.exitInitializationMode()
    except Exception as e:
        status = repr(e)
    print(json.dumps([status, s.log]))
""")


@pytest.mark.parametrize("N", [2_000_000_000, 30_000_000])
def test_out_of_memory_names_N_and_the_bytes(fmu_path, unzipdir, N):
    """In a child process whose address space is limited (RLIMIT_AS) to 512 MB
    beyond what it holds: the allocation fails on any machine.  N = 2e9: the
    history alone (64 GB) fails in dmi_create; N = 3e7 (0.96 GB kept) fails in
    dmi_init."""
    code = CHILD_OUT_OF_MEMORY.format(here=os.path.dirname(__file__), fmu=fmu_path,
                                      unzip=str(unzipdir), N=N)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    import json
    status, log = json.loads(out.strip().splitlines()[-1])
    assert "FMICallException" in str(status) or status == 3, (status, log)
    errors = [m for st, c, m in log if st == 3]
    assert len(errors) == 1, log
    msg = errors[0]
    peak, kept = solver_bytes(N)
    assert f"N = {N}" in msg and "out of memory" in msg, msg
    assert f"allocates {peak} bytes" in msg and f"keeps {kept} bytes" in msg, (msg, peak, kept)


CHILD_BIG_N = textwrap.dedent("""
    import sys, json, resource
    sys.path.insert(0, {here!r})
    import conftest, test_fmu
    from fmpy import read_model_description
    md = read_model_description({fmu!r})
    s = conftest.Slave(md, {unzip!r})
    s.vr = {{v.name: v.valueReference for v in md.modelVariables}}
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    test_fmu.start(s, N={N})
    s.fmu.doStep(0.0, 0.001)
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    print(json.dumps([grown * 1024, s.log]))
""")


def test_large_N_logs_what_initialization_allocates(fmu_path, unzipdir, sl):
    """Above 100 MB, ExitInitializationMode logs N and the bytes (category
    logMemory, although logging is off): the sizes of libdmi's layout
    (solver_bytes), and the bytes kept are the peak resident memory it takes to
    within 30 % (measured in a fresh process)."""
    N = 3_000_000
    code = CHILD_BIG_N.format(here=os.path.dirname(__file__), fmu=fmu_path, unzip=str(unzipdir), N=N)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=120).stdout
    import json
    grown, log = json.loads(out.strip().splitlines()[-1])
    notes = [m for st, c, m in log if c == "logMemory"]
    assert len(notes) == 1 and f"N = {N}" in notes[0], log
    peak, kept = solver_bytes(N)
    assert f"allocates {peak} bytes" in notes[0] and f"keeps {kept} bytes" in notes[0], notes
    # what the process takes: dmi_create's ring is allocated but not touched, so the resident
    # peak is that of the kept bytes (dmi_init's ring)
    assert peak > 100e6 and abs(grown - kept) < 0.3 * kept, (grown, kept)
    s = sl()
    start(s)  # N = 1000: nothing to say
    assert s.log == []


def test_each_call_logged_once_with_its_outcome(sl):
    s = sl(logging_on=True)
    start(s)
    p = s.prefix
    real = "Real" if p == "fmi2" else "Float64"
    n = len(s.log)
    with pytest.raises(FMICallException):
        s.fmu.setReal([s.vr["tau"]], [-1.0])  # in step mode, a parameter: refused
    assert [(st, m.split(":")[0]) for st, c, m in s.log[n:]] == [(3, f"{p}Set{real}")], s.log[n:]
    n = len(s.log)
    s.fmu.setReal([s.vr["g_in"]], [0.5])
    s.fmu.doStep(0.0, 0.01)
    assert s.log[n:] == [(0, "logCalls", f"{p}Set{real}"), (0, "logCalls", f"{p}DoStep")]
    n = len(s.log)
    with pytest.raises(FMICallException):
        s.fmu.doStep(0.5, 0.01)
    assert len(s.log[n:]) == 1 and s.log[n][0] == 3 and s.log[n][2].startswith(f"{p}DoStep: ")


# ---- state format 3 ----

def test_state_format3_names_the_model_and_keeps_the_events(sl):
    """A saved state is format 3: the model's name, and the event count and
    last event's step that the outputs give; restored, the run goes on with
    them bitwise.  A state whose name is another model's (checksum fixed) is
    refused, naming both."""
    s = sl()
    start(s)
    ev = [s.vr["stick_slip_events"]]
    for k in range(50):
        s.fmu.doStep(k * 0.1, 0.1)
    data = saved_bytes(s)
    count = s.fmu.getInteger(ev)[0]
    last = s.fmu.getReal([s.vr["last_event_time"]])[0]
    assert state_field(data, "version") == 3 and count > 10
    assert state_field(data, "name").rstrip(b"\0") == b"DelayFrictionOscillator"
    assert state_field(data, "nevents") == count
    assert abs(state_field(data, "event_p") * 1e-3 - last) <= 1e-12
    after = []
    for _ in range(2):
        for k in range(50, 80):
            s.fmu.doStep(k * 0.1, 0.1)
        after.append((s.fmu.getInteger(ev)[0], s.fmu.getReal([s.vr["last_event_time"]])[0],
                      outputs(s, s.vr)))
        st = s.fmu.deSerializeFMUstate(data)
        s.fmu.setFMUstate(st)
        s.fmu.freeFMUstate(st)
        assert s.fmu.getInteger(ev)[0] == count
    assert after[0] == after[1] and after[0][0] > count
    b = bytearray(data[:-8])
    struct.pack_into("=64s", b, STATE_AT["NAME"], b"OtherModel")
    assert_refused(s, bytes(b) + struct.pack("=Q", fnv1a64(b)), 'the state is of model "OtherModel"',
                   'this FMU is model "DelayFrictionOscillator"')


# ---- the bulk path of Float64 gets ----

def test_bulk_get_equals_value_by_value_and_refuses_the_same(sl, fmi_version):
    """A run of consecutive value references (the bulk path) gives bitwise
    the values of one-by-one gets, at a grid point and between two; a run
    that crosses a variable of another type, or (FMI 2.0) the time, is
    refused with the message of that value reference alone."""
    s = sl()
    start(s)
    vr = s.vr
    outs = [vr[n] for n in OUT[:4]]
    assert outs == list(range(outs[0], outs[0] + 4))  # the four Real outputs are a run
    runs = [outs, list(range(0, outs[-1] + 1)), [vr["stick_slip_events"] + 1]]
    for t, dt in ((0.0, 0.5), (0.5, 0.0123)):  # t_p, then between grid points
        s.fmu.doStep(t, dt)
        for run in runs[:2]:
            assert s.fmu.getReal(run) == [s.fmu.getReal([x])[0] for x in run]
    messages = []
    for bad in ([outs[-1], vr["N"]], [vr["last_event_time"], vr["last_event_time"] + 1]):
        one = []
        for call in (bad, [bad[-1]]):
            try:
                got = s.fmu.getReal(call)
            except FMICallException:
                one.append(s.errors()[-1])
            else:  # FMI 3.0: the time is a Float64 variable
                assert fmi_version == "3" and bad[-1] == vr["last_event_time"] + 1, call
                assert got[-1] == 0.5123
        messages.append(one)
    assert len(messages[0]) == 2 and messages[0][0] == messages[0][1]
    assert f"value reference {vr['N']} is not a Real variable" in messages[0][0]
    if fmi_version == "2":
        assert len(messages[1]) == 2 and messages[1][0] == messages[1][1]
