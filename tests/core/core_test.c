/*
 * Support code of the core test suite (see core_test.h).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "core_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <CUnit/Basic.h>

/* Set once by core_main before any test runs; CUnit tests take no argument. */
static const char *refdir;

const char *core_refdir(void)
{
    return refdir;
}

int core_main(int argc, char **argv, const char *suite_name, const core_test *tests)
{
    refdir = argc > 1 ? argv[1] : NULL;
    if (CU_initialize_registry() != CUE_SUCCESS)
        return 2;
    CU_pSuite suite = CU_add_suite(suite_name, NULL, NULL);
    for (const core_test *t = tests; suite && t->name; t++)
        if (!CU_add_test(suite, t->name, t->fn))
            suite = NULL;
    if (!suite) {
        fprintf(stderr, "%s: cannot register the tests: %s\n", suite_name, CU_get_error_msg());
        CU_cleanup_registry();
        return 2;
    }
    CU_basic_set_mode(CU_BRM_VERBOSE);
    CU_basic_run_tests();
    unsigned failed = CU_get_number_of_failures() + CU_get_number_of_tests_failed();
    unsigned run = CU_get_number_of_tests_run();
    CU_cleanup_registry();
    return failed == 0 && run > 0 ? 0 : 1;
}

double *core_read_csv(const char *name, size_t ncols, size_t *rows)
{
    *rows = 0;
    if (!refdir) {
        CU_FAIL("no reference directory given on the command line");
        return NULL;
    }
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", refdir, name);
    FILE *fp = fopen(path, "r");
    if (!fp) {
        fprintf(stderr, "cannot open %s\n", path);
        CU_FAIL("reference file missing");
        return NULL;
    }
    double *v = NULL;
    size_t cap = 0, count = 0;
    char line[4096];
    int ok = fgets(line, sizeof line, fp) != NULL; /* header */
    while (ok && fgets(line, sizeof line, fp)) {
        if (line[0] == '\n' || line[0] == '\0')
            continue;
        if (count + ncols > cap) {
            cap = cap ? 2 * cap : 64 * ncols;
            double *nv = realloc(v, cap * sizeof *nv);
            if (!nv) {
                ok = 0;
                break;
            }
            v = nv;
        }
        char *p = line;
        for (size_t c = 0; c < ncols && ok; c++) {
            char *end;
            v[count + c] = strtod(p, &end);
            ok = end != p && (*end == (c + 1 < ncols ? ',' : '\n') || (c + 1 == ncols && !*end));
            p = end + 1;
        }
        count += ncols;
    }
    fclose(fp);
    if (!ok || count == 0) {
        fprintf(stderr, "%s: malformed (expected %zu numeric columns)\n", path, ncols);
        CU_FAIL("reference file malformed");
        free(v);
        return NULL;
    }
    *rows = count / ncols;
    return v;
}

int core_close_rel(const char *what, double a, double b, double rel)
{
    int ok = fabs(a - b) <= rel * fabs(b);
    if (!ok)
        printf("\n  %s: %.10e vs reference %.10e (relative difference %.3e > %.3e)\n", what, a,
               b, fabs(a - b) / fabs(b), rel);
    return ok;
}

double core_ls_slope(const double *x, const double *y, size_t n)
{
    double mx = 0, my = 0, sxy = 0, sxx = 0;
    for (size_t i = 0; i < n; i++) {
        mx += x[i] / (double)n;
        my += y[i] / (double)n;
    }
    for (size_t i = 0; i < n; i++) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
    }
    return sxy / sxx;
}

dmi_solver *core_init_or_free(dmi_solver *s, int rc)
{
    if (rc != DMI_OK || dmi_init(s) != DMI_OK)
        dmi_free(&s);
    return s;
}

/* A new solver of n = 2, tau = 1, N steps, or NULL. */
static dmi_solver *new_n2(size_t N)
{
    dmi_solver *s = NULL;
    return dmi_create(&s, 2, 1.0, N) == DMI_OK ? s : NULL;
}

dmi_solver *core_paper_solver(paper_example *ex, size_t N)
{
    dmi_solver *s = new_n2(N);
    return s ? core_init_or_free(s, paper_setup(s, ex)) : NULL;
}

/* ---- saved states ---------------------------------------------------------- */

unsigned char *core_save(const dmi_solver *s, size_t *size)
{
    *size = dmi_state_size(s);
    unsigned char *b = *size ? malloc(*size) : NULL;
    if (b && dmi_state_save(s, b, *size) != DMI_OK) {
        free(b);
        b = NULL;
    }
    return b;
}

