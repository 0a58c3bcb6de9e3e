/*
 * Threads: dmi.h promises that distinct solvers may run at
 * once on distinct threads, and co-simulation masters step FMU instances on
 * parallel threads.  THREADS threads start together (a barrier); thread i runs
 * Example 4.3 with N = 100 (i + 1) under every method of the delay sum, each
 * on a solver of its own, then an FMU instance of its own (the unpacked
 * binary, loaded with dlopen) with the same N.  Every trajectory (w, v after
 * each step) must equal, bitwise, that of the same run done first in the main
 * thread alone (and each serial solver run must agree with DIRECT's to
 * 1e-10, so that every method really runs Example 4.3).  Run in the ThreadSanitizer build by scripts/test.sh, where a
 * data race stops the program (TSAN_OPTIONS=halt_on_error=1); in the other
 * builds it checks the bitwise equality alone.
 *
 * Usage: test_threads FMU.so GUID [threads]   (default 8 threads)
 * Exit status 0 if every trajectory matched, 1 if not, 2 for bad arguments.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_loader.h"
#include "paper.h"

/* The methods of the delay sum: every one runs on every thread (a new
 * method is one more line here).  exp: the kernel given to
 * dmi_set_kernel_exp (RECURSIVE needs it) instead of as a callback. */
static const struct {
    int method, exp;
    const char *name;
} METHODS[] = {
    {DMI_CONV_AUTO, 0, "AUTO"},
    {DMI_CONV_DIRECT, 0, "DIRECT"},
    {DMI_CONV_FFT, 0, "FFT"},
    {DMI_CONV_AUTO, 1, "AUTO, exponential kernel"},
    {DMI_CONV_RECURSIVE, 1, "RECURSIVE"},
};
enum { N_METHODS = sizeof METHODS / sizeof METHODS[0], MAX_THREADS = 64 };

/* FMU value references (its modelDescription.xml) and the FMU run. */
enum { VR_w = 19, VR_v = 20, VR_N = 23 };
static const double T = 30.0, FMU_DT = 0.01;

/* One run's trajectory: (w, v) after each step, or an error. */
typedef struct {
    double *wv;
    size_t steps;
    int failed;
} trajectory;

/* One thread's work: the solvers (one per method) and the FMU instance. */
typedef struct {
    size_t N;
    const fmu_api *fmu;
    const char *guid;
    pthread_barrier_t *start; /* NULL in the serial run */
    trajectory solver[N_METHODS], fmu_run;
} job;

/* Example 4.3 with h = 1/N to T under one method. */
static trajectory run_solver(size_t N, int method, int exp)
{
    trajectory r = {NULL, (size_t)llround(T * (double)N), 1};
    paper_example ex = {43};
    dmi_solver *s = NULL;
    r.wv = malloc(2 * r.steps * sizeof *r.wv);
    int rc = r.wv ? dmi_create(&s, 2, 1.0, N) : DMI_ENOMEM;
    if (rc == DMI_OK)
        rc = paper_setup(s, &ex);
    if (rc == DMI_OK && exp)
        rc = paper_set_kernel_exp43(s);
    if (rc == DMI_OK)
        rc = dmi_set_convolution(s, method);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    for (size_t p = 0; p < r.steps && rc == DMI_OK; p++) {
        rc = dmi_step(s);
        if (rc == DMI_OK)
            rc = dmi_get_state(s, r.wv + 2 * p);
    }
    if (rc != DMI_OK)
        fprintf(stderr, "test_threads: N = %zu, method %d%s: %s\n", N, method, exp ? " (exp)" : "",
                s ? dmi_last_error(s) : dmi_strerror(rc));
    r.failed = rc != DMI_OK;
    dmi_free(&s);
    return r;
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list ap;
    (void)env;
    if (status == fmi2OK)
        return;
    flockfile(stderr); /* one message per line, whichever thread logs */
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
    funlockfile(stderr);
}

/* The FMU with parameter N to T in communication steps of FMU_DT. */
static trajectory run_fmu(const fmu_api *f, const char *guid, size_t N)
{
    trajectory r = {NULL, (size_t)llround(T / FMU_DT), 1};
    const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    const fmi2ValueReference vr_N = VR_N, vr_wv[2] = {VR_w, VR_v};
    const fmi2Integer n_value = (fmi2Integer)N;
    r.wv = malloc(2 * r.steps * sizeof *r.wv);
    fmi2Component c = r.wv ? f->instantiate("thread", fmi2CoSimulation, guid, "", &cb, fmi2False,
                                            fmi2False)
                           : NULL;
    int ok = c && f->setup(c, fmi2False, 0.0, 0.0, fmi2True, T) == fmi2OK &&
             f->enter_init(c) == fmi2OK && f->set_integer(c, &vr_N, 1, &n_value) == fmi2OK &&
             f->exit_init(c) == fmi2OK;
    for (size_t k = 0; k < r.steps && ok; k++)
        ok = f->do_step(c, (double)k * FMU_DT, FMU_DT, fmi2True) == fmi2OK &&
             f->get_real(c, vr_wv, 2, r.wv + 2 * k) == fmi2OK;
    if (!ok)
        fprintf(stderr, "test_threads: the FMU with N = %zu failed\n", N);
    if (c) {
        f->terminate(c);
        f->free_instance(c);
    }
    r.failed = !ok;
    return r;
}

