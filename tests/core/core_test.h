/*
 * Support code of the core test suite: the CUnit runner, the
 * reference files, two histories of n = 1, saved-state comparisons and a
 * small n = 2 model whose callbacks can be made to fail on demand.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_CORE_TEST_H
#define DMI_CORE_TEST_H

#include <stddef.h>

#include <CUnit/CUnit.h>

#include "dmi.h"
#include "paper.h"

/* ---- runner -------------------------------------------------------------- */

typedef struct {
    const char *name;
    void (*fn)(void);
} core_test;

/* Runs the tests (array ended by {NULL, NULL}) as one CUnit suite and returns
 * the process exit status: 0 iff every assertion passed.  argv[1], if given,
 * is the reference directory (../shared/reference). */
int core_main(int argc, char **argv, const char *suite, const core_test *tests);

/* Defines main: core_main(argc, argv, suite, tests) with the tests given
 * after suite (each {"name", function}; the {NULL, NULL} end is added). */
#define CORE_MAIN(suite, ...)                                                  \
    int main(int argc, char **argv)                                            \
    {                                                                          \
        static const core_test core_main_tests[] = {__VA_ARGS__, {NULL, NULL}}; \
        return core_main(argc, argv, suite, core_main_tests);                  \
    }

/* The reference directory given on the command line (NULL if none). */
const char *core_refdir(void);

/* Reads a numeric CSV file of the reference directory: skips the header line,
 * returns rows * ncols values (row-major, malloc'd) and sets *rows, or NULL
 * (with a CUnit failure) if the file is missing or a row is malformed. */
double *core_read_csv(const char *name, size_t ncols, size_t *rows);

/* |a - b| <= rel * |b|, printing both values when it fails. */
int core_close_rel(const char *what, double a, double b, double rel);

/* Least-squares slope of y against x (n points). */
double core_ls_slope(const double *x, const double *y, size_t n);

/* s after dmi_init(s) if rc (the setup's code) is DMI_OK and dmi_init
 * succeeds; otherwise s is freed and NULL returned. */
dmi_solver *core_init_or_free(dmi_solver *s, int rc);

/* A new initialised solver of a paper example (examples/paper.c) with
 * h = tau / N, tau = 1, or NULL; ex must outlive it. */
dmi_solver *core_paper_solver(paper_example *ex, size_t N);

/* ---- histories of n = 1 (the cell rule's tests) -------------------------- */

/* z(t) = 1: W^0 is then the sum of all cell weights. */
int core_z_one(double t, double *out, void *user);

/* z(t) = cos(5 t): W^0 = sum_l w_l cos(5 l h) tells each cell's weight apart. */
int core_z_wave(double t, double *out, void *user);

/* ---- saved states ------------------------------------------------------ */

/* The bytes of dmi_state_save(s) (malloc'd, *size set), or NULL on failure. */
unsigned char *core_save(const dmi_solver *s, size_t *size);

/* 1 iff dmi_state_save gives the same bytes for a and b. */
int core_same_state(const dmi_solver *a, const dmi_solver *b);

/* 1 iff dmi_state_save(s) gives exactly bytes[0..size-1]. */
int core_state_is(const dmi_solver *s, const unsigned char *bytes, size_t size);

/* The state of s (n components, N steps per tau, delay tau; initialised)
 * in format version 1, as libdmi 1.0 wrote it (src/dmi.c of the 1.0.0
 * release, 5cd99de; written here from that layout, not with bytes.h): 8
 * uint64 words magic "DMISTATE", 1, n, N, bits of tau, p, p != 0, FNV-1a 64
 * of all bytes with this word zero; then (N + 1) n doubles U_j^{p-lag}
 * (lag-major), n doubles W^{p-1}, n doubles X^{p-1} (zeros before a step).
 * Caller frees; NULL on failure. */
unsigned char *core_state_v1(const dmi_solver *s, size_t n, size_t N, double tau, size_t *size);

/* ---- the fault-injection model ----------------------------------------------
 * n = 2, u' + A u + f(t, u) + int_0^tau H(s) u(t - s) ds = 0 with
 *   f(t, u) = (0.3 u0 - u1 + sin t, u0 + 0.1 u1 - 0.5 cos 2t),
 *   H(s)    = [[0.2 cos s, -0.1], [0.4 s, 0.3 - s]],   z(t) = (cos t, 0.5 + sin t),
 *   A       = diag(1, 2) (linear; resolvent x_i / (1 + lambda c_i)).
 * Each callback can be told to misbehave once it has been called more than
 * fail_after times: return nonzero, or write a NaN / +Inf / -Inf.
 */
enum { CB_RHS, CB_RESOLVENT, CB_KERNEL, CB_HISTORY, CB_KINDS };
enum { FAULT_NONE, FAULT_RETURN, FAULT_NAN, FAULT_INF, FAULT_NEGINF };

typedef struct {
    int fault[CB_KINDS];
    long fail_after[CB_KINDS];
    long calls[CB_KINDS];
} core_model;

int core_rhs(double t, const double *u, double *out, void *user);
int core_resolvent(double lambda, const double *x, double *out, void *user);
int core_kernel(double s, double *out, void *user);
int core_history(double t, double *out, void *user);

/* Sets every callback of the model on s (resolvent included). */
int core_model_setup(dmi_solver *s, core_model *m);

/* A new initialised solver (n = 2, tau = 1) of the model, or NULL. */
dmi_solver *core_model_solver(core_model *m, size_t N);

#endif
