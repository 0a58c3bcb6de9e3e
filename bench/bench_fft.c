/*
 * Benchmark of the transforms the FFT method of the delay sum is built on (not
 * a test): for each block size S, the cost per step of GSL's radix-2 real
 * forward and inverse FFTs of length M = 2S that every block of S steps needs
 * (src/conv.c, one kernel column and one row used, as in the oscillator), and
 * a plain copy of the window; nothing else: no spectral multiply-add, no
 * direct lags, no reversal of the imaginary parts.
 * Every exact online block method pays, for its smallest block size S_1, this
 * cost plus the S_1 - 1 newest lags summed directly, so the table bounds the
 * cost of any such engine from below (see the README).
 * Usage: bench_fft; bench_fft --help
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "clock.h"

#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

int main(int argc, char **argv)
{
    const cli_program prog = {
        "bench_fft",
        "Benchmark (not a test) of GSL's radix-2 real FFTs that the FFT method of the delay\n"
        "sum needs: forward + inverse of length M = 2S every S steps, S = 4..4096.  It takes\n"
        "no arguments and about half a minute.",
        "stdout: one row per block size S: S, M, ns per step (the fastest of 5 repetitions).\n"
        "exit status: 0, 1 if out of memory, 2 for any argument.",
        NULL, 0};
    cli_parse(&prog, argc, argv);
    printf("GSL radix-2 real FFTs, forward + inverse of length M = 2S every S steps\n");
    printf("%6s %6s | %12s\n", "S", "M", "ns per step");
    for (size_t S = 4; S <= 4096; S *= 2) {
        const size_t M = 2 * S, reps = 40000000 / (M * 12) + 1;
        double *x = malloc(M * sizeof *x), *x0 = malloc(M * sizeof *x0), best = INFINITY;
        if (!x || !x0) {
            free(x);
            free(x0);
            fprintf(stderr, "out of memory\n");
            return 1;
        }
        for (size_t i = 0; i < M; i++)
            x0[i] = 1.0 / (double)(i + 1);
        for (int r = 0; r < 5; r++) { /* the fastest of five repetitions */
            double t0 = now();
            for (size_t k = 0; k < reps; k++) {
                memcpy(x, x0, M * sizeof *x); /* a fresh window (the engine copies one too) */
                gsl_fft_real_radix2_transform(x, 1, M);
                gsl_fft_halfcomplex_radix2_backward(x, 1, M);
            }
            best = fmin(best, 1e9 * (now() - t0) / (double)(reps * S));
        }
        printf("%6zu %6zu | %12.1f\n", S, M, best);
        free(x);
        free(x0);
    }
    return 0;
}
