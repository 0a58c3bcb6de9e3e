/*
 * Examples 4.1 and 4.2 of the paper against their exact solutions, and the
 * order study of Figure 4.3.  The errors are measured here, from
 * the exact solutions (4.8) and (4.10) of the paper, and compared with the
 * independent reference values of ../shared/reference/errors_ex41_ex42.csv.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core_test.h"

/* The reference errors may differ in the third digit (README). */
static const double REF_REL = 0.01;

typedef struct {
    double state, w, v; /* max |U^p - (w, w')(t_p)| (Euclidean), in w, in w' */
    int times_exact;    /* dmi_time == p h at every step */
} max_errors;

/* Example 4.1 or 4.2 with h = 1/N (b = alpha = tau = 1) over t_p in [-1, 10]. */
static int exact_errors(int example, size_t N, max_errors *e)
{
    paper_example ex = {example};
    dmi_solver *s = core_paper_solver(&ex, N);
    const double h = 1.0 / (double)N;
    const size_t M = 10 * N; /* T = 10 */
    double u[2];
    *e = (max_errors){0, 0, 0, 1};
    int rc = s ? DMI_OK : DMI_ENOMEM;
    for (size_t k = 0; rc == DMI_OK && k <= N + M; k++) { /* p = k - N */
        double t;
        if (k < N) {
            t = -(double)(N - k) * h;
            rc = dmi_get_past(s, N - k, u);
        } else {
            t = (double)(k - N) * h;
            if (k > N)
                rc = dmi_step(s);
            if (rc == DMI_OK)
                rc = dmi_get_state(s, u);
            e->times_exact &= dmi_time(s) == t;
        }
        double ew = fabs(u[0] - paper_w(example, t)), ev = fabs(u[1] - paper_v(example, t));
        e->w = fmax(e->w, ew);
        e->v = fmax(e->v, ev);
        e->state = fmax(e->state, sqrt(ew * ew + ev * ev));
    }
    dmi_free(&s);
    return rc;
}

/* The reference row (example, N, h, state, w, v) for example 4.x and N. */
static const double *ref_row(const double *ref, size_t rows, double example, size_t N)
{
    for (size_t r = 0; r < rows; r++)
        if (ref[6 * r] == example && ref[6 * r + 1] == (double)N)
            return ref + 6 * r;
    printf("\n  no reference row for example %.1f, N = %zu\n", example, N);
    return NULL;
}

static void check_against_reference(const max_errors *e, const double *row)
{
    CU_ASSERT_PTR_NOT_NULL_FATAL(row);
    CU_ASSERT(core_close_rel("max error of the state", e->state, row[3], REF_REL));
    CU_ASSERT(core_close_rel("max error in w", e->w, row[4], REF_REL));
    CU_ASSERT(core_close_rel("max error in w'", e->v, row[5], REF_REL));
}

static void check_example(int example, double ref_name)
{
    size_t rows;
    double *ref = core_read_csv("errors_ex41_ex42.csv", 6, &rows);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ref);
    max_errors e;
    CU_ASSERT_EQUAL_FATAL(exact_errors(example, 9991, &e), DMI_OK);
    printf("\n  Example %d, h = 1/9991: max error state %.4e, w %.4e, w' %.4e\n", example,
           e.state, e.w, e.v);
    CU_ASSERT(e.times_exact);
    /* The paper's accuracy claim (Figures 4.1, 4.2: the curves are superimposed). */
    CU_ASSERT(e.w <= 1e-3);
    check_against_reference(&e, ref_row(ref, rows, ref_name, 9991));
    free(ref);
}

static void test_example_41(void)
{
    check_example(41, 4.1);
}

static void test_example_42(void)
{
    check_example(42, 4.2);
}

/* Figure 4.3: Example 4.2 at h = 1/(1001 + 50k), k = 1..18. */
static void test_order_study(void)
{
    enum { K = 18 };
    size_t rows;
    double *ref = core_read_csv("errors_ex41_ex42.csv", 6, &rows);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ref);
    double logh[K], loge[3][K];
    for (size_t k = 1; k <= K; k++) {
        size_t N = 1001 + 50 * k;
        max_errors e;
        CU_ASSERT_EQUAL_FATAL(exact_errors(42, N, &e), DMI_OK);
        CU_ASSERT(e.times_exact);
        check_against_reference(&e, ref_row(ref, rows, 4.2, N));
        logh[k - 1] = log(1.0 / (double)N);
        loge[0][k - 1] = log(e.state);
        loge[1][k - 1] = log(e.w);
        loge[2][k - 1] = log(e.v);
    }
    const char *name[3] = {"state", "w", "w'"};
    for (int c = 0; c < 3; c++) {
        double slope = core_ls_slope(logh, loge[c], K);
        printf("\n  observed order (least-squares slope, error in %s): %.4f", name[c], slope);
        CU_ASSERT(slope >= 0.95 && slope <= 1.05);
    }
    printf("\n");
    free(ref);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"Example 4.1 at h = 1/9991 against the exact solution", test_example_41},
        {"Example 4.2 at h = 1/9991 against the exact solution", test_example_42},
        {"order study of Figure 4.3 (Example 4.2, 18 step sizes)", test_order_study},
        {NULL, NULL}};
    return core_main(argc, argv, "core: paper Examples 4.1 and 4.2", tests);
}
