/*
 * Evidence for the erratum in the paper's scheme (4.4).  As printed, the
 * oscillator update reads
 *
 *   u^{p+1} = u^p + h v^p,
 *   v^{p+1} = (I + h alpha sigma)^{-1}( v^p - h (b u^p + g(t_p)) + h sum_{l=0}^{N-1} H(lh) u^{p-l} ),
 *
 * while (3.12)-(3.13) with (4.3) give -h W^p = -h * h sum_{l=0}^{N-1} H(lh) u^{p-l}:
 * the printed line drops the quadrature factor h of (3.12b) and flips the
 * sign of the delay term.  This program integrates Example 4.2 with four
 * hand-written variants of the update,
 *
 *   "(3.12)-(3.13)"  delay term -h * h sum   (the correct scheme, written by hand)
 *   "(4.4) printed"  delay term +h * sum     (both mistakes, the printed line)
 *   "no h only"      delay term -h * sum     (only the factor h missing)
 *   "sign only"      delay term +h * h sum   (only the sign flipped)
 *
 * beside the library (dmi_step, the scheme (3.12)-(3.13)), and reports the
 * maximal error against the exact solution (4.10) over t_p in [-tau, T] for
 * h = 1/1001, 1/2001, 1/4001, 1/9991.  The hand-written correct variant must
 * agree with the library to rounding, which validates the hand-written loop.
 *
 * Usage: scheme44_as_printed [T [stride]]   (defaults 10, 1)
 *   stdout: CSV "t,err_library,err_312,err_printed,err_no_h,err_sign" at
 *           h = 1/9991 (Euclidean error of (w, w') against (4.10), every
 *           stride-th step; "inf" once a variant has overflowed);
 *   stderr: the table of maximal errors.
 * Returns 0 if the evidence holds, else 1: at every h the hand-written
 * (3.12)-(3.13) agrees with the library to 1e-10, the error of (4.4) as
 * printed exceeds 1 and is larger at h = 1/9991 than at h = 1/1001 (it grows
 * as h -> 0), and the error of the library decreases with h.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cli.h"
#include "paper.h"

enum { EXAMPLE = 42, VARIANTS = 4 };

/* The delay term of the v update is sign * h * (with_h ? h : 1) * sum. */
static const struct {
    const char *name;
    double sign;
    int with_h;
} variant[VARIANTS] = {
    {"(3.12)-(3.13)", -1.0, 1},
    {"(4.4) printed", +1.0, 0},
    {"no h only", -1.0, 0},
    {"sign only", +1.0, 1},
};

/* (I + lambda sigma)^{-1}(x): the soft threshold. */
static double soft(double x, double lambda)
{
    return x > lambda ? x - lambda : x < -lambda ? x + lambda : 0.0;
}

static double state_error(double t, double w, double v)
{
    double ew = w - paper_w(EXAMPLE, t), ev = v - paper_v(EXAMPLE, t);
    return sqrt(ew * ew + ev * ev);
}

typedef struct {
    double max_err[VARIANTS + 1]; /* the variants, then the library */
    double blowup_t[VARIANTS];    /* first t_p with a non-finite state, or NAN */
    double diff_312;              /* max |hand-written (3.12)-(3.13) - library| */
} study_result;

/*
 * Example 4.2 with h = 1/N to T: all variants and the library in one loop.
 * Writes the CSV to csv (if not NULL) every stride-th step.
 */
