/*
 * 10,000 create/init/step/free cycles of the solver (Example 4.3, N = 1000,
 * both convolution methods, with state save/load and a rejected load in every
 * cycle) and 10,000 instantiate/initialize/step/free cycles of the FMU (with
 * state get/serialize/deserialize/set and a rejected state): the resident
 * memory after the last cycle exceeds the one after a warm-up of 1,000 cycles
 * by less than a generous bound, and every cycle ends in bitwise the same
 * state as the first one.
 * Usage: test_cycles solver | test_cycles fmu <unpacked .so> <GUID>
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/CUnit.h>

#include "dmi.h"
#include "fmu_host.h"
#include "hard_util.h"
#include "paper.h"

#define CYCLES 10000
#define WARMUP 1000
#define STEPS 20
#define RSS_BOUND_KIB 4096 /* one leaked history (32 KiB) per cycle would add 280 MiB */

/* Runs CYCLES cycles of one kind; cycle(k, u) returns 0 and the final (w, v). */
static void run_cycles(const char *what, int (*one)(int k, double u[2]))
{
    double first[2][2];
    long rss_warm = -1;
    size_t bad = 0, differ = 0;
    for (int c = 0; c < CYCLES; c++) {
        double u[2];
        int k = c % 2;
        if (one(k, u) != 0)
            bad++;
        else if (c < 2)
            memcpy(first[k], u, sizeof u);
        else if (memcmp(first[k], u, sizeof u) != 0)
            differ++;
        if (c + 1 == WARMUP)
            rss_warm = hard_rss_kib();
    }
    long rss_end = hard_rss_kib();
    CHECK(bad == 0, "%s: %zu cycles failed", what, bad);
    CHECK(differ == 0, "%s: %zu cycles ended elsewhere than the first", what, differ);
    CU_ASSERT_FATAL(rss_warm > 0 && rss_end > 0);
    printf("\n    %s cycles: RSS %ld KiB after %d cycles, %ld KiB after %d\n", what, rss_warm,
           WARMUP, rss_end, CYCLES);
    CHECK(rss_end - rss_warm < RSS_BOUND_KIB, "%s: RSS grew by %ld KiB over %d cycles (bound %d KiB)",
          what, rss_end - rss_warm, CYCLES - WARMUP, RSS_BOUND_KIB);
}

/* One cycle; u gets the final state.  Returns a DMI code. */
static int cycle(int method, double u[2])
{
    paper_example ex = {43};
    dmi_solver *s = NULL;
    int rc = dmi_create(&s, 2, 1.0, 1000);
    if (rc != DMI_OK)
        return rc;
    unsigned char *buf = NULL;
    size_t size = dmi_state_size(s);
    rc = paper_setup(s, &ex);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(s, method);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc == DMI_OK)
        rc = dmi_advance(s, STEPS / 2);
    if (rc == DMI_OK)
        rc = (buf = malloc(size)) ? dmi_state_save(s, buf, size) : DMI_ENOMEM;
    if (rc == DMI_OK)
        rc = dmi_advance(s, STEPS / 2);
    if (rc == DMI_OK)
        rc = dmi_state_load(s, buf, size);
    if (rc == DMI_OK) {
        buf[size / 2] ^= 1; /* corrupted: must be rejected */
        rc = dmi_state_load(s, buf, size) == DMI_EINVAL ? DMI_OK : DMI_ESTATE;
    }
    if (rc == DMI_OK)
        rc = dmi_advance(s, STEPS / 2);
    if (rc == DMI_OK)
        rc = dmi_get_state(s, u);
    free(buf);
    dmi_free(&s);
    return rc;
}

static int solver_cycle(int k, double u[2])
{
    static const int methods[2] = {DMI_CONV_DIRECT, DMI_CONV_AUTO};
    return cycle(methods[k], u) == DMI_OK ? 0 : -1;
}

static void test_solver_cycles(void)
{
    run_cycles("solver", solver_cycle);
}

static fmu_api F;
static const char *GUID;

/* One FMU life: N = 100, ten steps of h (k = 0) or of 2.5 h (k = 1), a state
 * round trip through bytes, a rejected state; u = (w, v) at the end. */
static int fmu_cycle(int k, double u[2])
{
    fmu_log log = {0};
    const fmi2CallbackFunctions cb = fmu_callbacks(&log);
    fmi2Component c = fmu_new(&F, GUID, &cb);
    if (!c)
        return -1;
    const fmi2ValueReference vrN = VR_N, vrwv[2] = {VR_w, VR_v};
    const fmi2Integer N = 100;
    const double dt = k ? 0.025 : 0.01;
    int ok = F.setup(c, fmi2False, 0, 0.0, fmi2False, 0) == fmi2OK &&
             F.enter_init(c) == fmi2OK && F.set_integer(c, &vrN, 1, &N) == fmi2OK &&
             F.exit_init(c) == fmi2OK;
    double t = 0;
    for (int s = 0; ok && s < 10; s++, t += dt)
        ok = F.do_step(c, t, dt, fmi2True) == fmi2OK;
    fmi2FMUstate st = NULL, back = NULL;
    size_t size = 0;
    fmi2Byte *bytes = NULL;
    ok = ok && F.get_state(c, &st) == fmi2OK && F.state_size(c, st, &size) == fmi2OK &&
         (bytes = malloc(size)) != NULL && F.serialize(c, st, bytes, size) == fmi2OK;
    for (int s = 0; ok && s < 5; s++, t += dt)
        ok = F.do_step(c, t, dt, fmi2True) == fmi2OK;
    if (ok) {
        t -= 5 * dt;
        ok = F.deserialize(c, bytes, size, &back) == fmi2OK && F.set_state(c, back) == fmi2OK;
        bytes[size / 2] ^= 1; /* corrupted: must be rejected */
        fmi2FMUstate bad = NULL;
        ok = ok && F.deserialize(c, bytes, size, &bad) == fmi2Error && bad == NULL;
    }
    for (int s = 0; ok && s < 5; s++, t += dt)
        ok = F.do_step(c, t, dt, fmi2True) == fmi2OK;
    ok = ok && F.get_real(c, vrwv, 2, u) == fmi2OK && F.terminate(c) == fmi2OK;
    if (st)
        F.free_state(c, &st);
    if (back)
        F.free_state(c, &back);
    free(bytes);
    F.free_instance(c);
    return ok ? 0 : -1;
}

static void test_fmu_cycles(void)
{
    run_cycles("FMU", fmu_cycle);
}

int main(int argc, char **argv)
{
    int fmu = argc > 1 && strcmp(argv[1], "fmu") == 0;
    if (!(argc == 2 && strcmp(argv[1], "solver") == 0) && !(fmu && argc == 4)) {
        fprintf(stderr, "usage: %s solver | %s fmu <unpacked .so> <GUID>\n", argv[0], argv[0]);
        return 2;
    }
    if (fmu) {
        GUID = argv[3];
        if (fmu_load(&F, argv[2]) != 0)
            return 2;
    }
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 2;
    CU_pSuite suite = CU_add_suite("cycles", NULL, NULL);
    if (!suite || !(fmu ? CU_add_test(suite, "10000 FMU cycles, flat RSS", test_fmu_cycles)
                        : CU_add_test(suite, "10000 solver cycles, flat RSS", test_solver_cycles))) {
        CU_cleanup_registry();
        return 2;
    }
    int status = hard_run_tests(0);
    if (fmu)
        fmu_unload(&F);
    return status;
}