int core_state_is(const dmi_solver *s, const unsigned char *bytes, size_t size)
{
    size_t n;
    unsigned char *b = core_save(s, &n);
    int same = b && bytes && n == size && memcmp(b, bytes, n) == 0;
    free(b);
    return same;
}

int core_same_state(const dmi_solver *a, const dmi_solver *b)
{
    size_t n;
    unsigned char *bytes = core_save(a, &n);
    int same = bytes && core_state_is(b, bytes, n);
    free(bytes);
    return same;
}

unsigned char *core_state_v1(const dmi_solver *s, size_t n, size_t N, double tau, size_t *size)
{
    uint64_t w[8] = {UINT64_C(0x444d495354415445), 1, n, N, 0, 0, 0, 0};
    memcpy(&w[4], &tau, sizeof tau);
    const size_t nd = (N + 3) * n;
    double *d = calloc(nd, sizeof *d);
    unsigned char *b = malloc(sizeof w + nd * sizeof *d);
    int ok = d && b && dmi_get_step_index(s, &w[5]) == DMI_OK;
    w[6] = w[5] != 0;
    for (size_t lag = 0; ok && lag <= N; lag++)
        ok = dmi_get_past(s, lag, d + lag * n) == DMI_OK;
    if (ok && w[5] > 0)
        ok = dmi_get_step_terms(s, d + (N + 1) * n, d + (N + 2) * n) == DMI_OK;
    if (!ok) {
        free(d);
        free(b);
        return NULL;
    }
    *size = sizeof w + nd * sizeof *d;
    memcpy(b, w, sizeof w);
    memcpy(b + sizeof w, d, nd * sizeof *d);
    uint64_t hsh = UINT64_C(0xcbf29ce484222325);
    for (size_t i = 0; i < *size; i++) {
        hsh ^= b[i];
        hsh *= UINT64_C(0x100000001b3);
    }
    memcpy(b + 7 * sizeof(uint64_t), &hsh, sizeof hsh);
    free(d);
    return b;
}

/* ---- the fault-injection model ------------------------------------------------- */

/* Counts the call; if the callback is to misbehave now, spoils out[k] or
 * returns a nonzero code.  Returns the callback's return value. */
static int inject(core_model *m, int kind, double *out, size_t k)
{
    m->calls[kind]++;
    if (m->fault[kind] == FAULT_NONE || m->calls[kind] <= m->fail_after[kind])
        return 0;
    switch (m->fault[kind]) {
    case FAULT_RETURN: return 7;
    case FAULT_NAN: out[k] = NAN; break;
    case FAULT_INF: out[k] = INFINITY; break;
    default: out[k] = -INFINITY; break;
    }
    return 0;
}

int core_rhs(double t, const double *u, double *out, void *user)
{
    out[0] = 0.3 * u[0] - u[1] + sin(t);
    out[1] = u[0] + 0.1 * u[1] - 0.5 * cos(2 * t);
    return inject(user, CB_RHS, out, 1);
}

int core_resolvent(double lambda, const double *x, double *out, void *user)
{
    out[0] = x[0] / (1 + lambda * 1.0);
    out[1] = x[1] / (1 + lambda * 2.0);
    return inject(user, CB_RESOLVENT, out, 0);
}

int core_kernel(double s, double *out, void *user)
{
    out[0] = 0.2 * cos(s);
    out[1] = -0.1;
    out[2] = 0.4 * s;
    out[3] = 0.3 - s;
    return inject(user, CB_KERNEL, out, 2);
}

int core_history(double t, double *out, void *user)
{
    out[0] = cos(t);
    out[1] = 0.5 + sin(t);
    return inject(user, CB_HISTORY, out, 1);
}

int core_model_setup(dmi_solver *s, core_model *m)
{
    int rc = dmi_set_rhs(s, core_rhs, m);
    if (rc == DMI_OK)
        rc = dmi_set_resolvent(s, core_resolvent, m);
    if (rc == DMI_OK)
        rc = dmi_set_kernel(s, core_kernel, m);
    if (rc == DMI_OK)
        rc = dmi_set_history(s, core_history, m);
    return rc;
}

dmi_solver *core_model_solver(core_model *m, size_t N)
{
    dmi_solver *s = new_n2(N);
    return s ? core_init_or_free(s, core_model_setup(s, m)) : NULL;
}

int core_z_one(double t, double *out, void *user)
{
    (void)t;
    (void)user;
    out[0] = 1;
    return 0;
}

int core_z_wave(double t, double *out, void *user)
{
    (void)user;
    out[0] = cos(5 * t);
    return 0;
}
