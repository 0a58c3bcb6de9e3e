/*
 * The resolvent's hold watched step by step (src/core.h: dmi_watch, the
 * FMU framework's built-in indicators), on libdmi's GSL-free core: the holds
 * and their changes counted by dmi_advance_watch are those computed here from
 * each step's resolvent argument X^p (dmi_get_step_terms) with the formulas of
 * dmi_fmu_stuck and dmi_fmu_contact; with stop, it returns after each change;
 * refused without friction or a box, for a component >= n, before dmi_init.
 *
 *   u' = (-u_1, u_0 + 1.3 cos 8t) - A(u), u(t) = (0.1 t, 0.2) for t <= 0, tau = 1,
 *   friction alpha = (0, 1), or the box [-0.1, 0.1] x [-0.15, 0.15].
 *
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/Basic.h>

#include "forced_oscillator.h"
#include "core.h"

enum { n = 2, N = 200, STEPS = 2000 };
static const double ALPHA[n] = {0.0, 1.0};
static const double LO[n] = {-0.1, -0.15}, HI[n] = {0.1, 0.15};


static dmi_solver *solver(int box)
{
    dmi_solver *s = NULL;
    if (dmi_create(&s, n, 1.0, N) != DMI_OK)
        return NULL;
    dmi_set_rhs(s, rhs, NULL);
    dmi_set_history(s, history, NULL);
    if (box)
        dmi_set_box(s, LO, HI);
    else
        dmi_set_friction(s, ALPHA);
    if (dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* The hold of component i at X (dmi_fmu_stuck, dmi_fmu_contact). */
static int hold(int box, size_t i, double x, double h)
{
    if (box)
        return x <= LO[i] ? -1 : x >= HI[i] ? 1 : 0;
    return fabs(x) <= h * ALPHA[i];
}

/* The steps p at which a hold of components 0 and 1 changes, by plain steps
 * and dmi_get_step_terms; returns their number. */
static size_t changes_by_hand(int box, uint64_t *at)
{
    dmi_solver *s = solver(box);
    const double h = dmi_get_h(s);
    double U[n], W[n], X[n];
    dmi_get_state(s, U);
    int was[n] = {hold(box, 0, U[0], h), hold(box, 1, U[1], h)};
    size_t count = 0;
    for (uint64_t p = 1; p <= STEPS; p++) {
        CU_ASSERT_EQUAL_FATAL(dmi_step(s), DMI_OK);
        dmi_get_step_terms(s, W, X);
        int changed = 0;
        for (size_t i = 0; i < n; i++) {
            int now = hold(box, i, X[i], h);
            changed |= now != was[i];
            was[i] = now;
        }
        if (changed)
            at[count++] = p;
    }
    dmi_free(&s);
    return count;
}

static void counts_as_by_hand(int box)
{
    uint64_t at[STEPS];
    const size_t want = changes_by_hand(box, at);
    CU_ASSERT(want > 10); /* the model sticks and slips (or touches) all along */
    dmi_solver *s = solver(box);
    const size_t comp[n] = {0, 1};
    int held[n];
    dmi_watch w = {n, comp, held, 0, 0};
    CU_ASSERT_EQUAL_FATAL(dmi_watch_start(s, &w), DMI_OK);
    size_t taken = 0;
    CU_ASSERT_EQUAL(dmi_advance_watch(s, STEPS, &w, 0, &taken), DMI_OK);
    CU_ASSERT_EQUAL(taken, STEPS);
    CU_ASSERT_EQUAL(w.changes, want);
    CU_ASSERT_EQUAL(w.last_p, at[want - 1]);
    dmi_free(&s);

    /* with stop: one change per call, at the steps found by hand */
    s = solver(box);
    dmi_watch v = {n, comp, held, 0, 0};
    dmi_watch_start(s, &v);
    uint64_t p = 0;
    for (size_t k = 0; k < want; k++) {
        CU_ASSERT_EQUAL_FATAL(dmi_advance_watch(s, STEPS - p, &v, 1, &taken), DMI_OK);
        p += taken;
        CU_ASSERT_EQUAL_FATAL(p, at[k]);
        CU_ASSERT_EQUAL(v.changes, k + 1);
        CU_ASSERT_EQUAL(v.last_p, p);
    }
    dmi_free(&s);
}

static void test_friction(void)
{
    counts_as_by_hand(0);
}

static void test_box(void)
{
    counts_as_by_hand(1);
}

static void test_refused(void)
{
    const size_t comp[1] = {2};
    int held[1];
    dmi_watch w = {1, comp, held, 0, 0};
    dmi_solver *s = NULL;
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, n, 1.0, N), DMI_OK);
    dmi_set_friction(s, ALPHA);
    CU_ASSERT_EQUAL(dmi_watch_start(s, &w), DMI_ESTATE); /* before dmi_init */
    dmi_init(s);
    CU_ASSERT_EQUAL(dmi_watch_start(s, &w), DMI_EINVAL); /* component 2 of n = 2 */
    CU_ASSERT_PTR_NOT_NULL(strstr(dmi_last_error(s), "component 2 >= n = 2"));
    dmi_set_resolvent(s, NULL, NULL);
    dmi_init(s);
    const size_t one[1] = {1};
    w.comp = one;
    CU_ASSERT_EQUAL(dmi_watch_start(s, &w), DMI_EINVAL); /* no friction, no box */
    CU_ASSERT_PTR_NOT_NULL(strstr(dmi_last_error(s), "dmi_set_friction or dmi_set_box"));
    dmi_free(&s);
}

int main(void)
{
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 1;
    CU_pSuite suite = CU_add_suite("watch", NULL, NULL);
    CU_add_test(suite, "friction", test_friction);
    CU_add_test(suite, "box", test_box);
    CU_add_test(suite, "refused", test_refused);
    CU_basic_set_mode(CU_BRM_VERBOSE);
    CU_basic_run_tests();
    const unsigned failed = CU_get_number_of_failures() + CU_get_number_of_tests_failed();
    CU_cleanup_registry();
    return failed ? 1 : 0;
}
