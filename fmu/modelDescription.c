/*
 * Writes an FMU's modelDescription.xml for FMI 2.0 or 3.0 from its model's
 * variable table (DMI_FMU_MODEL, dmi_fmu.h), after checking the table; run
 * by dmi_add_fmu at build time, linked with the model, the framework and
 * libdmi's core.
 *
 * Usage: modelDescription 2|3 NAME GUID OUTPUT [SOURCE...]
 * NAME is the model name and modelIdentifier, GUID the GUID (FMI 2.0) or
 * instantiationToken (FMI 3.0).  The SOURCEs (FMI 2.0: the C files of
 * sources/) go into <SourceFiles>; FMI 3.0 lists them in
 * sources/buildDescription.xml instead.  A table that is not valid: a
 * message naming the variable on stderr, exit status 1, no file written.
 * Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "framework.h"

#define MODEL (&DMI_FMU_MODEL)

/* The independent variable the framework adds when the table has none. */
static const dmi_fmu_variable TIME = {"time", "Float64", "independent", "", 0.0, "",
                                      "the simulation time, the last communication point"};

static const dmi_fmu_variable *var(unsigned vr)
{
    return vr < MODEL->nvariables ? &MODEL->variables[vr] : &TIME;
}

static int refuse(const char *name, const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "dmi_add_fmu(%s): error: ", name);
    fprintf(stderr, fmt, a, b);
    fprintf(stderr, "\n");
    return 1;
}

/* The table's errors, each with the variable's name: 0 if none. */
static int check_table(const char *name, unsigned nvr)
{
    int bad = 0, independent = 0;
    if (!MODEL->variables || MODEL->nvariables == 0 || !MODEL->configure || !MODEL->outputs ||
        MODEL->n == 0)
        return refuse(name, "the model needs variables, configure, outputs and n >= 1%s%s", "",
                      "");
    for (unsigned vr = 0; vr < MODEL->nvariables; vr++) {
        const dmi_fmu_variable *x = var(vr);
        const unsigned kind = fmu_kind(vr);
        const int has_start = x->start_text[0] != '\0';
        for (unsigned k = 0; k < vr; k++)
            if (strcmp(var(k)->name, x->name) == 0)
                bad |= refuse(name, "variable \"%s\" is defined twice%s", x->name, "");
        if (strcmp(x->type, "Float64") && strcmp(x->type, "Int32") && strcmp(x->type, "Boolean"))
            bad |= refuse(name, "variable \"%s\": unknown type \"%s\" (Float64, Int32 or Boolean)",
                          x->name, x->type);
        else if (!kind)
            bad |= refuse(name, "variable \"%s\": unknown causality \"%s\" (parameter, input, "
                                "output or independent)", x->name, x->causality);
        else if ((kind & (FMU_OUTPUT | FMU_INDEPENDENT)) && has_start)
            bad |= refuse(name, "variable \"%s\": an output or the independent variable has no "
                                "start value (start %s given)", x->name, x->start_text);
        else if (fmu_is_set(kind) && !has_start)
            bad |= refuse(name, "variable \"%s\": a %s needs a start value", x->name, x->causality);
        else if ((kind & FMU_INDEPENDENT) && (!(kind & FMU_FLOAT64) || independent++))
            bad |= refuse(name, "variable \"%s\": the independent variable is Float64, and only "
                          "one%s", x->name, "");
        else if ((kind & FMU_INDEPENDENT) && vr + 1 != MODEL->nvariables)
            /* FMI 2.0 leaves it out and numbers the others 1, 2, ...: it must be last */
            bad |= refuse(name, "variable \"%s\": the independent variable must be the table's "
                          "last%s", x->name, "");
        else if ((kind & FMU_BOOLEAN) && has_start && x->start != 0 && x->start != 1)
            bad |= refuse(name, "variable \"%s\": a Boolean starts at 0 or 1 (start %s)", x->name,
                          x->start_text);
    }
    if (MODEL->tau >= nvr || fmu_kind(MODEL->tau) != (FMU_FLOAT64 | FMU_PARAMETER))
        bad |= refuse(name, "the model's tau (value reference %s) is not a Float64 parameter%s",
                      MODEL->tau < nvr ? var(MODEL->tau)->name : "out of range", "");
    if (MODEL->N >= nvr || fmu_kind(MODEL->N) != (FMU_INT32 | FMU_PARAMETER))
        bad |= refuse(name, "the model's N (value reference %s) is not an Int32 parameter%s",
                      MODEL->N < nvr ? var(MODEL->N)->name : "out of range", "");
    return bad;
}

