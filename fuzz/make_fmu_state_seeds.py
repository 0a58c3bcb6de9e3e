#!/usr/bin/env python3
"""Writes the seed corpus of fuzz_fmu_state (fuzz/corpus/fmu_state/): states
serialized by the FMI 2.0 FMU in each phase, behind the fuzzer's flags byte
(bit 0: recompute the checksums; bits 1-2: the phase of the receiving
instance, see fuzz_fmu_state.c).  Run it again whenever the state format
changes (fmu/model.h MODEL_STATE_VERSION, src/bytes.h), then commit the corpus:

    .venv/bin/python fuzz/make_fmu_state_seeds.py build/fmu/DelayFrictionOscillator.fmu

The FMI 3.0 target shares this corpus (both FMUs write the same bytes).  The *_format2
seeds are states of format 2 (written by the FMU before format 3), kept by hand so that the
fuzzer also reaches the older format's restore path; this script does not write them.
SPDX-License-Identifier: GPL-3.0-or-later
"""
import argparse
import pathlib
import shutil
import tempfile

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

FIX, RECV_INIT, RECV_STEP = 1, 2, 4  # flags: fix checksums; receiver in init mode / stepping


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("fmu", help="the FMI 2.0 FMU (build/fmu/DelayFrictionOscillator.fmu)")
    ap.add_argument("--out", default=str(pathlib.Path(__file__).parent / "corpus" / "fmu_state"),
                    help="corpus folder (default: %(default)s)")
    args = ap.parse_args()
    md = read_model_description(args.fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(args.fmu, unzipdir=tempfile.mkdtemp())
    out = pathlib.Path(args.out)
    seeds = {}

    def fmu() -> FMU2Slave:
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="seed")
        s.instantiate()
        return s

    def started(N: int, start: float, stop: float) -> FMU2Slave:
        s = fmu()
        s.setupExperiment(startTime=start, stopTime=stop)
        s.enterInitializationMode()
        s.setInteger([vr["N"]], [N])
        return s

    def keep(name: str, s: FMU2Slave, flags: int) -> None:
        seeds[name] = bytes([flags]) + bytes(s.serializeFMUState(s.getFMUState()))

    s = fmu()
    keep("instantiated", s, FIX)
    s.freeInstance()
    s = started(10, 0.0, 1.0)
    keep("init_mode", s, FIX | RECV_INIT)
    s.freeInstance()
    s = started(3, 2.5, 3.5)
    s.exitInitializationMode()
    s.doStep(2.5, 1.0)
    keep("start_2.5_N3", s, FIX | RECV_INIT)
    s.freeInstance()
    s = started(10, 0.0, 1.0)
    s.exitInitializationMode()
    for k in range(4):
        s.doStep(0.01 * k, 0.01)
    keep("stepping_N10", s, FIX | RECV_STEP)
    keep("stepping_N10_nofix", s, RECV_STEP)
    s.doStep(0.04, 0.015)  # a communication point between the solver's grid points
    keep("stepping_between_grid", s, FIX)
    s.terminate()
    keep("terminated", s, FIX | RECV_STEP)
    s.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

    out.mkdir(parents=True, exist_ok=True)
    for name, data in seeds.items():
        (out / name).write_bytes(data)
        print(f"{out / name}: {len(data)} bytes")


if __name__ == "__main__":
    main()
