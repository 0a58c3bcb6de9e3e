# Fixtures of the FMU tests: paths from CMake (environment), the unpacked FMU,
# FMU2Slave instances with a logger that records the messages.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import sys

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE
from fmpy.fmi1 import calloc, free
from fmpy.logging import addLoggerProxy
from ctypes import byref

sys.path.insert(0, os.path.dirname(__file__))


def _env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"environment variable {name} is not set (run the tests through ctest)")
    return value


@pytest.fixture(scope="session")
def fmu_path():
    return _env("DMI_FMU")


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


class Slave:
    """An FMU2Slave whose log messages land in self.log as (status, category, message)."""

    def __init__(self, md, unzipdir, name="dfo", logging_on=False, memory_callbacks=True):
        self.log = []

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
