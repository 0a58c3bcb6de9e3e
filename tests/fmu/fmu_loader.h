/*
 * The FMI 2.0 functions of an unpacked FMU binary, loaded with dlopen (or
 * LoadLibrary under _WIN32): the one loader of the C importers in tests/
 * (fmu_master, also built for Windows; the hardening tests, the FMU fuzzer).
 * An FMI 3.0 binary is loaded behind the same FMI 2.0 function types
 * (fmu_fmi3.h); version tells which one it is.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef FMU_LOADER_H
#define FMU_LOADER_H

#include "fmi2FunctionTypes.h"

typedef struct {
    void *lib;   /* the dlopen handle or the HMODULE */
    int version; /* 2 or 3 */
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetDebugLoggingTYPE *set_debug_logging;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter_init;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2TerminateTYPE *terminate;
    fmi2ResetTYPE *reset;
    fmi2GetRealTYPE *get_real;
    fmi2GetIntegerTYPE *get_integer;
    fmi2GetBooleanTYPE *get_boolean;
    fmi2GetStringTYPE *get_string;
    fmi2SetRealTYPE *set_real;
    fmi2SetIntegerTYPE *set_integer;
    fmi2SetBooleanTYPE *set_boolean;
    fmi2SetStringTYPE *set_string;
    fmi2GetFMUstateTYPE *get_state;
    fmi2SetFMUstateTYPE *set_state;
    fmi2FreeFMUstateTYPE *free_state;
    fmi2SerializedFMUstateSizeTYPE *state_size;
    fmi2SerializeFMUstateTYPE *serialize;
    fmi2DeSerializeFMUstateTYPE *deserialize;
    fmi2DoStepTYPE *do_step;
    fmi2CancelStepTYPE *cancel_step;
    fmi2GetRealStatusTYPE *get_real_status;
} fmu_api;

/* 0 on success; -1 (message on stderr) if the library or a function is missing. */
int fmu_load(fmu_api *f, const char *so_path); /* .so or .dll */
void fmu_unload(fmu_api *f);

#endif
