/*
 * One paper example (EXAMPLE = 41, 42 or 43, set by the build: programs ex41,
 * ex42, ex43): writes the CSV to stdout, "t,w,v,w_exact,v_exact" for 4.1 and
 * 4.2 (from t = -tau), "t,w,v" for 4.3 (from t = 0), and a summary to stderr.
 * Usage: exNN [N [T [stride]]]   (defaults 9991, 10 (30 for 4.3), 1)
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "paper.h"

#ifndef EXAMPLE
#error "define EXAMPLE as 41, 42 or 43"
#endif

int main(int argc, char **argv)
{
    const int ex = EXAMPLE;
    size_t N = 9991, stride = 1;
    double T = ex == 43 ? 30 : 10;
    if (argc > 4 || (argc > 1 && paper_parse_count(argv[1], &N) != 0) ||
        (argc > 2 && paper_parse_time(argv[2], &T) != 0) ||
        (argc > 3 && paper_parse_count(argv[3], &stride) != 0)) {
        fprintf(stderr, "usage: ex%d [N [T [stride]]]  (N >= 1, T > 0, stride >= 1)\n", ex);
        return 2;
    }
    paper_result r;
    int rc = paper_run(ex, N, T, DMI_CONV_AUTO, stdout, stride, &r);
    if (rc != DMI_OK) {
        fprintf(stderr, "ex%d: %s\n", ex, dmi_strerror(rc));
        return 1;
    }
    fprintf(stderr, "example %d.%d: h = 1/%zu, %zu steps, ", ex / 10, ex % 10, N, r.steps);
    if (paper_has_exact(ex))
        fprintf(stderr, "max error %.4e (w %.4e, v %.4e), ", r.max_err_state, r.max_err_w,
                r.max_err_v);
    fprintf(stderr, "%zu static and %zu dynamic phases\n", r.static_phases, r.dynamic_phases);
    return 0;
}
