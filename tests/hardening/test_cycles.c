/*
 * 10,000 create/init/step/free cycles of the solver (Example 4.3, N = 1000,
 * both convolution methods, with state save/load and a rejected load in every
 * cycle): the resident memory after the last cycle exceeds the one after a
 * warm-up of 1,000 cycles by less than a generous bound, and every cycle ends
 * in bitwise the same state as the first cycle of its method.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/CUnit.h>

#include "dmi.h"
#include "hard_util.h"
#include "paper.h"

#define CYCLES 10000
#define WARMUP 1000
#define STEPS 20
#define RSS_BOUND_KIB 4096 /* one leaked history (32 KiB) per cycle would add 280 MiB */

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

static void test_solver_cycles(void)
{
    static const int methods[2] = {DMI_CONV_DIRECT, DMI_CONV_AUTO};
    double first[2][2];
    long rss_warm = -1;
    size_t bad = 0, differ = 0;
    for (int c = 0; c < CYCLES; c++) {
        double u[2];
        int m = c % 2;
        if (cycle(methods[m], u) != DMI_OK)
            bad++;
        else if (c < 2)
            memcpy(first[m], u, sizeof u);
        else if (memcmp(first[m], u, sizeof u) != 0)
            differ++;
        if (c + 1 == WARMUP)
            rss_warm = hard_rss_kib();
    }
    long rss_end = hard_rss_kib();
    CU_ASSERT_EQUAL(bad, 0);
    CU_ASSERT_EQUAL(differ, 0);
    CU_ASSERT_FATAL(rss_warm > 0 && rss_end > 0);
    printf("\n    solver cycles: RSS %ld KiB after %d cycles, %ld KiB after %d\n", rss_warm, WARMUP,
           rss_end, CYCLES);
    CHECK(rss_end - rss_warm < RSS_BOUND_KIB, "RSS grew by %ld KiB over %d cycles (bound %d KiB)",
          rss_end - rss_warm, CYCLES - WARMUP, RSS_BOUND_KIB);
}

int main(void)
{
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 2;
    CU_pSuite suite = CU_add_suite("cycles", NULL, NULL);
    if (!suite || !CU_add_test(suite, "10000 solver cycles, flat RSS", test_solver_cycles)) {
        CU_cleanup_registry();
        return 2;
    }
    return hard_run_tests(0);
}
