/*
 * Example 4.2 of the paper: writes the CSV (t, w, v, w_exact, v_exact) to stdout
 * and a summary to stderr.  Usage: ex42 [N [T [stride]]] (defaults 9991, 10, 1).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdlib.h>

#include "paper.h"

int main(int argc, char **argv)
{
    size_t N = argc > 1 ? strtoul(argv[1], NULL, 10) : 9991;
    double T = argc > 2 ? strtod(argv[2], NULL) : 10;
    size_t stride = argc > 3 ? strtoul(argv[3], NULL, 10) : 1;
    paper_result r;
    int rc = paper_run(42, N, T, DMI_CONV_AUTO, stdout, stride, &r);
    if (rc != DMI_OK) {
        fprintf(stderr, "ex42: %s\n", dmi_strerror(rc));
        return 1;
    }
    fprintf(stderr, "example 4.2: h = 1/%zu, %zu steps, max error %.4e (w %.4e, v %.4e), %zu static and %zu dynamic phases\n",
            N, r.steps, r.max_err_state, r.max_err_w, r.max_err_v, r.static_phases, r.dynamic_phases);
    return 0;
}
