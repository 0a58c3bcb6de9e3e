/*
 * dmi_state_save / dmi_state_load: a run replayed from a loaded
 * state is bitwise the run of the saving solver; states of other solvers
 * (n, N, tau), truncated, corrupted or foreign bytes are refused with
 * DMI_EINVAL and leave the solver unchanged.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bytes.h" /* the state's layout (src/) */
#include "core_test.h"

enum { N = 16, SAVED_AT = 37, MORE = 25 }; /* SAVED_AT > N: the ring has wrapped */

/* A model solver (n = 2, N = 16, tau = 1) after steps steps. */
static dmi_solver *model_after(core_model *m, size_t steps)
{
    dmi_solver *s = core_model_solver(m, N);
    if (s && dmi_advance(s, steps) != DMI_OK)
        dmi_free(&s);
    return s;
}

static void test_replay(void)
{
    core_model ma = {0}, mb = {0}, mc = {0};
    dmi_solver *a = model_after(&ma, SAVED_AT), *b = model_after(&mb, 5), *c = model_after(&mc, 0);
    CU_ASSERT_FATAL(a && b && c);
    size_t size;
    unsigned char *saved = core_save(a, &size);
    CU_ASSERT_PTR_NOT_NULL_FATAL(saved);
    CU_ASSERT_EQUAL(size, dmi_state_size(b));
    double Wa[2], Xa[2], Wb[2], Xb[2], ua[2], ub[2];
    CU_ASSERT_EQUAL(dmi_get_step_terms(a, Wa, Xa), DMI_OK);

    /* into a solver ahead of or behind the saved point, and into one never stepped */
    CU_ASSERT_EQUAL(dmi_state_load(b, saved, size), DMI_OK);
    CU_ASSERT_EQUAL(dmi_state_load(c, saved, size), DMI_OK);
    uint64_t p = 0;
    CU_ASSERT_EQUAL(dmi_get_step_index(b, &p), DMI_OK);
    CU_ASSERT_EQUAL(p, SAVED_AT);
    CU_ASSERT_EQUAL(dmi_time(b), dmi_time(a));
    CU_ASSERT_EQUAL(dmi_get_step_terms(b, Wb, Xb), DMI_OK);
    CU_ASSERT(memcmp(Wa, Wb, sizeof Wa) == 0 && memcmp(Xa, Xb, sizeof Xa) == 0);
    int past_same = 1;
    for (size_t lag = 0; lag <= N; lag++)
        past_same &= dmi_get_past(a, lag, ua) == DMI_OK && dmi_get_past(b, lag, ub) == DMI_OK &&
                     memcmp(ua, ub, sizeof ua) == 0;
    CU_ASSERT(past_same);
    CU_ASSERT(core_state_is(b, saved, size));

    CU_ASSERT_EQUAL(dmi_advance(a, MORE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(b, MORE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(c, MORE), DMI_OK);
    CU_ASSERT(core_same_state(a, b));
    CU_ASSERT(core_same_state(a, c));
    CU_ASSERT(!core_state_is(a, saved, size)); /* the run did move on */

    /* rewinding the saving solver itself replays the same run */
    size_t size_end;
    unsigned char *end = core_save(a, &size_end);
    CU_ASSERT_EQUAL(dmi_state_load(a, saved, size), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(a, MORE), DMI_OK);
    CU_ASSERT(core_state_is(a, end, size_end));

    /* buffers need no alignment */
    unsigned char *odd = malloc(size + 1);
    CU_ASSERT_PTR_NOT_NULL_FATAL(odd);
    CU_ASSERT_EQUAL(dmi_state_save(b, odd + 1, size), DMI_OK);
    CU_ASSERT_EQUAL(dmi_state_load(c, odd + 1, size), DMI_OK);
    CU_ASSERT(core_same_state(b, c));
    /* a larger buffer is fine for saving */
    unsigned char *large = calloc(size + 64, 1);
    CU_ASSERT_PTR_NOT_NULL_FATAL(large);
    CU_ASSERT_EQUAL(dmi_state_save(b, large, size + 64), DMI_OK);
    CU_ASSERT_EQUAL(dmi_state_load(c, large, size), DMI_OK);
    CU_ASSERT(core_same_state(b, c));

    free(large);
    free(odd);
    free(end);
    free(saved);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
}

/* The same with each method of the delay sum, at an N where the FFT engine
 * has blocks of several sizes: its rebuild from a loaded state must give the
 * engine of the uninterrupted run (bitwise), also when loaded into a solver
 * at an earlier or a later point. */
static void test_replay_methods(void)
{
    const int methods[] = {DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_AUTO};
    const size_t NB = 500, at = 1237, others[] = {0, 90, 1500, 1237}, more = 777;
    for (int m = 0; m < 3; m++) {
        core_model ma = {0};
        dmi_solver *a = core_model_solver(&ma, NB);
        CU_ASSERT_FATAL(a != NULL);
        CU_ASSERT_EQUAL(dmi_set_convolution(a, methods[m]), DMI_OK);
        CU_ASSERT_EQUAL(dmi_advance(a, at), DMI_OK);
        size_t size;
        unsigned char *saved = core_save(a, &size);
        CU_ASSERT_PTR_NOT_NULL_FATAL(saved);
        CU_ASSERT_EQUAL(dmi_advance(a, more), DMI_OK);
        for (size_t k = 0; k < sizeof others / sizeof *others; k++) {
            core_model mb = {0};
            dmi_solver *b = core_model_solver(&mb, NB);
            CU_ASSERT_FATAL(b != NULL);
            CU_ASSERT_EQUAL(dmi_set_convolution(b, methods[m]), DMI_OK);
            CU_ASSERT_EQUAL(dmi_advance(b, others[k]), DMI_OK);
            CU_ASSERT_EQUAL(dmi_state_load(b, saved, size), DMI_OK);
            CU_ASSERT_EQUAL(dmi_advance(b, more), DMI_OK);
            int same = core_same_state(a, b);
            if (!same)
                printf("\n  method %d: replay loaded at step %zu differs", methods[m], others[k]);
            CU_ASSERT(same);
            dmi_free(&b);
        }
        free(saved);
        dmi_free(&a);
    }
}

/* load must fail with DMI_EINVAL, a message, and leave s bitwise as before. */
static int refused(dmi_solver *s, const void *buf, size_t size, const unsigned char *before,
                   size_t before_size)
{
    int rc = dmi_state_load(s, buf, size);
    return rc == DMI_EINVAL && dmi_last_error(s)[0] != '\0' &&
           core_state_is(s, before, before_size);
}

static void test_refused(void)
{
    core_model ma = {0}, ms = {0};
    dmi_solver *a = model_after(&ma, SAVED_AT), *s = model_after(&ms, 11);
    CU_ASSERT_FATAL(a && s);
    size_t size, size_s;
    unsigned char *saved = core_save(a, &size), *before = core_save(s, &size_s);
    unsigned char *buf = malloc(size + 8);
    CU_ASSERT_FATAL(saved && before && buf);

    /* truncated, too long, empty, NULL */
    memcpy(buf, saved, size);
    buf[size] = 0;
    CU_ASSERT(refused(s, buf, size - 1, before, size_s));
    CU_ASSERT(refused(s, buf, size + 1, before, size_s));
    CU_ASSERT(refused(s, buf, 0, before, size_s));
    CU_ASSERT(refused(s, buf, 8, before, size_s));
    CU_ASSERT(refused(s, NULL, size, before, size_s));

    /* bad magic */
    memcpy(buf, saved, size);
    memset(buf, 'X', 8);
    CU_ASSERT(refused(s, buf, size, before, size_s));

    /* every single corrupted byte, anywhere (header, history, terms, checksum) */
    size_t accepted = 0;
    for (size_t i = 0; i < size; i++) {
        memcpy(buf, saved, size);
        buf[i] ^= 0x5A;
        accepted += !refused(s, buf, size, before, size_s);
        memcpy(buf, saved, size);
        buf[i] ^= 0x01; /* the lowest bit: the smallest change of a double */
        accepted += !refused(s, buf, size, before, size_s);
    }
    if (accepted)
        printf("\n  %zu corrupted states accepted", accepted);
    CU_ASSERT_EQUAL(accepted, 0);

    /* states of other solvers, of the same size (so the header is what tells) */
    const struct {
        size_t n, N;
        double tau;
    } other[] = {{1, 2 * N + 3, 1.0}, {2, N, 2.0}, {2, N, 1.0 + 1e-15}, {2, N + 1, 1.0},
                 {3, N, 1.0}};
    for (size_t k = 0; k < sizeof other / sizeof *other; k++) {
        dmi_solver *o = NULL;
        CU_ASSERT_EQUAL_FATAL(dmi_create(&o, other[k].n, other[k].tau, other[k].N), DMI_OK);
        CU_ASSERT_EQUAL_FATAL(dmi_init(o), DMI_OK);
        CU_ASSERT_EQUAL(dmi_advance(o, SAVED_AT), DMI_OK);
        size_t size_o;
        unsigned char *so = core_save(o, &size_o), *before_o = core_save(o, &size_o);
        CU_ASSERT_FATAL(so && before_o);
        if (k < 3) /* same byte count: the header check must catch it */
            CU_ASSERT_EQUAL(size_o, size);
        CU_ASSERT(refused(s, so, size_o, before, size_s));
        CU_ASSERT(refused(o, saved, size, before_o, size_o));
        free(so);
        free(before_o);
        dmi_free(&o);
    }

    /* after all that, s still runs like a twin that saw none of it */
    core_model mt = {0};
    dmi_solver *t = model_after(&mt, 11);
    CU_ASSERT_FATAL(t != NULL);
    CU_ASSERT_EQUAL(dmi_advance(s, MORE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(t, MORE), DMI_OK);
    CU_ASSERT(core_same_state(s, t));

    free(buf);
    free(saved);
    free(before);
    dmi_free(&a);
    dmi_free(&s);
    dmi_free(&t);
}

/* The model's solver with its kernel replaced by the exponential kernel
 * H(s) = [[exp(-s), 0.3], [0.5 cos(2 pi s), -0.2 exp(-3 s) cos(5 s)]] (summed
 * by the recursion), N = 16, initialised; NULL on failure. */
static dmi_solver *exp_solver(core_model *m)
{
    const double a[3] = {-1.0, 0.0, -3.0}, b[3] = {0.0, 6.283185307179586, 5.0};
    const double C[3 * 4] = {1.0, 0.3, 0, 0, /**/ 0, 0, 0.5, 0, /**/ 0, 0, 0, -0.2};
    dmi_solver *s = NULL;
    if (dmi_create(&s, 2, 1.0, N) != DMI_OK)
        return NULL;
    int rc = core_model_setup(s, m);
    if (rc == DMI_OK)
        rc = dmi_set_kernel_exp(s, 3, a, b, C, NULL);
    return core_init_or_free(s, rc);
}

/* A state of libdmi 1.0 (format version 1, no recursion sums), built from
 * that layout, loads since libdmi 1.2 (into a solver ahead, behind, or never
 * stepped) and the run goes on as the saving solver's: bitwise with the
 * model's callback kernel (the direct sum from the same stored states); with
 * an exponential kernel, whose recursion sums are rebuilt from the stored
 * states, to 1e-13 of the states' magnitude (rounding).  A version-1 state
 * with a byte changed, of another size, or loaded into a solver whose h is
 * not tau / N is refused, the solver unchanged. */
static void test_version_1(void)
{
    core_model ma = {0}, mb = {0}, mc = {0};
    dmi_solver *a = model_after(&ma, SAVED_AT), *b = model_after(&mb, 5), *c = model_after(&mc, 0);
    CU_ASSERT_FATAL(a && b && c);
    size_t size, size_b;
    unsigned char *v1 = core_state_v1(a, 2, N, 1.0, &size), *before_b = core_save(b, &size_b);
    CU_ASSERT_FATAL(v1 && before_b);
    CU_ASSERT_EQUAL(size, dmi_state_size(a) - DMI_STATE_REC_BYTES); /* no sums either way */

    unsigned char *bad = malloc(size + DMI_STATE_REC_BYTES);
    CU_ASSERT_FATAL(bad != NULL);
    memcpy(bad, v1, size);
    bad[size / 2] ^= 0x01;
    CU_ASSERT(refused(b, bad, size, before_b, size_b));
    memcpy(bad, v1, size);
    memset(bad + size, 0, DMI_STATE_REC_BYTES);
    CU_ASSERT(refused(b, bad, size - 8, before_b, size_b));
    CU_ASSERT(refused(b, bad, size + DMI_STATE_REC_BYTES, before_b, size_b));
    dmi_solver *h = NULL; /* h = 1/15.5: not tau / N, N = 16 cells */
    CU_ASSERT_EQUAL_FATAL(dmi_create_h(&h, 2, 1.0, 1.0 / 15.5), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(core_model_setup(h, &mc), DMI_OK);
    CU_ASSERT_EQUAL_FATAL(dmi_init(h), DMI_OK);
    CU_ASSERT_EQUAL(dmi_get_N(h), N);
    size_t size_h;
    unsigned char *before_h = core_save(h, &size_h);
    CU_ASSERT(refused(h, v1, size, before_h, size_h));

    CU_ASSERT_EQUAL(dmi_state_load(b, v1, size), DMI_OK);
    CU_ASSERT_EQUAL(dmi_state_load(c, v1, size), DMI_OK);
    uint64_t p = 0;
    CU_ASSERT_EQUAL(dmi_get_step_index(b, &p), DMI_OK);
    CU_ASSERT_EQUAL(p, SAVED_AT);
    CU_ASSERT(core_same_state(a, b)); /* the version-2 bytes of the same state */
    CU_ASSERT_EQUAL(dmi_advance(a, MORE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(b, MORE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(c, MORE), DMI_OK);
    CU_ASSERT(core_same_state(a, b));
    CU_ASSERT(core_same_state(a, c));

    /* the exponential kernel: the recursion's sums rebuilt */
    core_model me = {0}, mf = {0};
    dmi_solver *e = exp_solver(&me), *f = exp_solver(&mf);
    CU_ASSERT_FATAL(e && f);
    CU_ASSERT_EQUAL(dmi_advance(e, SAVED_AT), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(f, 5), DMI_OK);
    size_t size_e;
    unsigned char *v1e = core_state_v1(e, 2, N, 1.0, &size_e);
    CU_ASSERT_FATAL(v1e != NULL);
    CU_ASSERT_EQUAL(size_e, dmi_state_at_rec(2, N));
    CU_ASSERT(size_e < dmi_state_size(e)); /* version 2 holds the sums */
    CU_ASSERT_EQUAL(dmi_state_load(f, v1e, size_e), DMI_OK);
    double worst = 0, scale = 0;
    for (size_t k = 0; k < MORE; k++) {
        double ue[2], uf[2];
        CU_ASSERT_EQUAL(dmi_step(e), DMI_OK);
        CU_ASSERT_EQUAL(dmi_step(f), DMI_OK);
        CU_ASSERT(dmi_get_state(e, ue) == DMI_OK && dmi_get_state(f, uf) == DMI_OK);
        for (int j = 0; j < 2; j++) {
            worst = fmax(worst, fabs(ue[j] - uf[j]));
            scale = fmax(scale, fabs(ue[j]));
        }
    }
    if (!(worst <= 1e-13 * scale))
        printf("\n  exponential kernel from a version-1 state: |U - U_saving| = %g, |U| = %g",
               worst, scale);
    CU_ASSERT(scale > 0.1 && worst <= 1e-13 * scale);

    free(v1e);
    free(before_h);
    free(bad);
    free(before_b);
    free(v1);
    dmi_free(&h);
    dmi_free(&a);
    dmi_free(&b);
    dmi_free(&c);
    dmi_free(&e);
    dmi_free(&f);
}

/* bytes.h, the one description of the state's bytes (libdmi, the FMU and the
 * tests use it): its FNV-1a against the published test vectors, and a saved
 * state read at its offsets against what the solver's queries return. */
/* Whether the state b of the (2, N) model has size bytes with E doubles of
 * sums, the recursion's word running, and its checksum. */
static int tail_is(const unsigned char *b, size_t size, uint64_t E, uint64_t running)
{
    const size_t rec = dmi_state_at_rec(2, N);
    return size == dmi_state_bytes(2, N, (size_t)E) && dmi_get_u64(b, rec + DMI_STATE_REC_E) == E &&
           dmi_get_u64(b, rec + DMI_STATE_REC_RUNNING) == running &&
           dmi_get_u64(b, DMI_STATE_AT_CHECKSUM) == dmi_fnv1a_skip(b, size, DMI_STATE_AT_CHECKSUM);
}

static void test_layout(void)
{
    static const struct {
        const char *text;
        uint64_t fnv1a;
    } fnv[] = {{"", UINT64_C(0xcbf29ce484222325)}, {"a", UINT64_C(0xaf63dc4c8601ec8c)},
               {"foobar", UINT64_C(0x85944171f73967e8)}}; /* FNV reference test vectors */
    for (size_t k = 0; k < sizeof fnv / sizeof *fnv; k++)
        CU_ASSERT_EQUAL(dmi_fnv1a(DMI_FNV1A_INIT, (const unsigned char *)fnv[k].text,
                                  strlen(fnv[k].text)), fnv[k].fnv1a);
    const unsigned char ab[10] = "0123456789"; /* skip: the 8 bytes at 1 read as zero */
    const unsigned char az[10] = {'0', 0, 0, 0, 0, 0, 0, 0, 0, '9'};
    CU_ASSERT_EQUAL(dmi_fnv1a_skip(ab, 10, 1), dmi_fnv1a(DMI_FNV1A_INIT, az, 10));

    core_model m = {0};
    dmi_solver *s = model_after(&m, SAVED_AT);
    CU_ASSERT_FATAL(s != NULL);
    size_t size;
    unsigned char *b = core_save(s, &size);
    CU_ASSERT_FATAL(b != NULL);
    const size_t n = 2;
    CU_ASSERT_EQUAL(size, dmi_state_bytes(n, N, 0));
    CU_ASSERT_EQUAL(size, 8 * 8 + (N + 3) * n * 8 + 3 * 8); /* no sums: 8 + 3 words */
    CU_ASSERT_EQUAL(dmi_get_u64(b, DMI_STATE_AT_MAGIC), DMI_STATE_MAGIC);
    CU_ASSERT(memcmp(b, "ETATSIMD", 8) == 0 || memcmp(b, "DMISTATE", 8) == 0); /* by endianness */
    CU_ASSERT_EQUAL(dmi_get_u64(b, DMI_STATE_AT_VERSION), 2);
    CU_ASSERT_EQUAL(dmi_get_u64(b, DMI_STATE_AT_n), n);
    CU_ASSERT_EQUAL(dmi_get_u64(b, DMI_STATE_AT_N), N);
    CU_ASSERT_EQUAL(dmi_get_double(b, DMI_STATE_AT_TAU), 1.0);
    CU_ASSERT_EQUAL(dmi_get_u64(b, DMI_STATE_AT_P), SAVED_AT);
    CU_ASSERT_EQUAL(dmi_get_u64(b, DMI_STATE_AT_STEPPED), 1);
    int same = 1;
    double u[2], W[2], X[2];
    for (size_t lag = 0; lag <= N; lag++) {
        same &= dmi_get_past(s, lag, u) == DMI_OK;
        for (size_t j = 0; j < n; j++)
            same &= dmi_get_double(b, dmi_state_at_double(n, lag, j)) == u[j];
    }
    same &= dmi_get_step_terms(s, W, X) == DMI_OK;
    for (size_t j = 0; j < n; j++)
        same &= dmi_get_double(b, dmi_state_at_double(n, N + 1, j)) == W[j] &&
                dmi_get_double(b, dmi_state_at_double(n, N + 2, j)) == X[j];
    CU_ASSERT(same);
    CU_ASSERT_EQUAL(dmi_state_at_rec(n, N) + DMI_STATE_REC_BYTES, size);
    CU_ASSERT(tail_is(b, size, 0, 0));
    CU_ASSERT_EQUAL(dmi_get_u64(b, dmi_state_at_rec(n, N) + DMI_STATE_REC_SIGNATURE), 0);
    free(b);
    dmi_free(&s);

    /* with the recursion: two terms, each used in one column: 2 sums of 2 doubles */
    const double a[2] = {-1, 0}, bk[2] = {0, 3}, C[8] = {0, 1, 0, 0, 0, 0, 1, 0};
    CU_ASSERT_EQUAL_FATAL(dmi_create(&s, n, 1.0, N), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_kernel_exp(s, 2, a, bk, C, NULL), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_convolution(s, DMI_CONV_RECURSIVE), DMI_OK);
    CU_ASSERT_EQUAL(dmi_init(s), DMI_OK);
    CU_ASSERT_EQUAL(dmi_advance(s, 3), DMI_OK);
    b = core_save(s, &size);
    CU_ASSERT_FATAL(b != NULL);
    CU_ASSERT(tail_is(b, size, 4, 1));
    free(b);
    dmi_free(&s);
}

CORE_MAIN("core: state save and load",
          {"save, load elsewhere, replay: bitwise the same run", test_replay},
          {"replay with the direct, FFT and automatic delay sum, N = 500", test_replay_methods},
          {"other n/N/tau, truncated, corrupted, bad magic: refused, solver unchanged",
           test_refused},
          {"the layout of bytes.h: FNV-1a vectors, the saved bytes at its offsets", test_layout},
          {"a state of libdmi 1.0 (format version 1) loads and steps on as the saving run",
           test_version_1})
