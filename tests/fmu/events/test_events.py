# Events of the oscillator FMU: every stick-slip transition of
# Example 4.3 over t in [0, 30], as fmpy's simulate_fmu sees it with early
# return and with event mode, lies at the solver step where a native libdmi
# run (the Python binding dmi.Solver, the same kernel as sums of exponentials,
# stuck when |X_v| <= h alpha after step p, dmi.Solver.step_terms) changes
# state: the same step index, every transition.  With early return off the
# run is bitwise that of the FMUs built before events (plain_run.json).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import math
import os

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.simulation import instantiate_fmu

import dmi
from event_run import EVENT_RUNS, event_run
from plain_run import OUT, RUNS, digests, plain_run

HERE = os.path.dirname(os.path.abspath(__file__))
T, N, TAU, ALPHA = 30.0, 1000, 1.0, 1.0
H = TAU / N


def fmu_path(version):
    return os.environ["DMI_FMU" if version == "2" else "DMI_FMU3"]


@pytest.fixture(scope="module")
def native():
    """The steps p (1 .. T/h) at which the native run's friction sticks or
    slips: stuck(p) = |X_v^p| <= h alpha, stuck(0) = |v0| <= h alpha."""
    s = dmi.Solver(2, TAU, N)
    C = np.zeros((3, 2, 2))
    C[:, 1, 0] = 1.0  # H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s acting on w in the v equation
    s.set_kernel_exp(np.zeros(3), np.array([2 * math.pi, 10 * math.pi, 20 * math.pi]), C)
    s.set_rhs(lambda t, u: np.array([-u[1], 1.0 * u[0] + (0.0 + 1.3 * math.cos(8.0 * t + 0.0) + 0.0)]))
    s.set_history(lambda t: np.zeros(2))
    s.set_friction([0.0, ALPHA])
    s.init()
    stuck = [abs(s.state[1]) <= s.h * ALPHA]
    for _ in range(round(T / H)):
        s.step()
        stuck.append(abs(s.step_terms()[1][1]) <= s.h * ALPHA)
    s.close()
    events = [p for p in range(1, len(stuck)) if stuck[p] != stuck[p - 1]]
    assert len(events) > 100  # Example 4.3 sticks and slips all along
    return events


class Recorded:
    """An FMU3Slave whose doStep, enterEventMode and event counter are recorded."""

    def __init__(self, early_return, event_mode):
        path = fmu_path("3")
        self.md = read_model_description(path)
        self.unzipdir = extract(path)
        self.fmu = instantiate_fmu(self.unzipdir, self.md, "CoSimulation",
                                   early_return_allowed=early_return, event_mode_used=event_mode)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.steps, self.entered = [], []  # (t, dt, flags, count after), event mode times
        do_step, enter = self.fmu.doStep, self.fmu.enterEventMode

        def recorded_do_step(currentCommunicationPoint, communicationStepSize, **kw):
            r = do_step(currentCommunicationPoint=currentCommunicationPoint,
                        communicationStepSize=communicationStepSize, **kw)
            count = self.fmu.getInt32([self.vr["stick_slip_events"]])[0]
            self.steps.append((currentCommunicationPoint, communicationStepSize, r, count))
            return r

        def recorded_enter():
            self.entered.append(self.steps[-1][2][3] if self.steps[-1][2][2] else
                                self.steps[-1][0] + self.steps[-1][1])
            return enter()

        self.fmu.doStep, self.fmu.enterEventMode = recorded_do_step, recorded_enter

    def run(self, early_return, event_mode, **options):
        r = simulate_fmu(self.unzipdir, fmu_instance=self.fmu, model_description=self.md,
                         early_return_allowed=early_return, use_event_mode=event_mode,
                         stop_time=T, output=OUT + ["stick_slip_events", "last_event_time"],
                         **options)
        self.fmu.freeInstance()
        return r

    def event_times(self):
        """The FMU's time after each doStep that counted one transition more
        (one at most per step, checked), and whether that step returned early."""
        out, before = [], 0
        for t, dt, (handling, terminate, early, last), count in self.steps:
            assert not terminate and count - before in (0, 1), (t, count, before)
            if count > before:
                out.append((last if early else t + dt, early, handling))
            else:  # no transition: no early return, no event handling
                assert not early and not handling, (t, early, handling)
            before = count
        return out


