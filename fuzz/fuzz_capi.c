/*
 * libFuzzer target: the C API's create / set / init / step / save / load
 * sequence driven by the fuzzer's bytes (kernels as callbacks or as
 * exponential terms, dmi_set_kernel_exp, every method; the cell rule, near
 * cells and the exponent of dmi_set_kernel_singularity with extreme kernels:
 * powers s^-alpha up to and beyond 1, jumps inside cells, huge, infinite or
 * NaN scales, 1/(s ln^2 s), failures close to 0).  The sizes, tau, every setter's
 * arguments (raw doubles included: NaN, Inf, subnormals), the callbacks'
 * misbehaviour (fail, NaN, +-Inf, huge values) and the order of calls come
 * from the input.  Besides the sanitizers, it aborts on a broken contract:
 * an unknown return code, a failed call that changed the solver, a state that
 * is not finite after a successful step, an empty error message.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "capi_model.h"
#include "dmi.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct {
    const uint8_t *p;
    size_t left;
} input;

static uint8_t byte(input *in)
{
    if (!in->left)
        return 0;
    in->left--;
    return *in->p++;
}

static double raw_double(input *in)
{
    uint64_t bits = 0;
    for (int i = 0; i < 8; i++)
        bits = bits << 8 | byte(in);
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

/* A double that is usually tame, sometimes anything. */
static double value(input *in)
{
    static const double tame[] = {0.0, 1.0, -1.0, 0.5, 2.0, 1e-3, 1e300, -0.0, INFINITY,
                                  -INFINITY};
    uint8_t k = byte(in);
    if (k < 200)
        return tame[k % (sizeof tame / sizeof tame[0])];
    return raw_double(in);
}

/* An extreme kernel (every entry alike): c s^-alpha, c on [0, jump) and 0
 * beyond, c / (s ln^2 s), or c s^-alpha failing below s = 1e-30. */
typedef struct {
    size_t nn;
    int kind;
    double c, alpha, jump;
} extreme;

static int extreme_kernel(double s, double *out, void *user)
{
    const extreme *e = user;
    double v;
    switch (e->kind) {
    case 0:
        v = e->c * pow(s, -e->alpha);
        break;
    case 1:
        v = s < e->jump ? e->c : 0.0;
        break;
    case 2: {
        const double l = log(s);
        v = e->c / (s * l * l);
        break;
    }
    default:
        if (s < 1e-30)
            return 5;
        v = e->c * pow(s, -e->alpha);
    }
    for (size_t q = 0; q < e->nn; q++)
        out[q] = v;
    return 0;
}

static void must(int ok)
{
    if (!ok)
        abort();
}

static void check_code(dmi_solver *s, int rc)
{
    must(rc <= DMI_OK && rc >= DMI_ESTATE);
    if (rc != DMI_OK)
        must(dmi_last_error(s) != NULL && (s == NULL || dmi_last_error(s)[0] != '\0'));
}

/* The observable time-stepping state of s, as bytes (NULL before init). */
static unsigned char *snapshot(dmi_solver *s, size_t *size, uint64_t *p)
{
    *size = 0;
    *p = UINT64_MAX;
    if (dmi_get_step_index(s, p) != DMI_OK)
        return NULL;
    *size = dmi_state_size(s);
    unsigned char *b = malloc(*size);
    must(b != NULL);
    must(dmi_state_save(s, b, *size) == DMI_OK);
    return b;
}

