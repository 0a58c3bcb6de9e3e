/*
 * The saved state of a libdmi solver: dmi_state_size, dmi_state_save,
 * dmi_state_load.  The byte layout is in bytes.h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "solver.h"

#include "engine.h"
#include "errors.h"

#include "bytes.h"

#include <stdlib.h>
#include <string.h>

/* The number of doubles of the recursion's sums in s's state. */
static size_t state_sums(const dmi_solver *s)
{
    return dmi_has_expk(s) ? 2 * dmi_expk_sums(&s->expk) : 0;
}

/* The format version s writes: 3, with h, when h is not tau / N (bytes.h). */
static uint64_t state_version(const dmi_solver *s)
{
    return dmi_h_is_tau_over_N(s) ? DMI_STATE_VERSION : DMI_STATE_VERSION_H;
}

size_t dmi_state_size(const dmi_solver *s)
{
    if (!s)
        return 0;
    return dmi_state_bytes(s->n, s->N, state_sums(s)) +
           (state_version(s) == DMI_STATE_VERSION_H ? DMI_STATE_H_BYTES : 0);
}

int dmi_state_save(const dmi_solver *s, void *buf, size_t size)
{
    int rc = dmi_check_query(s, buf, "dmi_state_save");
    if (rc != DMI_OK)
        return rc;
    const size_t need = dmi_state_size(s), n = s->n, N = s->N, E = state_sums(s);
    if (size < need)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_save: buffer of %zu bytes, %zu needed", size,
                        need);
    unsigned char *b = buf; /* buf may be unaligned: every value is copied as bytes */
    dmi_put_u64(b, DMI_STATE_AT_MAGIC, DMI_STATE_MAGIC);
    dmi_put_u64(b, DMI_STATE_AT_VERSION, state_version(s));
    dmi_put_u64(b, DMI_STATE_AT_n, (uint64_t)n);
    dmi_put_u64(b, DMI_STATE_AT_N, (uint64_t)N);
    dmi_put_double(b, DMI_STATE_AT_TAU, s->tau);
    dmi_put_u64(b, DMI_STATE_AT_P, s->p);
    dmi_put_u64(b, DMI_STATE_AT_STEPPED, (uint64_t)(s->p != 0));
    for (size_t lag = 0; lag <= N; lag++)
        for (size_t j = 0; j < n; j++)
            dmi_put_double(b, dmi_state_at_double(n, lag, j),
                           dmi_history_series(&s->ring, j)[lag]);
    memcpy(b + dmi_state_at_double(n, N + 1, 0), s->last_W, n * sizeof(double));
    memcpy(b + dmi_state_at_double(n, N + 2, 0), s->last_X, n * sizeof(double));
    unsigned char *rec = b + dmi_state_at_rec(n, N);
    dmi_put_u64(rec, DMI_STATE_REC_E, E);
    dmi_put_u64(rec, DMI_STATE_REC_RUNNING, s->rec != NULL);
    dmi_put_u64(rec, DMI_STATE_REC_SIGNATURE, E ? dmi_expk_signature(&s->expk, N, s->h) : 0);
    if (s->rec)
        dmi_exp_get(s->rec, rec + DMI_STATE_REC_BYTES);
    else
        memset(rec + DMI_STATE_REC_BYTES, 0, E * sizeof(double));
    if (state_version(s) == DMI_STATE_VERSION_H)
        dmi_put_double(b, need - DMI_STATE_H_BYTES, s->h);
    dmi_put_u64(b, DMI_STATE_AT_CHECKSUM, dmi_fnv1a_skip(b, need, DMI_STATE_AT_CHECKSUM));
    return DMI_OK;
}