/* Writes text as an XML attribute value (without the quotes). */
static void attr(FILE *f, const char *text)
{
    for (const char *c = text; *c; c++)
        switch (*c) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*c, f);
        }
}

/* A number as xs:double, exact, with a decimal point ("30.0"). */
static void number(FILE *f, double x)
{
    char text[40];
    int digits = 15;
    do
        snprintf(text, sizeof text, "%.*g", digits, x);
    while (strtod(text, NULL) != x && ++digits <= 17);
    fprintf(f, "%s%s", text, strpbrk(text, ".eEn") ? "" : ".0");
}

/* Outputs: shown in ModelStructure. */
static int is_output(unsigned vr)
{
    return (fmu_kind(vr) & FMU_OUTPUT) != 0;
}

static const char *causality(unsigned vr)
{
    return var(vr)->causality;
}

/* FMI 2.0 and 3.0: parameters fixed; Float64 continuous; Int32 and Boolean
 * inputs and outputs discrete. */
static const char *variability(unsigned vr)
{
    const unsigned kind = fmu_kind(vr);
    return kind & FMU_PARAMETER ? "fixed" : kind & FMU_FLOAT64 ? "continuous" : "discrete";
}

static void start(FILE *f, unsigned vr)
{
    const dmi_fmu_variable *x = var(vr);
    if (!x->start_text[0])
        return;
    fprintf(f, " start=\"");
    if (fmu_kind(vr) & FMU_BOOLEAN)
        fprintf(f, "%s", x->start != 0 ? "true" : "false");
    else if (fmu_kind(vr) & FMU_INT32)
        fprintf(f, "%.0f", x->start);
    else
        attr(f, x->start_text);
    fprintf(f, "\"");
}

static void unit(FILE *f, unsigned vr, int v)
{
    const dmi_fmu_variable *x = var(vr);
    const unsigned kind = fmu_kind(vr);
    if (x->unit[0] && (kind & FMU_FLOAT64) && (v == 3 || !(kind & FMU_INDEPENDENT))) {
        fprintf(f, " unit=\"");
        attr(f, x->unit);
        fprintf(f, "\"");
    }
}

static void unit_definitions(FILE *f, unsigned nvr)
{
    int any = 0;
    for (unsigned vr = 0; vr < nvr; vr++) {
        const char *u = var(vr)->unit;
        int seen = !u[0] || !(fmu_kind(vr) & FMU_FLOAT64);
        for (unsigned k = 0; k < vr && !seen; k++)
            seen = (fmu_kind(k) & FMU_FLOAT64) && strcmp(var(k)->unit, u) == 0;
        if (seen)
            continue;
        if (!any++)
            fprintf(f, "  <UnitDefinitions>\n");
        fprintf(f, "    <Unit name=\"");
        attr(f, u);
        fprintf(f, "\"/>\n");
    }
    if (any)
        fprintf(f, "  </UnitDefinitions>\n");
}