/* A failed call must leave the solver as it was. */
static void same(dmi_solver *s, const unsigned char *before, size_t size, uint64_t p)
{
    size_t size2;
    uint64_t p2;
    unsigned char *after = snapshot(s, &size2, &p2);
    must(p2 == p && size2 == size);
    must(size == 0 || memcmp(before, after, size) == 0);
    free(after);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input in = {data, size};
    uint8_t k = byte(&in);
    size_t n = k % 4 == 3 ? 1 + byte(&in) % 3 : MODEL_n; /* the model callbacks need n = 2 */
    size_t N = 1 + (byte(&in) | (size_t)byte(&in) << 8) % (k & 4 ? 1200 : 300); /* FFT from ~400 */
    double tau = byte(&in) < 224 ? 0.25 + byte(&in) / 64.0 : raw_double(&in);
    model m;
    model_default(&m);
    dmi_solver *s = NULL;
    /* (libdmi 1.2) or a step h that need not divide tau: N + 0..255/256 steps per tau */
    int rc = k & 8 ? dmi_create_h(&s, n, tau, tau / ((double)N + byte(&in) / 256.0))
                   : dmi_create(&s, n, tau, N);
    check_code(NULL, rc);
    must((rc == DMI_OK) == (s != NULL));
    if (!s)
        return 0;
    must(dmi_get_N(s) == N || (k & 8 && dmi_get_N(s) == N + 1));
    N = dmi_get_N(s);
    double *u = calloc(2 * n, sizeof *u);
    must(u != NULL);
    extreme ek = {n * n, 0, 1.0, 0.5, 0.3};
    for (int ops = 0; ops < 64 && in.left; ops++) {
        uint8_t op = byte(&in);
        size_t ssize;
        uint64_t p;
        unsigned char *before = snapshot(s, &ssize, &p);
        int stateful = 0; /* whether a failure must leave the state unchanged */
        switch (op % 20) {
        case 0:
            rc = dmi_set_rhs(s, n == MODEL_n && byte(&in) % 4 ? model_rhs : NULL, &m);
            break;
        case 1:
            rc = dmi_set_resolvent(s, n == MODEL_n && byte(&in) % 4 ? model_resolvent : NULL, &m);
            break;
        case 2: {
            double a[3];
            for (size_t i = 0; i < n; i++)
                a[i] = value(&in);
            rc = dmi_set_friction(s, byte(&in) == 255 ? NULL : a);
            break;
        }
        case 3: {
            double lo[3], hi[3];
            for (size_t i = 0; i < n; i++) {
                lo[i] = value(&in);
                hi[i] = value(&in);
            }
            rc = dmi_set_box(s, lo, hi);
            break;
        }
        case 4: {
            uint8_t how = byte(&in);
            if (how % 4 != 1) {
                rc = dmi_set_kernel(s, n == MODEL_n && how % 4 ? model_kernel : NULL, &m);
                break;
            }
            /* exponential terms (libdmi 1.1): K = 0..4, values from the
             * input, any of a, b, C, D missing */
            double a[4], b[4], C[4 * 9], D[4 * 9];
            size_t K = byte(&in) % 5;
            for (size_t t = 0; t < K; t++) {
                a[t] = -fabs(value(&in)) * (byte(&in) < 240 ? 1 : -1); /* mostly not growing */
                b[t] = value(&in);
                for (size_t q = 0; q < n * n; q++) {
                    C[t * n * n + q] = value(&in);
                    D[t * n * n + q] = value(&in);
                }
            }
            uint8_t miss = byte(&in);
            rc = dmi_set_kernel_exp(s, K, miss == 1 ? NULL : a, miss == 2 ? NULL : b,
                                    miss == 3 ? NULL : C, miss % 2 ? NULL : D);
            stateful = 1;
            break;
        }
        case 5:
            rc = dmi_set_history(s, n == MODEL_n && byte(&in) % 4 ? model_history : NULL, &m);
            break;
        case 6:
            rc = dmi_set_convolution(s, (int8_t)byte(&in) % 5);
            break;
        case 7:
            rc = dmi_init(s);
            stateful = 1;
            break;
        case 8:
        case 9:
        case 10:
            rc = dmi_step(s);
            stateful = 1;
            if (rc == DMI_OK) {
                must(dmi_get_state(s, u) == DMI_OK);
                for (size_t i = 0; i < n; i++)
                    must(isfinite(u[i]));
            }
            break;
        case 11:
            rc = dmi_advance(s, byte(&in) % 8);
            break;
        case 12: {
            size_t lag = byte(&in);
            rc = dmi_get_past(s, lag, u);
            must(rc != DMI_OK || lag <= N);
            break;
        }
        case 13: {
            rc = dmi_get_step_terms(s, u, u + n);
            must(dmi_time(s) >= 0 && dmi_get_h(s) > 0);
            break;
        }
        case 14: { /* save, maybe corrupt or cut, load */
            size_t len = dmi_state_size(s);
            unsigned char *b = calloc(len + 1, 1);
            must(b != NULL);
            rc = dmi_state_save(s, b, len);
            if (rc == DMI_OK) {
                uint8_t how = byte(&in);
                if (how % 4 == 1)
                    b[byte(&in) % len] ^= (uint8_t)(1 + byte(&in) % 255);
                if (how % 4 == 2)
                    len -= 1 + byte(&in) % len;
                if (how % 4 == 3)
                    len++;
                rc = dmi_state_load(s, b, len);
                must(how % 4 == 0 ? rc == DMI_OK : rc == DMI_EINVAL);
            }
            free(b);
            stateful = 1;
            break;
        }
        case 15: { /* make a callback misbehave from some call on */
            cb_ctl *c[4] = {&m.rhs, &m.resolvent, &m.kernel, &m.history};
            cb_ctl *t = c[byte(&in) % 4];
            t->mode = byte(&in) % (CB_NEGHUGE + 1);
            t->from = t->calls + byte(&in) % 8;
            t->comp = byte(&in) % 2;
            rc = DMI_OK;
            break;
        }
        case 16: /* (libdmi 1.3) the rule: left, cell, or unknown */
            rc = dmi_set_quadrature(s, (int)(byte(&in) % 4) - 1);
            break;
        case 17: /* an extreme kernel (its parameters also seen by near cells) */
        case 18: {
            ek.kind = byte(&in) % 4;
            const uint8_t scale = byte(&in);
            ek.c = scale < 128 ? 1.0 : scale < 192 ? 1e307 : value(&in);
            ek.alpha = byte(&in) / 200.0; /* 0 .. 1.275: integrable or not */
            ek.jump = tau * byte(&in) / 255.0;
            if (op % 20 == 17)
                rc = dmi_set_kernel(s, byte(&in) % 8 ? extreme_kernel : NULL, &ek);
            else /* (libdmi 1.3) near cells below delta */
                rc = dmi_set_kernel_near(s, byte(&in) % 8 ? extreme_kernel : NULL, &ek,
                                         byte(&in) < 200 ? tau * byte(&in) / 255.0 : value(&in));
            break;
        }
        case 19: /* (libdmi 1.4) the exponent at 0: in [0, 1), NaN, or anything */
            rc = dmi_set_kernel_singularity(s, byte(&in) < 128 ? byte(&in) / 256.0
                                                                : byte(&in) < 64 ? NAN
                                                                                 : value(&in));
            break;
        }
        check_code(s, rc);
        if (stateful && rc != DMI_OK)
            same(s, before, ssize, p);
        free(before);
    }
    free(u);
    dmi_free(&s);
    must(s == NULL);
    return 0;
}