static int study(size_t N, double T, FILE *csv, size_t stride, study_result *res)
{
    const double h = 1.0 / (double)N, b = 1.0, alpha = 1.0; /* (4.5) */
    const size_t M = (size_t)llround(T / h);
    paper_example ex = {EXAMPLE};
    dmi_solver *s = NULL;
    /* w[q] = u^{q-N} of each variant, q = 0..N+M; the history is exact. */
    double *w = malloc(sizeof(double) * VARIANTS * (N + M + 1));
    double *H = malloc(sizeof(double) * N);
    double v[VARIANTS], lib[2];
    int rc = dmi_create(&s, 2, 1.0, N);
    if (rc == DMI_OK)
        rc = paper_setup(s, &ex);
    if (rc == DMI_OK)
        rc = dmi_init(s);
    if (rc == DMI_OK && (!w || !H))
        rc = DMI_ENOMEM;
    if (rc != DMI_OK) {
        dmi_free(&s);
        free(w);
        free(H);
        return rc;
    }
    for (size_t l = 0; l < N; l++)
        H[l] = paper_H(EXAMPLE, (double)l * h);
    for (int i = 0; i < VARIANTS; i++) {
        double *wi = w + (size_t)i * (N + M + 1);
        for (size_t q = 0; q <= N; q++)
            wi[q] = paper_w(EXAMPLE, ((double)q - (double)N) * h);
        v[i] = paper_v(EXAMPLE, 0.0);
        res->max_err[i] = 0;
        res->blowup_t[i] = NAN;
    }
    res->max_err[VARIANTS] = 0;
    res->diff_312 = 0;
    if (csv)
        fputs("t,err_library,err_312,err_printed,err_no_h,err_sign\n", csv);
    for (size_t p = 0;; p++) {
        const double t = (double)p * h;
        double err[VARIANTS + 1];
        rc = dmi_get_state(s, lib);
        if (rc != DMI_OK)
            break;
        err[VARIANTS] = state_error(t, lib[0], lib[1]);
        for (int i = 0; i < VARIANTS; i++) {
            const double wp = w[(size_t)i * (N + M + 1) + N + p];
            err[i] = isnan(res->blowup_t[i]) ? state_error(t, wp, v[i]) : INFINITY;
        }
        {
            const double *w312 = w + N + p; /* variant 0 */
            res->diff_312 = fmax(res->diff_312, fmax(fabs(*w312 - lib[0]), fabs(v[0] - lib[1])));
        }
        for (int i = 0; i <= VARIANTS; i++)
            res->max_err[i] = fmax(res->max_err[i], err[i]);
        if (csv && (p % stride == 0 || p == M))
            fprintf(csv, "%.17g,%.6e,%.6e,%.6e,%.6e,%.6e\n", t, err[VARIANTS], err[0], err[1],
                    err[2], err[3]);
        if (p == M)
            break;
        for (int i = 0; i < VARIANTS; i++) {
            double *wi = w + (size_t)i * (N + M + 1) + N; /* wi[k] = u^k, k >= -N */
            if (!isnan(res->blowup_t[i]))
                continue;
            const long P = (long)p;
            double sum = 0;
            for (size_t l = 0; l < N; l++)
                sum += H[l] * wi[P - (long)l];
            const double delay = variant[i].sign * h * (variant[i].with_h ? h : 1.0) * sum;
            wi[P + 1] = wi[P] + h * v[i];
            v[i] = soft(v[i] - h * (b * wi[P] + paper_g(EXAMPLE, t)) + delay, h * alpha);
            if (!isfinite(wi[P + 1]) || !isfinite(v[i]))
                res->blowup_t[i] = t + h;
        }
        rc = dmi_step(s);
        if (rc != DMI_OK)
            break;
    }
    dmi_free(&s);
    free(w);
    free(H);
    return rc;
}

