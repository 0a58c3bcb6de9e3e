/*
 * The CUnit runner of the conv tests.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#ifndef CONV_RUN_H
#define CONV_RUN_H

#include <CUnit/CUnit.h>

/* Runs tests (ended by CU_TEST_INFO_NULL) as the suite `name`; returns the
 * exit status: 0 iff every assertion passed, 1 on failures, 2 if CUnit fails. */
int conv_run(const char *name, CU_TestInfo *tests);

#endif
