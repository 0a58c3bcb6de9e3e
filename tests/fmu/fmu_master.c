/*
 * fmu_master — a small FMI 2.0 co-simulation master, a second importer beside
 * fmpy: loads the unpacked FMU binary with dlopen, runs Example 4.3 at
 * N = 9991 and compares w, v at the reference's points (every 100th step,
 * values computed by an independent implementation) to 1e-12; checks on the
 * way that a saved FMU state, serialized and restored, replays bitwise; then
 * runs the error paths on a second instance (invalid parameters, calls out of
 * sequence, a zero step, truncated state bytes, reset), so that they run under the
 * sanitizers too.
 *
 * Usage: fmu_master FMU.so GUID ex43_N9991.csv T [outputs.csv]
 * With outputs.csv: writes p, w, v at each compared point (%.17g), for the
 * comparison of two builds (the Windows DLL under Wine against the Linux .so).
 * Built for Linux and, unchanged, for Windows (mingw-w64; fmu_loader.c).
 * Exit status 0 if every check passed.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_loader.h"

/* Value references VR_* of the FMU (fmu/config.h, as its modelDescription.xml). */
#include "model.h"
static const int N = 9991;
static const double TOL = 1e-12;


static int failures = 0;

static void check(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "fmu_master: FAILED: %s\n", what);
        failures++;
    }
}

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list ap;
    (void)env;
    fprintf(stderr, "[%s %d %s] ", name, (int)status, category);
    va_start(ap, message);
    vfprintf(stderr, message, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* The reference rows: step index p and w, v at t_p. */
typedef struct {
    long p;
    double w, v;
} row;

/* A second instance through the error paths, rows of docs/bad-inputs.md
 * among them (their logged reasons, printed by the logger, are compared with
 * the table by tests/wine): each call must give fmi2Error and leave the
 * instance usable. */
static void error_paths(const fmu_api *f, const char *guid, const fmi2CallbackFunctions *cb)
{
    fmi2Component c = f->instantiate("errors", fmi2CoSimulation, guid, "", cb, fmi2False,
                                     fmi2False);
    const fmi2ValueReference vr_tau = VR_tau, vr_N = VR_N, vr_wv[2] = {VR_w, VR_v}, vr_999 = 999;
    const fmi2Real bad_tau[3] = {-1.0, NAN, INFINITY}, one = 1.0;
    const fmi2Integer bad_N[2] = {0, INT_MIN};
    const fmi2String nonsense = "nonsense";
    double wv[2];
    check(c != NULL, "second fmi2Instantiate");
    if (!c)
        return;
    check(f->instantiate("x", fmi2CoSimulation, "{00000000-0000-0000-0000-000000000000}", "", cb,
                         fmi2False, fmi2False) == NULL,
          "wrong GUID refused"); /* F06 */
    check(f->do_step(c, 0.0, 0.1, fmi2False) == fmi2Error, "doStep before initialization"); /* F50 */
    check(f->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK, "setup");
    check(f->enter_init(c) == fmi2OK, "enter initialization");
    for (int i = 0; i < 3; i++) /* F11, F12, F13 */
        check(f->set_real(c, &vr_tau, 1, &bad_tau[i]) == fmi2Error, "tau = -1, NaN, Inf refused");
    for (int i = 0; i < 2; i++) /* F25, F27 */
        check(f->set_integer(c, &vr_N, 1, &bad_N[i]) == fmi2Error, "N = 0, INT_MIN refused");
    check(f->set_real(c, &vr_999, 1, &one) == fmi2Error, "unknown value reference"); /* F33 */
    check(f->set_debug_logging(c, fmi2True, 1, &nonsense) == fmi2Error,
          "unknown log category"); /* F65 */
    if (f->version == 2) /* F64; FMI 3.0 has no fmi3CancelStep */
        check(f->cancel_step(c) == fmi2Error, "fmi2CancelStep");
    check(f->exit_init(c) == fmi2OK, "exit initialization after refused values");
    check(f->do_step(c, 0.5, 0.1, fmi2False) == fmi2Error, "doStep from a wrong time");
    check(f->do_step(c, 0.0, 0.0, fmi2False) == fmi2Error, "zero step refused");
    check(f->do_step(c, 0.0, 0.1, fmi2False) == fmi2OK, "doStep");
    fmi2FMUstate st = NULL;
    size_t size = 0;
    check(f->get_state(c, &st) == fmi2OK && f->state_size(c, st, &size) == fmi2OK, "get state");
    fmi2Byte *bytes = malloc(size);
    if (bytes && f->serialize(c, st, bytes, size) == fmi2OK) {
        fmi2FMUstate bad = NULL;
        check(f->deserialize(c, bytes, size - 1, &bad) == fmi2Error, "truncated state refused");
        check(f->deserialize(c, bytes, 20, &bad) == fmi2Error, "short state refused"); /* F87 */
    }
    free(bytes);
    f->free_state(c, &st);
    check(f->reset(c) == fmi2OK, "reset");
    check(f->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK &&
              f->enter_init(c) == fmi2OK && f->exit_init(c) == fmi2OK &&
              f->do_step(c, 0.0, 0.1, fmi2False) == fmi2OK &&
              f->get_real(c, vr_wv, 2, wv) == fmi2OK,
          "a new experiment after reset");
    f->free_instance(c);
}

static row *read_reference(const char *path, size_t *count)
{
    FILE *in = fopen(path, "r");
    char line[256];
    size_t n = 0, cap = 4096;
    row *rows = malloc(cap * sizeof *rows);
    if (!in || !rows || !fgets(line, sizeof line, in)) {
        if (in)
            fclose(in);
        free(rows);
        return NULL;
    }
    double t;
    while (n < cap && fscanf(in, "%ld,%lf,%lf,%lf", &rows[n].p, &t, &rows[n].w, &rows[n].v) == 4)
        n++;
    fclose(in);
    *count = n;
    return rows;
}

int main(int argc, char **argv)
{
    if (argc != 5 && argc != 6) {
        fprintf(stderr, "usage: fmu_master FMU.so GUID ex43_N9991.csv T [outputs.csv]\n");
        return 2;
    }
    FILE *out = argc == 6 ? fopen(argv[5], "w") : NULL;
    if (argc == 6 && !out) {
        fprintf(stderr, "fmu_master: cannot write %s\n", argv[5]);
        return 1;
    }
    const double T = atof(argv[4]), h = 1.0 / N;
    size_t nrows = 0;
    row *ref = read_reference(argv[3], &nrows);
    fmu_api f;
    if (!ref || nrows < 2 || fmu_load(&f, argv[1]) != 0) {
        fprintf(stderr, "fmu_master: cannot read %s or load %s\n", argv[3], argv[1]);
        return 1;
    }
    const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = f.instantiate("master", fmi2CoSimulation, argv[2], "", &cb, fmi2False,
                                    fmi2False);
    const fmi2ValueReference vr_N = VR_N, vr_wv[2] = {VR_w, VR_v};
    const fmi2Integer n_value = N;
    check(c != NULL, "fmi2Instantiate");
    if (!c)
        return 1;
    check(f.setup(c, fmi2False, 0.0, 0.0, fmi2True, T) == fmi2OK, "fmi2SetupExperiment");
    check(f.enter_init(c) == fmi2OK, "fmi2EnterInitializationMode");
    check(f.set_integer(c, &vr_N, 1, &n_value) == fmi2OK, "fmi2SetInteger N");
    check(f.exit_init(c) == fmi2OK, "fmi2ExitInitializationMode");

    double t = 0.0, maxdev = 0.0, wv[2];
    size_t compared = 0;
    fmi2FMUstate saved = NULL;
    double saved_t = 0.0, replay[2] = {0, 0};
    size_t k;
    for (k = 0; k < nrows && ref[k].p * h <= T + 1e-9; k++) {
        const double t_next = (double)ref[k].p / N; /* the reference's t_p */
        if (k > 0)
            check(f.do_step(c, t, t_next - t, fmi2False) == fmi2OK, "fmi2DoStep");
        t = t_next;
        check(f.get_real(c, vr_wv, 2, wv) == fmi2OK, "fmi2GetReal");
        const double dev = fmax(fabs(wv[0] - ref[k].w), fabs(wv[1] - ref[k].v));
        maxdev = fmax(maxdev, dev);
        compared++;
        if (out)
            fprintf(out, "%ld,%.17g,%.17g\n", ref[k].p, wv[0], wv[1]);
        if (k == nrows / 20) { /* save the state here, check it replays below */
            check(f.get_state(c, &saved) == fmi2OK, "fmi2GetFMUstate");
            saved_t = t;
        }
        if (k == nrows / 20 + 5)
            memcpy(replay, wv, sizeof wv);
    }
    check(maxdev <= TOL, "w, v equal the reference values to 1e-12");
    check(compared > 5, "enough reference points");

    /* serialize, deserialize, restore: the same five communication steps again */
    if (saved) {
        size_t size = 0;
        check(f.state_size(c, saved, &size) == fmi2OK && size > 0, "fmi2SerializedFMUstateSize");
        fmi2Byte *bytes = malloc(size);
        fmi2FMUstate back = NULL;
        check(bytes && f.serialize(c, saved, bytes, size) == fmi2OK, "fmi2SerializeFMUstate");
        check(bytes && f.deserialize(c, bytes, size, &back) == fmi2OK, "fmi2DeSerializeFMUstate");
        if (bytes && size > 100) { /* a corrupted copy is refused */
            fmi2FMUstate bad = NULL;
            bytes[size / 2] ^= 1;
            check(f.deserialize(c, bytes, size, &bad) == fmi2Error && bad == NULL,
                  "corrupted state rejected");
        }
        free(bytes);
        check(back && f.set_state(c, back) == fmi2OK, "fmi2SetFMUstate");
        size_t k0 = nrows / 20;
        t = saved_t;
        for (size_t j = k0 + 1; j <= k0 + 5 && j < nrows; j++) {
            const double t_next = (double)ref[j].p / N;
            check(f.do_step(c, t, t_next - t, fmi2False) == fmi2OK, "fmi2DoStep after restore");
            t = t_next;
        }
        check(f.get_real(c, vr_wv, 2, wv) == fmi2OK, "fmi2GetReal after restore");
        check(k > k0 + 5 ? wv[0] == replay[0] && wv[1] == replay[1] : 1,
              "restored state replays bitwise");
        f.free_state(c, &saved);
        f.free_state(c, &back);
    }
    error_paths(&f, argv[2], &cb);
    check(f.terminate(c) == fmi2OK, "fmi2Terminate");
    f.free_instance(c);
    fmu_unload(&f);
    free(ref);
    check(!out || fclose(out) == 0, "outputs written");
    printf("fmu_master: %zu reference points to t = %g, max deviation %.3g; %d failures\n",
           compared, T, maxdev, failures);
    return failures == 0 ? 0 : 1;
}
