/*
 * The C library's own results for the Python binding's tests
 * (test_vs_c.py): the paper's oscillator (examples/paper.c) at
 * N = 500, stepped in C, in four scenarios:
 *   box     Example 4.3's rhs and kernel (callbacks) with the box
 *           [-0.01, 0.01] x [-0.05, 0.05] instead of the friction;
 *   exp     Example 4.3 with its kernel as exponential terms
 *           (paper_set_kernel_exp43), DMI_CONV_RECURSIVE;
 *   switch  the same, the method switched every 250 steps:
 *           DIRECT, FFT, RECURSIVE, AUTO, DIRECT, RECURSIVE;
 *   save    "exp" for 700 steps, the state saved (printed in hex), 300 more
 *           steps; then the saved bytes loaded into a new solver and 300 steps.
 * Prints "p w v" (%.17g) after every 50th step, "state <hex>" for save, and
 * "loaded" before the rows of the second solver.  Exit status 1 on a libdmi error.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "paper.h"

static paper_example ex43 = {43};

static int make(dmi_solver **s, int exp_kernel)
{
    int rc = dmi_create(s, 2, 1.0, 500);
    if (rc == DMI_OK)
        rc = paper_setup(*s, &ex43);
    if (rc == DMI_OK && exp_kernel)
        rc = paper_set_kernel_exp43(*s);
    if (rc == DMI_OK && exp_kernel)
        rc = dmi_set_convolution(*s, DMI_CONV_RECURSIVE);
    return rc;
}

static int steps(dmi_solver *s, size_t count)
{
    double u[2];
    uint64_t p;
    for (size_t k = 0; k < count; k++) {
        int rc = dmi_step(s);
        if (rc != DMI_OK)
            return rc;
        dmi_get_step_index(s, &p);
        dmi_get_state(s, u);
        if (p % 50 == 0)
            printf("%llu %.17g %.17g\n", (unsigned long long)p, u[0], u[1]);
    }
    return DMI_OK;
}

int main(int argc, char **argv)
{
    const char *what = argc == 2 ? argv[1] : "";
    dmi_solver *s = NULL, *t = NULL;
    unsigned char *buf = NULL;
    int rc;
    if (strcmp(what, "box") == 0) {
        const double lo[2] = {-0.01, -0.05}, hi[2] = {0.01, 0.05};
        rc = make(&s, 0);
        if (rc == DMI_OK)
            rc = dmi_set_box(s, lo, hi);
        if (rc == DMI_OK)
            rc = dmi_init(s);
        if (rc == DMI_OK)
            rc = steps(s, 3000);
    } else if (strcmp(what, "exp") == 0) {
        rc = make(&s, 1);
        if (rc == DMI_OK)
            rc = dmi_init(s);
        if (rc == DMI_OK)
            rc = steps(s, 3000);
    } else if (strcmp(what, "switch") == 0) {
        const int methods[6] = {DMI_CONV_DIRECT, DMI_CONV_FFT, DMI_CONV_RECURSIVE, DMI_CONV_AUTO,
                                DMI_CONV_DIRECT, DMI_CONV_RECURSIVE};
        rc = make(&s, 1);
        if (rc == DMI_OK)
            rc = dmi_init(s);
        for (int k = 0; k < 6 && rc == DMI_OK; k++) {
            rc = dmi_set_convolution(s, methods[k]);
            if (rc == DMI_OK)
                rc = steps(s, 250);
        }
    } else if (strcmp(what, "save") == 0) {
        rc = make(&s, 1);
        if (rc == DMI_OK)
            rc = dmi_init(s);
        if (rc == DMI_OK)
            rc = steps(s, 700);
        size_t size = dmi_state_size(s);
        buf = malloc(size);
        if (rc == DMI_OK)
            rc = buf ? dmi_state_save(s, buf, size) : DMI_ENOMEM;
        if (rc == DMI_OK) {
            printf("state ");
            for (size_t i = 0; i < size; i++)
                printf("%02x", buf[i]);
            printf("\n");
            rc = steps(s, 300);
        }
        if (rc == DMI_OK)
            rc = make(&t, 1);
        if (rc == DMI_OK)
            rc = dmi_init(t);
        if (rc == DMI_OK)
            rc = dmi_state_load(t, buf, size);
        if (rc == DMI_OK) {
            printf("loaded\n");
            rc = steps(t, 300);
        }
    } else {
        fprintf(stderr, "usage: binding_ref box|exp|switch|save\n");
        return 2;
    }
    if (rc != DMI_OK)
        fprintf(stderr, "binding_ref %s: %s\n", what, s ? dmi_last_error(s) : dmi_strerror(rc));
    free(buf);
    dmi_free(&s);
    dmi_free(&t);
    return rc == DMI_OK ? 0 : 1;
}