int main(int argc, char **argv)
{
    static const size_t Ns[] = {1001, 2001, 4001, 9991};
    const size_t n_runs = sizeof Ns / sizeof Ns[0];
    double T = 10;
    size_t stride = 1;
    int failed = 0;
    const cli_arg args[] = {
        {"T", CLI_TIME, &T, 1e4, "end time of Example 4.2"},
        {"stride", CLI_COUNT, &stride, 0, "write only every stride-th step of the CSV"}};
    const cli_program prog = {
        "scheme44_as_printed",
        "Evidence for the erratum in the paper's scheme (4.4): integrates Example 4.2 on [-1, T]\n"
        "with (4.4) as printed, two variants with one of its two mistakes, the correct\n"
        "(3.12)-(3.13) written by hand, and libdmi, at h = 1/1001, 1/2001, 1/4001, 1/9991.",
        "stdout: CSV \"t,err_library,err_312,err_printed,err_no_h,err_sign\" at h = 1/9991,\n"
        "  the error of each against the exact solution (4.10), every stride-th step\n"
        "  (about 110,000 lines with no arguments).\n"
        "stderr: the table of maximal errors.\n"
        "exit status: 0 if the evidence holds (the hand-written (3.12)-(3.13) agrees with\n"
        "  libdmi, (4.4) as printed diverges), 1 if not, 2 for a bad argument.",
        args, sizeof args / sizeof args[0]};
    cli_parse(&prog, argc, argv);
    fprintf(stderr, "Scheme (4.4) as printed against (3.12)-(3.13), Example 4.2 on [-1, %g]:\n", T);
    fprintf(stderr, "max over t_p of |U^p - (w, w')(t_p)| (inf: overflow, first non-finite t_p given)\n");
    fprintf(stderr, "%-30s", "variant (delay term in v)");
    for (size_t j = 0; j < n_runs; j++)
        fprintf(stderr, "  h = 1/%-13zu", Ns[j]);
    fputc('\n', stderr);
    study_result r[sizeof Ns / sizeof Ns[0]];
    for (size_t j = 0; j < n_runs; j++) {
        FILE *csv = Ns[j] == 9991 ? stdout : NULL;
        int rc = study(Ns[j], T, csv, stride, &r[j]);
        if (rc != DMI_OK) {
            fprintf(stderr, "scheme44_as_printed: h = 1/%zu: %s\n", Ns[j], dmi_strerror(rc));
            return 1;
        }
        if (!(r[j].diff_312 <= 1e-10)) {
            fprintf(stderr, "h = 1/%zu: the hand-written (3.12)-(3.13) differs from the library\n",
                    Ns[j]);
            failed = 1;
        }
        if (!(r[j].max_err[1] > 1)) {
            fprintf(stderr, "h = 1/%zu: (4.4) as printed does not diverge\n", Ns[j]);
            failed = 1;
        }
        if (j > 0 && !(r[j].max_err[VARIANTS] < r[j - 1].max_err[VARIANTS])) {
            fprintf(stderr, "h = 1/%zu: the error of the library does not decrease\n", Ns[j]);
            failed = 1;
        }
    }
    if (!(r[n_runs - 1].max_err[1] > r[0].max_err[1])) {
        fputs("the error of (4.4) as printed does not grow as h decreases\n", stderr);
        failed = 1;
    }
    static const char *terms[VARIANTS + 1] = {"-h*h*sum", "+h*sum", "-h*sum", "+h*h*sum",
                                              "-h W^p"};
    for (int i = 0; i <= VARIANTS; i++) {
        char label[64];
        snprintf(label, sizeof label, "%s (%s)", i < VARIANTS ? variant[i].name : "libdmi dmi_step",
                 terms[i]);
        fprintf(stderr, "%-30s", label);
        for (size_t j = 0; j < n_runs; j++) {
            if (i < VARIANTS && !isnan(r[j].blowup_t[i]))
                fprintf(stderr, "  inf (t = %-8.4f) ", r[j].blowup_t[i]);
            else
                fprintf(stderr, "  %-18.4e", r[j].max_err[i]);
        }
        fputc('\n', stderr);
    }
    fprintf(stderr, "%-30s", "|hand (3.12)-(3.13) - libdmi|");
    for (size_t j = 0; j < n_runs; j++)
        fprintf(stderr, "  %-18.2e", r[j].diff_312);
    fputc('\n', stderr);
    return failed;
}