int dmi_state_load(dmi_solver *s, const void *buf, size_t size)
{
    int rc = dmi_check_query(s, buf, "dmi_state_load");
    if (rc != DMI_OK)
        return rc;
    const size_t need = dmi_state_size(s), n = s->n, N = s->N;
    const unsigned char *b = buf;
    /* magic and version before the size: a state of another format has
     * another size, and the version is what tells the caller why */
    if (size < DMI_STATE_HEADER)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: %zu bytes, this solver's state has %zu",
                        size, need);
    if (dmi_get_u64(b, DMI_STATE_AT_MAGIC) != DMI_STATE_MAGIC)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: not a dmi state (bad magic)");
    const uint64_t version = dmi_get_u64(b, DMI_STATE_AT_VERSION);
    if (version != DMI_STATE_VERSION_1 && version != DMI_STATE_VERSION &&
        version != DMI_STATE_VERSION_H)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: state format version %llu; this libdmi "
                                       "reads versions 1, 2 and 3 only",
                        (unsigned long long)version);
    /* versions 1 and 2: h = tau / N; version 3: h is its last word */
    if (version != DMI_STATE_VERSION_H && state_version(s) == DMI_STATE_VERSION_H)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: state of a solver with h = tau / N; this "
                                       "one has h = %.17g, not tau / N = %.17g (dmi_create_h)",
                        s->h, s->tau / (double)s->N);
    if (version == DMI_STATE_VERSION_H && state_version(s) != DMI_STATE_VERSION_H)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: state of a solver with h = %.17g, not "
                                       "tau / N (dmi_create_h); this one has h = tau / N = %.17g",
                        dmi_get_double(b, size - DMI_STATE_H_BYTES), s->h);
    /* version 1 (libdmi 1.0) has no recursion's part: its bytes end before it */
    const int v1 = version == DMI_STATE_VERSION_1;
    const size_t have = v1 ? dmi_state_at_rec(n, N) : need;
    if (size != have)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: %zu bytes, this solver's state has %zu%s",
                        size, have, v1 ? " in format version 1" : "");
    const uint64_t hn = dmi_get_u64(b, DMI_STATE_AT_n), hN = dmi_get_u64(b, DMI_STATE_AT_N);
    const uint64_t p = dmi_get_u64(b, DMI_STATE_AT_P);
    const uint64_t stepped = dmi_get_u64(b, DMI_STATE_AT_STEPPED);
    const double tau = dmi_get_double(b, DMI_STATE_AT_TAU);
    if (hn != (uint64_t)n || hN != (uint64_t)N || memcmp(&tau, &s->tau, sizeof tau))
        return dmi_fail(s, DMI_EINVAL,
                        "dmi_state_load: state of a solver with n = %llu, N = %llu, tau = %g; "
                        "this one has n = %zu, N = %zu, tau = %g",
                        (unsigned long long)hn, (unsigned long long)hN, tau, n, N, s->tau);
    if (version == DMI_STATE_VERSION_H) {
        const double h = dmi_get_double(b, need - DMI_STATE_H_BYTES);
        if (memcmp(&h, &s->h, sizeof h))
            return dmi_fail(s, DMI_EINVAL, "dmi_state_load: state of a solver with h = %.17g; this "
                                           "one has h = %.17g (n = %zu, N = %zu, tau = %g)",
                            h, s->h, n, N, s->tau);
    }
    if (dmi_get_u64(b, DMI_STATE_AT_CHECKSUM) != dmi_fnv1a_skip(b, have, DMI_STATE_AT_CHECKSUM))
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: corrupted state (checksum mismatch)");
    if (stepped != (uint64_t)(p != 0))
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: corrupted state (step flag %llu at p = "
                                       "%llu)", (unsigned long long)stepped,
                        (unsigned long long)p);
    const size_t E = v1 ? 0 : state_sums(s), nd = (N + 3) * n + E;
    const unsigned char *rec = b + dmi_state_at_rec(n, N); /* version 1: its end */
    const uint64_t rec_E = v1 ? 0 : dmi_get_u64(rec, DMI_STATE_REC_E);
    const uint64_t running = v1 ? 0 : dmi_get_u64(rec, DMI_STATE_REC_RUNNING);
    if (rec_E != E || running > 1)
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: corrupted state (recursion words %llu, "
                                       "%llu; this solver has %zu sums)",
                        (unsigned long long)rec_E, (unsigned long long)running, E);
    /* the doubles, checked before anything changes */
    double *d = malloc((nd ? nd : 1) * sizeof *d);
    if (!d)
        return dmi_fail(s, DMI_ENOMEM, "dmi_state_load: out of memory");
    memcpy(d, b + dmi_state_at_double(n, 0, 0), (nd - E) * sizeof *d);
    if (E)
        memcpy(d + nd - E, rec + DMI_STATE_REC_BYTES, E * sizeof *d);
    /* The states, W and X of a committed step are finite.  The recursion's
     * sums need not be: a finite but huge history can overflow them, and the
     * next step then fails with DMI_ENONFINITE; they are restored as saved,
     * so that a loaded solver fails the same way. */
    if (dmi_first_nonfinite(d, nd - E) < nd - E) {
        free(d);
        return dmi_fail(s, DMI_EINVAL, "dmi_state_load: state holds a non-finite value");
    }
    dmi_history ring = {0};
    if (dmi_history_alloc(&ring, n, N) != 0) {
        free(d);
        return dmi_fail(s, DMI_ENOMEM, "dmi_state_load: out of memory");
    }
    for (size_t lag = 0; lag <= N; lag++)
        dmi_history_put(&ring, lag, d + lag * n);
    dmi_history_release(&s->ring);
    s->ring = ring;
    memcpy(s->last_W, d + (N + 1) * n, n * sizeof *d);
    memcpy(s->last_X, d + (N + 2) * n, n * sizeof *d);
    s->p = p;
    /* The sums of the same recursion continue bitwise; any others (a state
     * of another method or kernel, or of version 1, which has none) are
     * anchored afresh from the states, and
     * the FFT engine is rebuilt from them (s->rec and s->conv are never both
     * set). */
    if (s->rec && running == 1 &&
        dmi_get_u64(rec, DMI_STATE_REC_SIGNATURE) == dmi_expk_signature(&s->expk, N, s->h))
        dmi_exp_set(s->rec, d + nd - E, p);
    else
        dmi_engine_rebuild(s, s->conv, s->rec);
    free(d);
    return DMI_OK;
}
