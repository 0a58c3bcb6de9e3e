/*
 * A minimal FMI 2.0 importer for the hardening tests and the FMU fuzzer: loads
 * an unpacked FMU binary with dlopen and records what the FMU logs.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef FMU_HOST_H
#define FMU_HOST_H

#include <stddef.h>

#include "fmi2FunctionTypes.h"

/* Value references of the FMU's variables (modelDescription.xml). */
enum {
    FMU_b, FMU_alpha, FMU_tau, FMU_w0, FMU_v0,
    FMU_H_c0, FMU_H_c1, FMU_H_lambda,
    FMU_H_a1, FMU_H_omega1, FMU_H_a2, FMU_H_omega2, FMU_H_a3, FMU_H_omega3,
    FMU_g_offset, FMU_g_amp, FMU_g_omega, FMU_g_phase,
    FMU_g_in,
    FMU_w, FMU_v, FMU_friction, FMU_delay_force,
    FMU_N,
    FMU_sticking
};

typedef struct {
    void *lib;
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
int fmu_load(fmu_api *f, const char *so_path);
void fmu_unload(fmu_api *f);

/* What the FMU logged through the callback. */
typedef struct {
    unsigned count, errors; /* messages, messages with status fmi2Error */
    fmi2Status status;      /* of the last message */
    char category[64];
    char message[512];
} fmu_log;

/* Callbacks with calloc/free and a logger writing into *log. */
fmi2CallbackFunctions fmu_callbacks(fmu_log *log);

/* Instantiates (co-simulation, logging off) with the GUID; NULL on failure. */
fmi2Component fmu_new(const fmu_api *f, const char *guid, const fmi2CallbackFunctions *cb);

/* The serialized state of c (malloc'd, *size bytes) or NULL if it cannot be
 * taken (e.g. in the error state). */
unsigned char *fmu_snapshot(const fmu_api *f, fmi2Component c, size_t *size);

#endif