static void header(FILE *f, int v, const char *name, const char *guid, int nsources,
                   char **sources, unsigned nvr)
{
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<!-- Written by dmi_add_fmu (libdmi %s) from the model's variable table. -->\n"
               "<fmiModelDescription\n"
               "  fmiVersion=\"%s\"\n"
               "  modelName=\"%s\"\n"
               "  %s=\"%s\"\n"
               "  description=\"",
            dmi_version(), v == 2 ? "2.0" : "3.0", name, v == 2 ? "guid" : "instantiationToken",
            guid);
    attr(f, MODEL->description ? MODEL->description : "");
    fprintf(f, " (libdmi %s)\"\n", dmi_version());
    if (MODEL->author) {
        fprintf(f, "  author=\"");
        attr(f, MODEL->author);
        fprintf(f, "\"\n");
    }
    /* libdmi's licence: the FMU holds its code */
    fprintf(f, "  version=\"%s\"\n"
               "  license=\"GPL-3.0-or-later\"\n"
               "  generationTool=\"dmi\"\n"
               "  variableNamingConvention=\"flat\"%s>\n",
            dmi_version(), v == 2 ? "\n  numberOfEventIndicators=\"0\"" : "");
    if (v == 2)
        fprintf(f, "  <CoSimulation\n"
                   "    modelIdentifier=\"%s\"\n"
                   "    canHandleVariableCommunicationStepSize=\"true\"\n"
                   "    canInterpolateInputs=\"false\"\n"
                   "    maxOutputDerivativeOrder=\"0\"\n"
                   "    canNotUseMemoryManagementFunctions=\"true\"\n"
                   "    canGetAndSetFMUstate=\"true\"\n"
                   "    canSerializeFMUstate=\"true\"",
                name);
    if (v == 2 && nsources == 0)
        fprintf(f, "/>\n");
    if (v == 2 && nsources > 0) {
        fprintf(f, ">\n    <SourceFiles>\n");
        for (int k = 0; k < nsources; k++) {
            fprintf(f, "      <File name=\"");
            attr(f, sources[k]);
            fprintf(f, "\"/>\n");
        }
        fprintf(f, "    </SourceFiles>\n  </CoSimulation>\n");
    }
    /* event mode always; with the model's indicators, early return at their
     * events and intermediateUpdate called there (fmi3Functions.c) */
    const char *events =
        (MODEL->indicators || MODEL->held) && MODEL->nindicators > 0 ? "true" : "false";
    if (v == 3)
        fprintf(f, "  <CoSimulation\n"
                   "    modelIdentifier=\"%s\"\n"
                   "    canHandleVariableCommunicationStepSize=\"true\"\n"
                   "    canGetAndSetFMUState=\"true\"\n"
                   "    canSerializeFMUState=\"true\"\n"
                   "    providesIntermediateUpdate=\"%s\"\n"
                   "    mightReturnEarlyFromDoStep=\"%s\"\n"
                   "    canReturnEarlyAfterIntermediateUpdate=\"%s\"\n"
                   "    hasEventMode=\"true\"\n"
                   "    providesEvaluateDiscreteStates=\"false\"\n"
                   "    maxOutputDerivativeOrder=\"0\"/>\n",
                name, events, events, events);
    unit_definitions(f, nvr);
    fprintf(f, "  <LogCategories>\n");
#define CAT(cat, description)                                                                      \
    fprintf(f, "    <Category name=\"%s\" description=\"", #cat);                                  \
    attr(f, description);                                                                          \
    fprintf(f, "\"/>\n");
    FMU_LOG_CATEGORIES(CAT)
#undef CAT
    fprintf(f, "  </LogCategories>\n  <DefaultExperiment startTime=\"0.0\" stopTime=\"");
    number(f, MODEL->stop_time);
    fprintf(f, "\" stepSize=\"");
    number(f, MODEL->step_size);
    fprintf(f, "\"/>\n");
}

