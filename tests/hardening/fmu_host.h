/*
 * A minimal FMI 2.0 importer for the hardening tests and the FMU fuzzer: loads
 * an unpacked FMU binary with dlopen and records what the FMU logs.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef FMU_HOST_H
#define FMU_HOST_H

#include <stddef.h>

#include "fmu_loader.h"

/* The value references VR_* of the FMU's variables, as in modelDescription.xml. */
#include "model.h"


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

/* Serialized states (layout: MODEL_STATE_AT_* of fmu/model.h, libdmi's part
 * at MODEL_STATE_AT_DMI laid out as src/bytes.h says).  Recomputes the outer
 * checksum, and libdmi's if inner and the recorded ndmi fits, so that an
 * edit reaches the checks behind. */
void fmu_state_fix_checksums(unsigned char *b, size_t size, int inner);

#endif
