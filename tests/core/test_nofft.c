/*
 * libdmi built from its GSL-free core (DMI_CORE_SOURCES, compiled without
 * DMI_HAVE_FFT, as inside the FMU): DMI_CONV_FFT is refused with a message,
 * AUTO falls back to the direct sum, and Example 4.3 at h = 1/9991 still
 * matches ../shared/reference/ex43_N9991.csv.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core_test.h"

static void test_fft_refused(void)
{
    paper_example ex = {43};
    dmi_solver *s = core_paper_solver(&ex, 1000);
    CU_ASSERT_PTR_NOT_NULL_FATAL(s);
    CU_ASSERT_EQUAL(dmi_set_convolution(s, DMI_CONV_FFT), DMI_EINVAL);
    printf("\n  message: %s\n", dmi_last_error(s));
    CU_ASSERT_PTR_NOT_NULL(strstr(dmi_last_error(s), "without the FFT"));
    dmi_solver *t = NULL; /* before dmi_init too */
    CU_ASSERT_EQUAL_FATAL(dmi_create(&t, 2, 1.0, 10), DMI_OK);
    CU_ASSERT_EQUAL(dmi_set_convolution(t, DMI_CONV_FFT), DMI_EINVAL);
    CU_ASSERT_EQUAL(dmi_set_convolution(t, DMI_CONV_DIRECT), DMI_OK);
    dmi_free(&t);
    dmi_free(&s);
}

/* AUTO (the default) at N = 9991 against the reference rows (p, t, w, v). */
static void test_reference(void)
{
    size_t rows;
    double *ref = core_read_csv("ex43_N9991.csv", 4, &rows);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ref);
    CU_ASSERT(rows >= 2990);
    paper_example ex = {43};
    dmi_solver *s = core_paper_solver(&ex, 9991);
    CU_ASSERT_PTR_NOT_NULL_FATAL(s);
    double dw = 0, dv = 0, u[2];
    uint64_t p = 0;
    for (size_t r = 0; r < rows; r++) {
        const double *row = ref + 4 * r;
        CU_ASSERT_FATAL(row[0] >= (double)p && row[0] == floor(row[0]));
        if (dmi_advance(s, (size_t)row[0] - (size_t)p) != DMI_OK) {
            CU_FAIL("dmi_advance failed");
            break;
        }
        p = (uint64_t)row[0];
        dmi_get_state(s, u);
        dw = fmax(dw, fabs(u[0] - row[2]));
        dv = fmax(dv, fabs(u[1] - row[3]));
    }
    printf("\n  h = 1/9991 vs reference (%zu rows): |dw| = %.3e, |dv| = %.3e\n", rows, dw, dv);
    CU_ASSERT(dw <= 1e-11);
    CU_ASSERT(dv <= 1e-11);
    dmi_free(&s);
    free(ref);
}

int main(int argc, char **argv)
{
    static const core_test tests[] = {
        {"built without the FFT: DMI_CONV_FFT refused with a message", test_fft_refused},
        {"built without the FFT: Example 4.3, h = 1/9991, AUTO = reference", test_reference},
        {NULL, NULL}};
    return core_main(argc, argv, "core: libdmi without GSL", tests);
}