static void variables2(FILE *f, unsigned nvr)
{
    static const char *const TYPE2[] = {"Real", "Integer", "Boolean"};
    fprintf(f, "  <ModelVariables>\n");
    for (unsigned vr = 0; vr < nvr; vr++) {
        const unsigned kind = fmu_kind(vr);
        const char *type = TYPE2[kind & FMU_FLOAT64 ? 0 : kind & FMU_INT32 ? 1 : 2];
        if (kind & FMU_INDEPENDENT)
            continue; /* FMI 2.0: no independent variable (the time is the FMU's) */
        fprintf(f, "    <!-- index %u -->\n"
                   "    <ScalarVariable name=\"%s\" valueReference=\"%u\" causality=\"%s\" "
                   "variability=\"%s\"%s\n"
                   "                    description=\"",
                vr + 1, var(vr)->name, vr, causality(vr), variability(vr),
                kind & FMU_INPUT       ? ""
                : fmu_is_set(kind)     ? " initial=\"exact\""
                                       : " initial=\"calculated\"");
        attr(f, var(vr)->description);
        fprintf(f, "\">\n      <%s", type);
        unit(f, vr, 2);
        start(f, vr);
        fprintf(f, "/>\n    </ScalarVariable>\n");
    }
    fprintf(f, "  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
    for (unsigned vr = 0; vr < nvr; vr++)
        if (is_output(vr))
            fprintf(f, "      <Unknown index=\"%u\" dependencies=\"\"/>\n", vr + 1);
    fprintf(f, "    </Outputs>\n    <InitialUnknowns>\n");
    for (unsigned vr = 0; vr < nvr; vr++)
        if (is_output(vr))
            fprintf(f, "      <Unknown index=\"%u\"/>\n", vr + 1);
    fprintf(f, "    </InitialUnknowns>\n  </ModelStructure>\n");
}

static void variables3(FILE *f, unsigned nvr)
{
    fprintf(f, "  <ModelVariables>\n");
    for (unsigned vr = 0; vr < nvr; vr++) {
        const unsigned kind = fmu_kind(vr);
        fprintf(f, "    <%s name=\"%s\" valueReference=\"%u\" causality=\"%s\" "
                   "variability=\"%s\"%s",
                var(vr)->type, var(vr)->name, vr, causality(vr), variability(vr),
                kind & (FMU_INPUT | FMU_INDEPENDENT | FMU_OUTPUT) ? "" : " initial=\"exact\"");
        unit(f, vr, 3);
        start(f, vr);
        fprintf(f, "\n      description=\"");
        attr(f, var(vr)->description);
        fprintf(f, "\"/>\n");
    }
    fprintf(f, "  </ModelVariables>\n  <ModelStructure>\n");
    for (unsigned vr = 0; vr < nvr; vr++)
        if (is_output(vr))
            fprintf(f, "    <Output valueReference=\"%u\" dependencies=\"\"/>\n", vr);
    for (unsigned vr = 0; vr < nvr; vr++)
        if (is_output(vr))
            fprintf(f, "    <InitialUnknown valueReference=\"%u\" dependencies=\"\"/>\n", vr);
    fprintf(f, "  </ModelStructure>\n");
}

int main(int argc, char **argv)
{
    if (argc < 5 || (strcmp(argv[1], "2") != 0 && strcmp(argv[1], "3") != 0)) {
        fprintf(stderr, "usage: modelDescription 2|3 NAME GUID OUTPUT [SOURCE...]\n");
        return 2;
    }
    const char *name = argv[2];
    unsigned nvr = (unsigned)MODEL->nvariables;
    while (fmu_kind(nvr)) /* the time the framework adds */
        nvr++;
    if (check_table(name, nvr) != 0)
        return 1;
    const int v = argv[1][0] - '0';
    FILE *f = fopen(argv[4], "w");
    if (!f) {
        perror(argv[4]);
        return 1;
    }
    header(f, v, name, argv[3], argc - 5, argv + 5, nvr);
    if (v == 2)
        variables2(f, nvr);
    else
        variables3(f, nvr);
    fprintf(f, "</fmiModelDescription>\n");
    return fclose(f) == 0 ? 0 : 1;
}