static void *work(void *arg)
{
    job *j = arg;
    if (j->start)
        pthread_barrier_wait(j->start);
    for (size_t m = 0; m < N_METHODS; m++)
        j->solver[m] = run_solver(j->N, METHODS[m].method, METHODS[m].exp);
    j->fmu_run = run_fmu(j->fmu, j->guid, j->N);
    return NULL;
}

/* 0 if the two runs both succeeded and are bitwise equal, else 1 (message). */
static int compare(const trajectory *serial, const trajectory *par, size_t thread, const char *what)
{
    if (serial->failed || par->failed) {
        fprintf(stderr, "FAILED: thread %zu, %s: a run failed\n", thread, what);
        return 1;
    }
    if (memcmp(serial->wv, par->wv, 2 * serial->steps * sizeof *serial->wv) != 0) {
        size_t p = 0;
        while (memcmp(serial->wv + p, par->wv + p, sizeof *serial->wv) == 0)
            p++;
        fprintf(stderr, "FAILED: thread %zu, %s: step %zu differs (%.17g serial, %.17g in the thread)\n",
                thread, what, p / 2 + 1, serial->wv[p], par->wv[p]);
        return 1;
    }
    return 0;
}

/* 0 if the serial run of method m is within 1e-10 max|U| of DIRECT's with
 * the kernel as a callback (the plain sum; measured: 6e-16), else 1. */
static int near_direct(const job *j, size_t m)
{
    size_t d = 0;
    while (METHODS[d].method != DMI_CONV_DIRECT || METHODS[d].exp)
        d++;
    const trajectory *x = &j->solver[m], *ref = &j->solver[d];
    double dev = 0, big = 0;
    for (size_t k = 0; !x->failed && !ref->failed && k < 2 * x->steps; k++) {
        dev = fmax(dev, fabs(x->wv[k] - ref->wv[k]));
        big = fmax(big, fabs(ref->wv[k]));
    }
    if (x->failed || ref->failed || !(dev <= 1e-10 * big) || !(big > 0)) {
        fprintf(stderr, "FAILED: N = %zu, %s: max deviation %.3g from DIRECT (max |U| %.3g)\n",
                j->N, METHODS[m].name, dev, big);
        return 1;
    }
    return 0;
}

static void release(job *j)
{
    for (size_t m = 0; m < N_METHODS; m++)
        free(j->solver[m].wv);
    free(j->fmu_run.wv);
}

int main(int argc, char **argv)
{
    size_t threads = 8;
    if (argc < 3 || argc > 4 || (argc == 4 && (sscanf(argv[3], "%zu", &threads) != 1 ||
                                                threads < 1 || threads > MAX_THREADS))) {
        fprintf(stderr, "usage: test_threads FMU.so GUID [threads (1..%d, default 8)]\n",
                MAX_THREADS);
        return 2;
    }
    fmu_api f;
    if (fmu_load(&f, argv[1]) != 0)
        return 1;
    static job serial[MAX_THREADS], par[MAX_THREADS];
    pthread_t tid[MAX_THREADS];
    pthread_barrier_t start;
    int failed = pthread_barrier_init(&start, NULL, (unsigned)threads) != 0;
    for (size_t i = 0; i < threads; i++) { /* the serial runs first, in this thread */
        serial[i] = (job){.N = 100 * (i + 1), .fmu = &f, .guid = argv[2], .start = NULL};
        par[i] = serial[i];
        par[i].start = &start;
        work(&serial[i]);
    }
    for (size_t i = 0; i < threads; i++) /* each run is Example 4.3 (a check of the test) */
        for (size_t m = 0; m < N_METHODS; m++)
            failed |= near_direct(&serial[i], m);
    size_t started = 0;
    while (!failed && started < threads &&
           pthread_create(&tid[started], NULL, work, &par[started]) == 0)
        started++;
    if (started < threads) { /* the barrier would wait for ever: not a test result */
        fprintf(stderr, "test_threads: could not start %zu threads\n", threads);
        return 1;
    }
    for (size_t i = 0; i < threads; i++)
        pthread_join(tid[i], NULL);
    pthread_barrier_destroy(&start);
    for (size_t i = 0; i < threads; i++) {
        for (size_t m = 0; m < N_METHODS; m++)
            failed |= compare(&serial[i].solver[m], &par[i].solver[m], i, METHODS[m].name);
        failed |= compare(&serial[i].fmu_run, &par[i].fmu_run, i, "FMU");
        release(&serial[i]);
        release(&par[i]);
    }
    fmu_unload(&f);
    printf("test_threads: %zu threads, each %d method runs (N = 100..%zu, T = %g) and an FMU: %s\n",
           threads, (int)N_METHODS, 100 * threads, T, failed ? "FAILED" : "bitwise equal to serial runs");
    return failed;
}
