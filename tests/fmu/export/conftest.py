# The tests of FMU export (dmi_add_fmu) as a user does it: dmi is
# installed from this build into a temporary prefix (DMI_BUILD_DIR), and each
# project (examples/fmu-chain, the page docs/fmu-export.md, the bad models
# here) is configured and built from that prefix alone.  Helpers: an FMU
# instance of either FMI version with its log, a project build.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import subprocess
from ctypes import byref

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi3 import FMU3Slave
from fmpy.logging import addLoggerProxy


def env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set (run through ctest)")
    return value


@pytest.fixture(scope="session")
def source_dir():
    return env("DMI_SOURCE_DIR")


@pytest.fixture(scope="session")
def prefix(tmp_path_factory):
    """dmi installed from the build tree into a temporary prefix."""
    p = tmp_path_factory.mktemp("prefix")
    subprocess.run(["cmake", "--install", env("DMI_BUILD_DIR"), "--prefix", str(p)], check=True,
                   capture_output=True)
    return str(p)


def build(src, build_dir, prefix, check=True):
    """Configures and builds the CMake project src against prefix only: the
    completed process (stdout and stderr together)."""
    out = ""
    for cmd in (["cmake", "-S", str(src), "-B", str(build_dir), "-G", "Ninja",
                 f"-DCMAKE_PREFIX_PATH={prefix}"],
                ["cmake", "--build", str(build_dir), "-j2"]):
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        out += r.stdout + r.stderr
        if r.returncode != 0:
            break
    if check:
        assert r.returncode == 0, out
    return r.returncode, out


def write_project(src, name, source, file=None, guid=None):
    """The CMake project of one model in src (made if missing): dmi_add_fmu(name SOURCES file)
    from an installed dmi, file (default: the first name in lower case, .c) holding source.
    name may be a list: one dmi_add_fmu per name, all from the one file; guid: the GUID of
    dmi_add_fmu (one name only). Returns src."""
    names = [name] if isinstance(name, str) else list(name)
    assert guid is None or len(names) == 1, "one GUID for one FMU"
    file = file or f"{names[0].lower()}.c"
    src.mkdir(parents=True, exist_ok=True)
    calls = "".join(f"dmi_add_fmu({n} SOURCES {file}{' GUID ' + guid if guid else ''})\n" for n in names)
    (src / "CMakeLists.txt").write_text(f"cmake_minimum_required(VERSION 3.25)\n"
                                        f"project({names[0].lower()} LANGUAGES C)\n"
                                        f"find_package(dmi REQUIRED)\n" + calls)
    (src / file).write_text(source)
    return src


def fmus(build_dir, name):
    """The FMI 2.0 and 3.0 FMUs dmi_add_fmu(name) built in build_dir, by version ("2", "3")."""
    return {"2": str(build_dir / f"{name}.fmu"), "3": str(build_dir / "fmi3" / f"{name}.fmu")}


# The history z = 1 on [-tau, 0] of a model source: the C callback one.
HISTORY_ONE = r"""static int one(double t, double *out, void *user)
{
    (void)t, (void)user;
    out[0] = 1.0;
    return 0;
}
"""


def built_fmus(tmp_path_factory, prefix, name, source):
    """The FMUs (as fmus gives them) of the model name from the C source source,
    built with dmi_add_fmu in a new temporary folder against the installed dmi at prefix."""
    src = write_project(tmp_path_factory.mktemp(name.lower()), name, source)
    build(src, src / "build", prefix)
    return fmus(src / "build", name)


class Instance:
    """An FMU2Slave or FMU3Slave of the FMU at path with the calls the tests
    use under one name; self.log holds (status, category, message) (FMI 2.0:
    of the newest instance, fmpy's logger proxy being shared)."""

    def __init__(self, path, name="inst"):
        self.md = read_model_description(path)
        self.v3 = self.md.fmiVersion.startswith("3")
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.log = []
        unzipdir = extract(path)
        args = dict(guid=self.md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        if self.v3:
            def log3(env_, status, category, message):
                self.log.append((status, category.decode(), message.decode()))
            self.fmu = FMU3Slave(**args)
            self.fmu.instantiate(logMessage=log3)
        else:
            def log2(env_, instance, status, category, message):
                self.log.append((status, category.decode(), message.decode()))
            self.callbacks = fmi2CallbackFunctions()
            self.callbacks.logger = fmi2CallbackLoggerTYPE(log2)
            addLoggerProxy(byref(self.callbacks))
            self.fmu = FMU2Slave(**args)
            self.fmu.instantiate(callbacks=self.callbacks)

    def set(self, name, value):
        vr = [self.vr[name]]
        if isinstance(value, int) and not isinstance(value, bool):
            (self.fmu.setInt32 if self.v3 else self.fmu.setInteger)(vr, [value])
        else:
            (self.fmu.setFloat64 if self.v3 else self.fmu.setReal)(vr, [value])

    def get(self, names):
        vr = [self.vr[n] for n in names]
        return list(self.fmu.getFloat64(vr) if self.v3 else self.fmu.getReal(vr))

    def start(self, stop=None):
        if self.v3:
            self.fmu.enterInitializationMode(startTime=0.0, stopTime=stop)
        else:
            self.fmu.setupExperiment(startTime=0.0, stopTime=stop)
            self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def save(self):
        if self.v3:
            return bytes(self.fmu.serializeFMUState(self.fmu.getFMUState()))
        return bytes(self.fmu.serializeFMUstate(self.fmu.getFMUstate()))

    def restore(self, data):
        if self.v3:
            self.fmu.setFMUState(self.fmu.deserializeFMUState(data))
        else:
            self.fmu.setFMUstate(self.fmu.deSerializeFMUstate(data))

    def free(self):
        self.fmu.freeInstance()
