/*
 * A stand-in for libdmi.so with another ABI: it exports dmi_version only, so
 * the ABI gate must reject it (test abi_gate_rejects_change: the gate is not
 * vacuous, e.g. if abidw recorded nothing).
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include "dmi.h"

const char *dmi_version(void)
{
    return "0.0.0";
}