def steps_of(times):
    """The step index p of each time t_p = p h, checked to be on the grid."""
    p = [round(t / H) for t in times]
    assert all(abs(t - q * H) <= 1e-9 * H * max(q, 1) for t, q in zip(times, p)), times
    return p


@pytest.mark.parametrize("event_mode", [False, True], ids=["early_return", "early_return+event_mode"])
def test_early_return_at_every_transition(native, event_mode):
    """Every transition reported at its native step: an early return there
    (lastSuccessfulTime = t_start + p h) unless the step ends a communication
    step; with event mode, eventHandlingNeeded and fmi3EnterEventMode there."""
    rec = Recorded(True, event_mode)
    r = rec.run(True, event_mode, output_interval=0.1)
    got = rec.event_times()
    assert steps_of([t for t, _, _ in got]) == native
    regular = {round(k * 0.1 / H) for k in range(round(T / 0.1) + 1)}
    for (t, early, handling), p in zip(got, native):
        assert early == (p not in regular), (t, p)
        assert handling == event_mode
    assert sum(early for _, early, _ in got) > 100
    if event_mode:
        assert steps_of(rec.entered) == native
    # the last event's time and the count as outputs (what an FMI 2.0 master reads)
    assert r["stick_slip_events"][-1] == len(native)
    assert abs(r["last_event_time"][-1] - native[-1] * H) <= 1e-12


def test_event_mode_without_early_return(native):
    """eventModeUsed alone: the communication steps that contain a transition
    ask for event handling (at their end), the others not."""
    rec = Recorded(False, True)
    rec.run(False, True, output_interval=0.1)
    asked = [t + dt for t, dt, (handling, _, early, _), _ in rec.steps if handling]
    assert not any(early for _, _, (_, _, early, _), _ in rec.steps)
    want = sorted({math.ceil(p * H / 0.1 - 1e-6) for p in native})  # the step containing t_p
    assert steps_of(asked) == [round(k * 0.1 / H) for k in want]
    assert steps_of(rec.entered) == [round(k * 0.1 / H) for k in want]


@pytest.mark.parametrize("version", ["2", "3"])
def test_fmi2_master_reads_the_event_outputs(native, version):
    """Without early return (FMI 2.0, or 3.0 by default) the run is unchanged
    and the outputs give the count and the last transition's time."""
    r = simulate_fmu(fmu_path(version), stop_time=T, output_interval=0.1,
                     output=["stick_slip_events", "last_event_time"])
    t = r["time"]
    count = np.array([sum(1 for p in native if p * H <= x + 1e-9 * H) for x in t])
    assert np.array_equal(r["stick_slip_events"], count)
    last = np.array([max([p for p in native if p * H <= x + 1e-9 * H], default=0) * H for x in t])
    assert np.max(np.abs(r["last_event_time"] - last)) <= 1e-12


@pytest.mark.parametrize("run", sorted(RUNS))
@pytest.mark.parametrize("version", ["2", "3"])
def test_early_return_off_is_bitwise_as_before(version, run):
    """The plain runs (no early return, no event mode) give the digests of
    the FMUs built before events, bitwise."""
    with open(os.path.join(HERE, "plain_run.json")) as f:
        want = json.load(f)[f"{version} {run}"]
    r = plain_run(fmu_path(version), **RUNS[run])
    assert len(r) == want["rows"] and digests(r) == want["digests"]


