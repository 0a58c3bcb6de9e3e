/*
 * The minimal FMI 2.0 importer of fmu_host.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#define _POSIX_C_SOURCE 200809L
#include "fmu_host.h"

#include "bytes.h" /* the checksums and libdmi's state layout (src/) */

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    fmu_log *log = env;
    (void)name;
    if (!log)
        return;
    log->count++;
    if (status == fmi2Error)
        log->errors++;
    log->status = status;
    snprintf(log->category, sizeof log->category, "%s", category ? category : "");
    va_list ap;
    va_start(ap, message);
    vsnprintf(log->message, sizeof log->message, message ? message : "", ap);
    va_end(ap);
}

fmi2CallbackFunctions fmu_callbacks(fmu_log *log)
{
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, log};
    return cb;
}

fmi2Component fmu_new(const fmu_api *f, const char *guid, const fmi2CallbackFunctions *cb)
{
    return f->instantiate("hardening", fmi2CoSimulation, guid, "", cb, fmi2False, fmi2False);
}

unsigned char *fmu_snapshot(const fmu_api *f, fmi2Component c, size_t *size)
{
    fmi2FMUstate st = NULL;
    unsigned char *b = NULL;
    *size = 0;
    if (f->get_state(c, &st) == fmi2OK && f->state_size(c, st, size) == fmi2OK &&
        (b = malloc(*size ? *size : 1)) != NULL &&
        f->serialize(c, st, (fmi2Byte *)b, *size) != fmi2OK) {
        free(b);
        b = NULL;
    }
    if (st)
        f->free_state(c, &st);
    return b;
}

void fmu_state_fix_checksums(unsigned char *b, size_t size, int inner)
{
    if (size < MODEL_STATE_AT_DMI + 8)
        return;
    const uint64_t ndmi = dmi_get_u64(b, MODEL_STATE_AT_NDMI);
    if (inner && ndmi >= DMI_STATE_HEADER && ndmi <= size - MODEL_STATE_AT_DMI - 8) {
        unsigned char *d = b + MODEL_STATE_AT_DMI;
        dmi_put_u64(d, DMI_STATE_AT_CHECKSUM,
                    dmi_fnv1a_skip(d, (size_t)ndmi, DMI_STATE_AT_CHECKSUM));
    }
    dmi_put_u64(b, size - 8, dmi_fnv1a(DMI_FNV1A_INIT, b, size - 8));
}
