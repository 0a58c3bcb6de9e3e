/*
 * libFuzzer target: fmi2DeSerializeFMUstate of the fuzzer's bytes into an
 * instance of the FMU (loaded with dlopen, instrumented like this program),
 * then fmi2SetFMUstate and a few steps from the restored time.  Built for
 * each FMU: fuzz_fmu_state (FMI 2.0) and fuzz_fmu3_state (FMI 3.0, through
 * tests/fmu/fmu_fmi3.c: fmi3DeserializeFMUState, ...; the same corpus, as
 * both write the same bytes).
 *
 * Input: one flags byte, then the serialized state.  Flags bit 0: recompute
 * the state's checksums (the FMU's outer one and libdmi's inner one, layouts
 * in fmu/model.h and src/bytes.h) so that the fuzzer gets past them to the checks
 * behind; bits 1-2: the phase of the instance that receives the state
 * (instantiated, initialization mode, stepping).
 *
 * Besides the sanitizers, it aborts on a broken contract: an fmi2Error without
 * a logged reason, a rejected state that changed the instance, a restored
 * instance whose state cannot be saved again, anything printed is not checked
 * (libFuzzer prints itself).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_host.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static fmu_api F;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    if (fmu_load(&F, DMI_FMU_SO) != 0)
        abort();
    return 0;
}

static void must(int ok)
{
    if (!ok)
        abort();
}

/* An instance in phase 0 (instantiated), 1 (initialization mode) or 2
 * (stepping, t = 0.03 with N = 10). */
static fmi2Component instance(int phase, const fmi2CallbackFunctions *cb)
{
    fmi2Component c = fmu_new(&F, DMI_FMU_GUID, cb);
    must(c != NULL);
    const fmi2ValueReference vrN = VR_N;
    const fmi2Integer N = 10;
    if (phase >= 1)
        /* stop time 1: N = 10 is no coarse step for so short an experiment (no warning) */
        must(F.setup(c, fmi2False, 0, 0.0, fmi2True, 1.0) == fmi2OK && F.enter_init(c) == fmi2OK &&
             F.set_integer(c, &vrN, 1, &N) == fmi2OK);
    if (phase >= 2) {
        must(F.exit_init(c) == fmi2OK);
        for (int k = 0; k < 3; k++)
            must(F.do_step(c, 0.01 * k, 0.01, fmi2True) == fmi2OK);
    }
    return c;
}

/* Status st must come with a logged reason if it is an error. */
static void logged(const fmu_log *log, unsigned errors_before, fmi2Status st)
{
    must(st == fmi2OK || st == fmi2Error);
    if (st == fmi2Error)
        must(log->errors > errors_before && log->message[0] != '\0');
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    const uint8_t flags = data[0];
    size_t n = size - 1;
    uint8_t *bytes = malloc(n ? n : 1);
    must(bytes != NULL);
    memcpy(bytes, data + 1, n);
    if (flags & 1)
        fmu_state_fix_checksums(bytes, n, 1);

    fmu_log log = {0};
    const fmi2CallbackFunctions cb = fmu_callbacks(&log);
    fmi2Component c = instance((flags >> 1) % 3, &cb);
    size_t size0 = 0, size1 = 0;
    unsigned char *before = fmu_snapshot(&F, c, &size0);
    must(before != NULL);

    fmi2FMUstate st = NULL;
    unsigned errors = log.errors;
    fmi2Status rc = F.deserialize(c, (const fmi2Byte *)bytes, n, &st);
    logged(&log, errors, rc);
    if (rc == fmi2OK) {
        errors = log.errors;
        rc = F.set_state(c, st);
        logged(&log, errors, rc);
        F.free_state(c, &st);
    }
    if (rc != fmi2OK) { /* rejected: the instance is as it was */
        unsigned char *after = fmu_snapshot(&F, c, &size1);
        must(after != NULL && size1 == size0 && memcmp(before, after, size0) == 0);
        free(after);
    } else { /* restored: it can be saved again and stepped on from its time */
        unsigned char *again = fmu_snapshot(&F, c, &size1);
        must(again != NULL);
        free(again);
        fmi2Real t = 0;
        const fmi2ValueReference vr_time = VR_time; /* FMI 3.0: the variable time */
        if (F.get_real_status ? F.get_real_status(c, fmi2LastSuccessfulTime, &t) == fmi2OK
                              : F.get_real(c, &vr_time, 1, &t) == fmi2OK)
            for (int k = 0; k < 3; k++) {
                errors = log.errors;
                fmi2Status s = F.do_step(c, t, 0.01, fmi2True);
                logged(&log, errors, s);
                if (s != fmi2OK)
                    break;
                t += 0.01;
                const fmi2ValueReference vr[4] = {VR_w, VR_v, VR_friction, VR_delay_force};
                fmi2Real out[4];
                must(F.get_real(c, vr, 4, out) == fmi2OK);
            }
    }
    free(before);
    free(bytes);
    F.free_instance(c);
    return 0;
}