@pytest.mark.parametrize("run", sorted(EVENT_RUNS))
def test_event_runs_bitwise_as_main(run):
    """Early return on and off, event mode, FMI 2.0 and 3.0, the event
    outputs too: the digests of the FMUs whose indicators read the state back
    after every step (event_run.json), bitwise."""
    with open(os.path.join(HERE, "event_run.json")) as f:
        want = json.load(f)[run]
    rows, got = event_run(fmu_path(run[0]), run)
    assert rows == want["rows"] and got == want["digests"]


def test_early_return_keeps_the_regular_points_bitwise():
    """With early return the outputs at the regular communication points are
    bitwise those of the plain run (the same solver steps, the same points)."""
    rec = Recorded(True, False)
    r = rec.run(True, False, output_interval=0.0492)  # between grid points: interpolated
    plain = plain_run(fmu_path("3"), output_interval=0.0492)
    grid = np.isin(r["time"], plain["time"])
    assert grid.sum() == len(plain)
    assert digests(r, grid) == digests(plain)


def test_c_master_couples_at_the_transitions(native):
    """tests/fmu/event_master.c: the oscillator (early return) drives the
    chain FMU with its friction force; the event times it prints are the
    native run's transition steps, all of them, most by early return, and
    the chain followed it to T."""
    import subprocess
    out = subprocess.run([os.environ["DMI_EVENT_MASTER"], os.environ["DMI_OSC3_SO"],
                          os.environ["DMI_FMU_GUID"], os.environ["DMI_CHAIN3_SO"],
                          os.environ["DMI_CHAIN_GUID"], str(T), "0.1"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.split("\n")
    events = [(float(x.split()[1]), x.split()[2] == "1") for x in lines if x.startswith("event ")]
    assert steps_of([t for t, _ in events]) == native
    regular = {round(k * 0.1 / H) for k in range(round(T / 0.1) + 1)}
    assert [early for _, early in events] == [p not in regular for p in native]
    chain = [x.split() for x in lines if x.startswith("chain ")]
    assert len(chain) == 1 and float(chain[0][4]) == T and math.isfinite(float(chain[0][2]))
    assert f"events {len(native)} early {sum(p not in regular for p in native)}" in out.stdout


def test_event_mode_calling_sequence(tmp_path):
    """eventModeUsed: event mode after initialization (doStep refused there,
    UpdateDiscreteStates answers no update, no time event), EnterStepMode;
    without eventModeUsed EnterEventMode is refused with a logged reason; a
    state saved in event mode restores into an FMI 2.0 instance in step mode."""
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi3 import FMU3Slave

    def slave(version, log, **kw):
        path = fmu_path(version)
        md = read_model_description(path)
        args = dict(guid=md.guid, unzipDirectory=extract(path, str(tmp_path / version)),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="ev")
        if version == "2":
            f = FMU2Slave(**args)
            f.instantiate()
            return f
        f = FMU3Slave(**args)
        f.instantiate(logMessage=lambda env, st, cat, msg: log.append((st, msg.decode())), **kw)
        return f

    log = []
    f = slave("3", log, eventModeUsed=True)
    f.enterInitializationMode(startTime=0.0)
    f.exitInitializationMode()
    with pytest.raises(FMICallException):
        f.doStep(0.0, 0.1)
    assert "not allowed in state event mode" in log[-1][1]
    assert list(f.updateDiscreteStates()) == [False, False, False, False, False, 0.0]
    state = f.serializeFMUState(f.getFMUState())
    f.enterStepMode()
    f.doStep(0.0, 0.1)
    f.terminate()
    f.freeInstance()
    log = []
    f = slave("3", log)
    f.enterInitializationMode(startTime=0.0)
    f.exitInitializationMode()
    with pytest.raises(FMICallException):
        f.enterEventMode()
    assert "eventModeUsed = false" in log[-1][1]
    f.freeInstance()
    f2 = slave("2", None)
    f2.setFMUstate(f2.deSerializeFMUstate(bytes(state)))
    f2.doStep(0.0, 0.1)  # step mode: allowed
    assert f2.getReal([0])[0] == 1.0  # b, from the state
    f2.terminate()
    f2.freeInstance()
