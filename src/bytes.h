/*
 * Bytes of libdmi (private, not installed; header only): sizes of arrays in
 * bytes, the FNV-1a checksum, words read and written at a byte offset of a
 * buffer of any alignment, and the layout of libdmi's saved state
 * (dmi_state_save, src/state.c).  The FMU (fmu/) and the C tests use these
 * too, so that a change of the state format is made here and nowhere else.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef DMI_BYTES_H
#define DMI_BYTES_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* a * b elements of size sz, or 0 on overflow. */
static inline size_t dmi_mul_size(size_t a, size_t b, size_t sz)
{
    if (a != 0 && b > SIZE_MAX / a)
        return 0;
    if (a * b != 0 && sz > SIZE_MAX / (a * b))
        return 0;
    return a * b * sz;
}

/* ---- FNV-1a 64 ------------------------------------------------------------- */

/* FNV-1a 64 of len bytes, continuing from hsh (DMI_FNV1A_INIT to start). */
#define DMI_FNV1A_INIT UINT64_C(0xcbf29ce484222325)
static inline uint64_t dmi_fnv1a(uint64_t hsh, const unsigned char *b, size_t len)
{
    for (size_t i = 0; i < len; i++) {
        hsh ^= b[i];
        hsh *= UINT64_C(0x100000001b3);
    }
    return hsh;
}

/* FNV-1a 64 of the len bytes at b with the 8 bytes at offset at read as
 * zero: the checksum of a buffer that stores it at byte at
 * (at + 8 <= len). */
static inline uint64_t dmi_fnv1a_skip(const unsigned char *b, size_t len, size_t at)
{
    static const unsigned char zero[sizeof(uint64_t)];
    uint64_t hsh = dmi_fnv1a(DMI_FNV1A_INIT, b, at);
    hsh = dmi_fnv1a(hsh, zero, sizeof zero);
    return dmi_fnv1a(hsh, b + at + sizeof zero, len - at - sizeof zero);
}

/* ---- values at a byte offset (native endian, any alignment) ----------------------
 * dmi_put_u32(b, at, x), dmi_get_u32(b, at), and the same for u64 (uint64_t)
 * and double: x copied to or from the bytes b[at .. at + sizeof x). */
#define DMI_BYTES_AT(name, type)                                                                  \
    static inline void dmi_put_##name(unsigned char *b, size_t at, type x)                        \
    {                                                                                             \
        memcpy(b + at, &x, sizeof x);                                                             \
    }                                                                                             \
    static inline type dmi_get_##name(const unsigned char *b, size_t at)                          \
    {                                                                                             \
        type x;                                                                                   \
        memcpy(&x, b + at, sizeof x);                                                             \
        return x;                                                                                 \
    }
DMI_BYTES_AT(u32, uint32_t)
DMI_BYTES_AT(u64, uint64_t)
DMI_BYTES_AT(double, double)
#undef DMI_BYTES_AT

/* ---- libdmi's saved state ------------------------------------------------------
 * Native endian.  A header of 8 uint64 words at the byte offsets below:
 *   magic, version, n, N, bits of tau, p, p != 0 (a step was taken), checksum;
 * then (N + 1) n doubles U_j^{p-lag}, lag = 0..N (lag-major), n doubles W^{p-1},
 * n doubles X^{p-1}: that is all of version 1 (libdmi 1.0), whose checksum
 * is the same; then (version 2, libdmi 1.1) the recursion's part:
 * 3 uint64 words
 *   E = 2 dmi_expk_sums (0 without an exponential kernel),
 *   1 if the sums are those of a running recursion (else 0 and zeros),
 *   dmi_expk_signature (0 without an exponential kernel)
 * and E doubles, the sums (re, im).  Version 3 (libdmi 1.2) is version 2
 * followed by the bits of h (DMI_STATE_H_BYTES): the state of a solver whose h
 * is not the tau / N of dmi_create (one made by dmi_create_h with a partial
 * last cell); every other solver writes version 2, whose h is tau / N.
 * checksum = dmi_fnv1a_skip(state, size, DMI_STATE_AT_CHECKSUM).
 */
#define DMI_STATE_MAGIC UINT64_C(0x444d495354415445) /* "DMISTATE" */
#define DMI_STATE_VERSION_1 UINT64_C(1) /* read only */
#define DMI_STATE_VERSION UINT64_C(2)
#define DMI_STATE_VERSION_H UINT64_C(3)
enum { DMI_STATE_H_BYTES = 8 };
enum {
    DMI_STATE_AT_MAGIC = 0,
    DMI_STATE_AT_VERSION = 8,
    DMI_STATE_AT_n = 16,
    DMI_STATE_AT_N = 24,
    DMI_STATE_AT_TAU = 32,
    DMI_STATE_AT_P = 40,
    DMI_STATE_AT_STEPPED = 48,
    DMI_STATE_AT_CHECKSUM = 56,
    DMI_STATE_HEADER = 64 /* bytes of the header: the first double's offset */
};
/* The recursion's words, at these offsets from dmi_state_at_rec. */
enum { DMI_STATE_REC_E = 0, DMI_STATE_REC_RUNNING = 8, DMI_STATE_REC_SIGNATURE = 16,
       DMI_STATE_REC_BYTES = 24 /* the words' bytes: the sums' offset */ };

/* Byte offset of U_j^{p-lag} (lag = 0..N), of W_j (lag = N + 1) and of X_j
 * (lag = N + 2) in the state of an n-component solver. */
static inline size_t dmi_state_at_double(size_t n, size_t lag, size_t j)
{
    return DMI_STATE_HEADER + (lag * n + j) * sizeof(double);
}

/* Byte offset of the recursion's words; its E sums follow them. */
static inline size_t dmi_state_at_rec(size_t n, size_t N)
{
    return dmi_state_at_double(n, N + 3, 0);
}

/* Bytes of the state of an (n, N) solver with E doubles of sums. */
static inline size_t dmi_state_bytes(size_t n, size_t N, size_t E)
{
    return dmi_state_at_rec(n, N) + DMI_STATE_REC_BYTES + E * sizeof(double);
}

#endif
