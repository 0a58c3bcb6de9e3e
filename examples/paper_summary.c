/*
 * The summary table of the paper's Section 4: Examples 4.1-4.3 at
 * h = 1/9991 (4.5) and the order study of Figure 4.3 (h = 1/(1001 + 50k),
 * k = 1..18) for Examples 4.1 and 4.2.  Prints the table to stdout and writes
 * the errors of the order study as CSV to the file given as argument
 * ("example,k,N,h,max_err_state,max_err_w,max_err_v", the columns of
 * ../shared/reference/errors_ex41_ex42.csv).
 *
 * Usage: paper_summary [order.csv]; paper_summary --help
 *
 * The errors are maxima over t_p in [-tau, T] against the exact solutions
 * (4.8) and (4.10); the observed order is the least-squares slope of
 * log(max error) against log h.  The run time is the processor time of the
 * solver run alone (no output), measured with clock().
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "paper.h"

enum { N_PAPER = 9991, ORDER_RUNS = 18 };

/* The step sizes of Figure 4.3: h = 1/(1001 + 50k), k = 1..18. */
static size_t order_N(int k)
{
    return (size_t)(1001 + 50 * k);
}

/* Least-squares slope of y against x. */
static double ls_slope(const double *x, const double *y, int n)
{
    double mx = 0, my = 0, sxy = 0, sxx = 0;
    for (int i = 0; i < n; i++) {
        mx += x[i] / n;
        my += y[i] / n;
    }
    for (int i = 0; i < n; i++) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
    }
    return sxy / sxx;
}

/* paper_run with csv = NULL, timed; *seconds = processor time. */
static int timed_run(int example, size_t N, double T, paper_result *r, double *seconds)
{
    clock_t start = clock();
    int rc = paper_run(example, N, T, DMI_CONV_AUTO, NULL, 1, r);
    *seconds = (double)(clock() - start) / CLOCKS_PER_SEC;
    if (rc != DMI_OK)
        fprintf(stderr, "paper_summary: example %d.%d, N = %zu: %s\n", example / 10, example % 10, N,
                dmi_strerror(rc));
    return rc;
}

/*
 * The order study of one example: writes its CSV rows, returns the slopes of
 * the state, w and v errors in slope[0..2] and the total time in *seconds.
 */
static int order_study(int example, FILE *csv, double slope[3], double *seconds)
{
    double logh[ORDER_RUNS], loge[3][ORDER_RUNS];
    *seconds = 0;
    for (int k = 1; k <= ORDER_RUNS; k++) {
        size_t N = order_N(k);
        paper_result r;
        double sec;
        int rc = timed_run(example, N, 10, &r, &sec);
        if (rc != DMI_OK)
            return rc;
        *seconds += sec;
        logh[k - 1] = log(1.0 / (double)N);
        loge[0][k - 1] = log(r.max_err_state);
        loge[1][k - 1] = log(r.max_err_w);
        loge[2][k - 1] = log(r.max_err_v);
        if (csv)
            fprintf(csv, "%d.%d,%d,%zu,%.17g,%.10e,%.10e,%.10e\n", example / 10, example % 10, k,
                    N, 1.0 / (double)N, r.max_err_state, r.max_err_w, r.max_err_v);
    }
    for (int c = 0; c < 3; c++)
        slope[c] = ls_slope(logh, loge[c], ORDER_RUNS);
    return DMI_OK;
}

static void rule(void)
{
    puts("-------  --  ------  ----------  ----------  ----------  -----  -----  -----  ------  -------"
         "  -----");
}

int main(int argc, char **argv)
{
    static const struct {
        int example;
        double T;
    } runs[] = {{41, 10}, {42, 10}, {43, 30}};
    FILE *csv = NULL;
    double study_seconds = 0;
    int failed = 0;
    const char *csv_path = NULL;
    const cli_arg args[] = {{"order.csv", CLI_PATH, &csv_path, 0,
                             "also write the errors of the order study to this CSV file"}};
    const cli_program prog = {
        "paper_summary",
        "The summary table of the paper's Section 4: Examples 4.1-4.3 at h = 1/9991 and the\n"
        "order study of Figure 4.3 (h = 1/(1001 + 50k), k = 1..18) for Examples 4.1 and 4.2.",
        "stdout: the table (errors, observed orders, static and dynamic phases, CPU time).\n"
        "order.csv: \"example,k,N,h,max_err_state,max_err_w,max_err_v\", one row per run.\n"
        "exit status: 0, 1 if a run fails or the CSV cannot be written, 2 for a bad\n"
        "  argument (also an order.csv that cannot be opened).",
        args, 1};
    cli_parse(&prog, argc, argv);
    if (csv_path) {
        csv = fopen(csv_path, "w");
        if (!csv)
            cli_reject(&prog, "order.csv", csv_path, strerror(errno));
        fputs("example,k,N,h,max_err_state,max_err_w,max_err_v\n", csv);
    }
    puts("Paper, Section 4 (b = alpha = tau = 1, h = 1/9991).  error: max over t_p in [-1, T] of");
    puts("|U^p - u(t_p)|, Euclidean in (w, w'), and in w and w' alone.  order: least-squares slope of");
    puts("log(error) against log h over the 18 step sizes h = 1/(1001 + 50k) of Figure 4.3.  Phases:");
    puts("static (w' = 0 exactly on >= 2 consecutive t_p) and dynamic.  CPU s: the run at h = 1/9991.");
    rule();
    puts("example   T  h       error       in w        in w'       order  in w   in w'  static  dynamic"
         "  CPU s");
    rule();
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
        const int ex = runs[i].example;
        paper_result r;
        double slope[3], sec, study_sec = 0;
        if (timed_run(ex, N_PAPER, runs[i].T, &r, &sec) != DMI_OK ||
            (paper_has_exact(ex) && order_study(ex, csv, slope, &study_sec) != DMI_OK)) {
            failed = 1;
            continue;
        }
        study_seconds += study_sec;
        printf("%d.%d     %2.0f  1/%d  ", ex / 10, ex % 10, runs[i].T, N_PAPER);
        if (paper_has_exact(ex))
            printf("%.4e  %.4e  %.4e  %.3f  %.3f  %.3f", r.max_err_state, r.max_err_w, r.max_err_v,
                   slope[0], slope[1], slope[2]);
        else
            printf("%-10s  %-10s  %-10s  %-5s  %-5s  %-5s", "-", "-", "-", "-", "-", "-");
        printf("  %6zu  %7zu  %5.2f\n", r.static_phases, r.dynamic_phases, sec);
    }
    rule();
    printf("Order study (Figure 4.3): 2 x 18 runs, %.2f s CPU.  Paper: slope 0.993 for Example 4.2;\n",
           study_seconds);
    puts("a finite number of static and dynamic phases for Example 4.3 (Figures 4.4, 4.5).");
    if (csv && fclose(csv) != 0) {
        perror(csv_path);
        failed = 1;
    }
    return failed;
}
