# Fixtures of the FMU tests: paths from CMake (environment), the unpacked FMU
# (FMI 2.0 and FMI 3.0: every test that takes fmu_path runs on both), FMU2Slave
# instances (or FMU3Slave instances behind an FMI 2.0-like face) with a logger
# that records the messages.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import sys

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE
from fmpy.fmi1 import calloc, free
from fmpy.fmi3 import FMU3Slave
from fmpy.logging import addLoggerProxy
from ctypes import byref

sys.path.insert(0, os.path.dirname(__file__))


def _env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"environment variable {name} is not set (run the tests through ctest)")
    return value


@pytest.fixture(scope="session", params=["2", "3"], ids=["fmi2", "fmi3"])
def fmi_version(request):
    return request.param


@pytest.fixture(scope="session")
def fmu_path(fmi_version):
    return _env("DMI_FMU" if fmi_version == "2" else "DMI_FMU3")


@pytest.fixture(scope="session")
def fmu_paths():
    """Both FMUs: {"2": FMI 2.0, "3": FMI 3.0}."""
    return {"2": _env("DMI_FMU"), "3": _env("DMI_FMU3")}


@pytest.fixture(scope="session")
def libdmi():
    return _env("DMI_LIBDMI")


@pytest.fixture(scope="session")
def source_dir():
    return _env("DMI_SOURCE_DIR")


@pytest.fixture(scope="session")
def md(fmu_path):
    return read_model_description(fmu_path)


@pytest.fixture(scope="session")
def unzipdir(fmu_path, tmp_path_factory):
    return extract(fmu_path, str(tmp_path_factory.mktemp("fmu")))


@pytest.fixture(scope="session")
def vr(md):
    return {v.name: v.valueReference for v in md.modelVariables}


class FMI3AsFMI2:
    """An FMU3Slave with the FMI 2.0 names the tests use: setupExperiment keeps
    the times for fmi3EnterInitializationMode, Real is Float64, Integer is
    Int32, FMUstate is FMUState."""

    def __init__(self, fmu):
        self.fmu3 = fmu
        self.times = (0.0, None)

    def setupExperiment(self, startTime=0.0, stopTime=None, **_):
        self.times = (startTime, stopTime)

    def enterInitializationMode(self):
        return self.fmu3.enterInitializationMode(startTime=self.times[0], stopTime=self.times[1])

    def exitInitializationMode(self):  # with its status (fmpy's returns None)
        return self.fmu3.fmi3ExitInitializationMode(self.fmu3.component)

    def reset(self):
        self.times = (0.0, None)
        return self.fmu3.reset()

    def doStep(self, t, h, noSetFMUStatePriorToCurrentPoint=True):
        return self.fmu3.doStep(t, h, noSetFMUStatePriorToCurrentPoint)

    def __getattr__(self, name):
        for fmi2, fmi3 in (("Real", "Float64"), ("Integer", "Int32"), ("FMUstate", "FMUState"),
                           ("deSerialize", "deserialize")):
            name = name.replace(fmi2, fmi3)
        return getattr(self.fmu3, name)


class Slave:
    """An FMU2Slave (FMI 2.0) or FMI3AsFMI2 (FMI 3.0) whose log messages land in
    self.log as (status, category, message); self.prefix is "fmi2" or "fmi3"."""

    def __init__(self, md, unzipdir, name="dfo", logging_on=False, memory_callbacks=True):
        self.log = []
        self.prefix = "fmi" + md.fmiVersion[0]
        if md.fmiVersion.startswith("3"):
            def log3(env, status, category, message):
                self.log.append((status, category.decode(), message.decode()))

            fmu = FMU3Slave(guid=md.guid, unzipDirectory=unzipdir,
                            modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
            fmu.instantiate(loggingOn=logging_on, logMessage=log3)
            self.fmu = FMI3AsFMI2(fmu)
            return

        def logger(env, instance, status, category, message):
            self.log.append((status, category.decode(), message.decode()))

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        if memory_callbacks:  # else NULL, as canNotUseMemoryManagementFunctions allows
            self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(self.callbacks))
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=logging_on)

    def errors(self):
        return [m for s, c, m in self.log if s == 3]


@pytest.fixture
def slave(md, unzipdir):
    made = []

    def make(**kw):
        s = Slave(md, unzipdir, **kw)
        made.append(s)
        return s

    yield make
    for s in made:
        s.fmu.freeInstance()
