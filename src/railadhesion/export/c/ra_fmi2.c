/* railadhesion native FMUs: the FMI 2.0 co-simulation layer, shared by every model.
 *
 * Model-independent: the model is the generated header ra_model.h (records, variable table,
 * GUID; see ra_fmu.h) and its compiled step function. This file does the FMI plumbing:
 * instances, the call sequence, value references, range checks, logging, FMU states.
 *
 * Rules kept here (docs/fmu.md):
 * - every fmi2Error is logged, naming the function and, where there is one, the variable;
 *   after an fmi2Error the instance accepts only fmi2Reset, fmi2SetFMUstate, fmi2Get*,
 *   fmi2Terminate and fmi2FreeInstance (FMI 2.0: the simulation cannot go on otherwise);
 * - no global mutable data: any number of instances side by side, in any threads (one thread
 *   per instance at a time);
 * - memory is allocated only by fmi2Instantiate, fmi2GetFMUstate and fmi2DeSerializeFMUstate,
 *   through the master's allocateMemory; fmi2SetReal, fmi2DoStep and fmi2GetReal allocate
 *   nothing;
 * - the FMU state is the three records plus time and phase: saving it is a memcpy.
 *
 * Build (what railadhesion.export.native does for linux64):
 *   cc -std=c11 -O2 -fPIC -fvisibility=hidden -shared -I<FMI 2.0 headers> -I. ra_fmi2.c
 *      <law object> -o <modelIdentifier>.so -lm
 * The linux64 binary also links the same model optimised for x86-64-v3 (AVX2, FMA, BMI2),
 * named by -DRA_STEP_X86_64_V3=<symbol>: fmi2Instantiate uses it when the processor has
 * x86-64-v3, unless the environment variable RAILADHESION_FMU_GENERIC is set (non-empty).
 * Both give the same numbers (the model's IR has no fast-math flags).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "ra_model.h"

#define RA_MESSAGE_SIZE 1024
#define RA_SNAPSHOT_MAGIC 0x52414653u /* "RAFS" */
#define RA_INSTANCE_MAGIC 0x52414649u /* "RAFI" */

typedef enum {
    PHASE_INSTANTIATED = 0,
    PHASE_INITIALIZATION,
    PHASE_STEPPING,
    PHASE_TERMINATED,
    PHASE_ERROR
} Phase;

static const char *const PHASE_NAMES[] = {"instantiated", "initialization mode", "stepping",
                                          "terminated", "error"};

#define IN_INSTANTIATED (1u << PHASE_INSTANTIATED)
#define IN_INITIALIZATION (1u << PHASE_INITIALIZATION)
#define IN_STEPPING (1u << PHASE_STEPPING)
#define IN_TERMINATED (1u << PHASE_TERMINATED)
#define IN_ERROR (1u << PHASE_ERROR)
#define IN_ANY (IN_INSTANTIATED | IN_INITIALIZATION | IN_STEPPING | IN_TERMINATED | IN_ERROR)

/* Everything fmi2GetFMUstate saves. */
typedef struct {
    uint32_t magic;
    int phase;
    int outputs_stale; /* feedthrough models: an input changed since the outputs were made */
    double time;
    ra_state state;
    ra_settings settings;
    ra_inputs inputs;
} Snapshot;

typedef struct {
    uint32_t magic;
    Snapshot now;
    ra_step_function step; /* RA_STEP, or its x86-64-v3 code */
    fmi2CallbackFunctions functions;
    char *name;
    int logging_on;
    char message[RA_MESSAGE_SIZE];
    char escaped[2 * RA_MESSAGE_SIZE];
} Instance;

/* ---- logging ------------------------------------------------------------------------------ */

/* Formats into the instance's buffers (no allocation) and passes the text with every '%'
 * doubled, so that a logger that treats the message as a format prints it as it is. */
static void emit(const fmi2CallbackFunctions *functions, const char *name, fmi2Status status,
                 const char *text, char *escaped, size_t size) {
    size_t j = 0;
    const char *category = status == fmi2Error     ? "logStatusError"
                           : status == fmi2Warning ? "logStatusWarning"
                                                   : "logAll";
    if (functions == NULL || functions->logger == NULL) return;
    for (size_t i = 0; text[i] != '\0' && j + 2 < size; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    functions->logger(functions->componentEnvironment, name, status, category, escaped);
}

static void log_status(Instance *c, fmi2Status status, const char *format, ...) {
    va_list args;
    if (status == fmi2OK && !c->logging_on) return;
    va_start(args, format);
    vsnprintf(c->message, sizeof c->message, format, args);
    va_end(args);
    emit(&c->functions, c->name, status, c->message, c->escaped, sizeof c->escaped);
}

/* Logs an error and puts the instance into the error phase; returns fmi2Error. */
static fmi2Status fail(Instance *c, const char *format, ...) {
    va_list args;
    va_start(args, format);
    vsnprintf(c->message, sizeof c->message, format, args);
    va_end(args);
    emit(&c->functions, c->name, fmi2Error, c->message, c->escaped, sizeof c->escaped);
    c->now.phase = PHASE_ERROR;
    return fmi2Error;
}

/* Before an instance exists (fmi2Instantiate): log with the master's callbacks. */
static void log_without_instance(const fmi2CallbackFunctions *functions, const char *name,
                                 const char *format, ...) {
    char text[RA_MESSAGE_SIZE], escaped[2 * RA_MESSAGE_SIZE];
    va_list args;
    va_start(args, format);
    vsnprintf(text, sizeof text, format, args);
    va_end(args);
    emit(functions, name, fmi2Error, text, escaped, sizeof escaped);
}

/* ---- checks ------------------------------------------------------------------------------- */

static Instance *instance(fmi2Component component) {
    Instance *c = (Instance *)component;
    return (c != NULL && c->magic == RA_INSTANCE_MAGIC) ? c : NULL;
}

/* 1 if `function` may not be called in the instance's phase (logged, error phase). */
static int wrong_phase(Instance *c, const char *function, unsigned allowed) {
    if (allowed & (1u << c->now.phase)) return 0;
    fail(c, "%s: not allowed in the %s phase", function, PHASE_NAMES[c->now.phase]);
    return 1;
}

/* The instance, if it is one and in an allowed phase (else NULL, the wrong phase logged). */
static Instance *instance_in(fmi2Component component, const char *function, unsigned allowed) {
    Instance *c = instance(component);
    if (c == NULL || wrong_phase(c, function, allowed)) return NULL;
    return c;
}

/* Moves the instance from an allowed phase to the phase ``to``. */
static fmi2Status change_phase(fmi2Component component, const char *function,
                               unsigned allowed, int to) {
    Instance *c = instance_in(component, function, allowed);
    if (c == NULL) return fmi2Error;
    c->now.phase = to;
    return fmi2OK;
}

static void *field(Snapshot *s, const ra_variable *v) {
    char *base = v->record == RA_STATE      ? (char *)&s->state
                 : v->record == RA_SETTINGS ? (char *)&s->settings
                                            : (char *)&s->inputs;
    return base + v->offset;
}

static double load(Snapshot *s, const ra_variable *v) {
    void *p = field(s, v);
    switch (v->type) {
    case RA_I64: return (double)*(int64_t *)p;
    case RA_I32: return (double)*(int32_t *)p;
    case RA_U8: return (double)*(uint8_t *)p;
    default: return *(double *)p;
    }
}

static void store(Snapshot *s, const ra_variable *v, double x) {
    void *p = field(s, v);
    switch (v->type) {
    case RA_I64: *(int64_t *)p = (int64_t)nearbyint(x); break;
    case RA_I32: *(int32_t *)p = (int32_t)nearbyint(x); break;
    case RA_U8: *(uint8_t *)p = (uint8_t)nearbyint(x); break;
    default: *(double *)p = x;
    }
}

#ifdef RA_STEP_X86_64_V3
int RA_STEP_X86_64_V3(void *state, const void *settings, const void *inputs, double dt);

static int has_x86_64_v3(void) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
    __builtin_cpu_init();
    return __builtin_cpu_supports("x86-64-v3");
#elif defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    /* the feature names every GCC and clang know; processors with these have the rest of
       x86-64-v3 (F16C, MOVBE, LZCNT: Intel since Haswell, AMD since Excavator) */
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
           __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
#else
    return 0;
#endif
}
#endif

/* The model's step for this processor (see the build notes above); *which names it. */
static ra_step_function choose_step(const char **which) {
#ifdef RA_STEP_X86_64_V3
    const char *generic = getenv("RAILADHESION_FMU_GENERIC");
    if ((generic == NULL || generic[0] == '\0') && has_x86_64_v3()) {
        *which = "x86-64-v3";
        return RA_STEP_X86_64_V3;
    }
#endif
    *which = "x86-64";
    return RA_STEP;
}

/* Runs the step; on failure logs the model's message and returns fmi2Error. */
static fmi2Status run_step(Instance *c, const char *function, double dt) {
    int code = c->step(&c->now.state, &c->now.settings, &c->now.inputs, dt);
    if (code == 0) {
        c->now.outputs_stale = 0;
        return fmi2OK;
    }
    if (code > 0 && code < RA_N_STEP_ERRORS && RA_STEP_ERRORS[code] != NULL)
        return fail(c, "%s: %s", function, RA_STEP_ERRORS[code]);
    return fail(c, "%s: the model's step function failed (code %d)", function, code);
}

static void start(Instance *c) {
    memset(&c->now, 0, sizeof c->now);
    c->now.magic = RA_SNAPSHOT_MAGIC;
    c->now.phase = PHASE_INSTANTIATED;
    c->now.outputs_stale = RA_FEEDTHROUGH;
    c->now.state = RA_STATE_START;
    c->now.settings = RA_SETTINGS_START;
    c->now.inputs = RA_INPUTS_START;
}

/* ---- inquiry, logging, instances ---------------------------------------------------------- */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn,
                               size_t nCategories, const fmi2String categories[]) {
    static const char *const known[] = {"logStatusError", "logStatusWarning", "logAll"};
    Instance *c = instance(component);
    if (c == NULL) return fmi2Error;
    for (size_t i = 0; i < nCategories; i++) {
        int found = 0;
        if (categories == NULL || categories[i] == NULL)
            return fail(c, "fmi2SetDebugLogging: category %u is NULL", (unsigned)i);
        for (size_t k = 0; k < sizeof known / sizeof known[0]; k++)
            found |= strcmp(categories[i], known[k]) == 0;
        if (!found)
            return fail(c, "fmi2SetDebugLogging: unknown log category '%s' (the FMU has "
                           "logStatusError, logStatusWarning, logAll)", categories[i]);
    }
    c->logging_on = loggingOn != fmi2False;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    const char *name = instanceName != NULL ? instanceName : "";
    Instance *c;
    size_t length;
    const char *code;
    (void)fmuResourceLocation; /* the model is compiled in: no resource is read */
    (void)visible;
    if (functions == NULL || functions->logger == NULL) return NULL; /* nowhere to say why */
    if (functions->allocateMemory == NULL || functions->freeMemory == NULL) {
        log_without_instance(functions, name, "fmi2Instantiate: allocateMemory and freeMemory "
                                              "must be given");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        log_without_instance(functions, name, "fmi2Instantiate: %s supports co-simulation only",
                             RA_MODEL_IDENTIFIER);
        return NULL;
    }
    if (fmuGUID == NULL || strcmp(fmuGUID, RA_GUID) != 0) {
        log_without_instance(functions, name,
                             "fmi2Instantiate: wrong GUID %s, this binary is %s (the "
                             "modelDescription.xml read by the master does not belong to it)",
                             fmuGUID != NULL ? fmuGUID : "(NULL)", RA_GUID);
        return NULL;
    }
    c = (Instance *)functions->allocateMemory(1, sizeof(Instance));
    length = strlen(name) + 1;
    if (c == NULL) {
        log_without_instance(functions, name, "fmi2Instantiate: out of memory");
        return NULL;
    }
    c->name = (char *)functions->allocateMemory(length, 1);
    if (c->name == NULL) {
        functions->freeMemory(c);
        log_without_instance(functions, name, "fmi2Instantiate: out of memory");
        return NULL;
    }
    memcpy(c->name, name, length);
    c->magic = RA_INSTANCE_MAGIC;
    c->functions = *functions;
    c->logging_on = loggingOn != fmi2False;
    c->step = choose_step(&code);
    start(c);
    log_status(c, fmi2OK, "fmi2Instantiate: %s code", code);
    return c;
}

void fmi2FreeInstance(fmi2Component component) {
    Instance *c = instance(component);
    fmi2CallbackFreeMemory release;
    if (c == NULL) return;
    release = c->functions.freeMemory;
    c->magic = 0;
    release(c->name);
    release(c);
}

/* ---- initialisation, termination ---------------------------------------------------------- */

fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Instance *c = instance_in(component, "fmi2SetupExperiment", IN_INSTANTIATED);
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    if (c == NULL) return fmi2Error;
    if (!isfinite(startTime))
        return fail(c, "fmi2SetupExperiment: startTime = %g is not finite", startTime);
    c->now.time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component component) {
    return change_phase(component, "fmi2EnterInitializationMode", IN_INSTANTIATED,
                        PHASE_INITIALIZATION);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    Instance *c = instance_in(component, "fmi2ExitInitializationMode", IN_INITIALIZATION);
    if (c == NULL) return fmi2Error;
#if RA_HAS_INIT
    {
        int code = RA_INIT(&c->now.state, &c->now.settings, &c->now.inputs);
        if (code != 0) {
            if (code > 0 && code < RA_N_STEP_ERRORS && RA_STEP_ERRORS[code] != NULL)
                return fail(c, "fmi2ExitInitializationMode: %s", RA_STEP_ERRORS[code]);
            return fail(c, "fmi2ExitInitializationMode: the model's init function failed "
                           "(code %d)", code);
        }
    }
#endif
    if (RA_FEEDTHROUGH && run_step(c, "fmi2ExitInitializationMode", 0.0) != fmi2OK)
        return fmi2Error;
    c->now.phase = PHASE_STEPPING;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component component) {
    return change_phase(component, "fmi2Terminate", IN_STEPPING | IN_ERROR, PHASE_TERMINATED);
}

fmi2Status fmi2Reset(fmi2Component component) {
    Instance *c = instance(component);
    if (c == NULL) return fmi2Error;
    start(c);
    return fmi2OK;
}

/* ---- variables ---------------------------------------------------------------------------- */

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    Instance *c = instance_in(component, "fmi2SetReal",
                              IN_INSTANTIATED | IN_INITIALIZATION | IN_STEPPING);
    size_t i;
    if (c == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL))
        return fail(c, "fmi2SetReal: vr or value is NULL");
    for (i = 0; i < nvr; i++) { /* check every value before storing any */
        const ra_variable *v;
        double x = value[i];
        if (vr[i] >= RA_N_VARIABLES)
            return fail(c, "fmi2SetReal: unknown value reference %u", (unsigned)vr[i]);
        v = &RA_VARIABLES[vr[i]];
        if (v->causality == RA_OUTPUT)
            return fail(c, "fmi2SetReal: %s is an output", v->name);
        if (v->causality == RA_PARAMETER && c->now.phase == PHASE_STEPPING)
            return fail(c, "fmi2SetReal: %s is a fixed parameter: it can be set before "
                           "fmi2ExitInitializationMode only", v->name);
        if (isnan(x)) return fail(c, "fmi2SetReal: %s = NaN", v->name);
        if (!isfinite(x)) return fail(c, "fmi2SetReal: %s = %g is not finite", v->name, x);
        if (x < v->min || (v->min_open && x == v->min) || x > v->max)
            return fail(c, "fmi2SetReal: %s = %.17g is out of range %s%.17g, %.17g%s", v->name,
                        x, v->min_open || isinf(v->min) ? "(" : "[", v->min, v->max,
                        isinf(v->max) ? ")" : "]");
    }
    for (i = 0; i < nvr; i++) {
        const ra_variable *v = &RA_VARIABLES[vr[i]];
        store(&c->now, v, value[i]);
        if (v->causality == RA_INPUT || v->causality == RA_PARAMETER)
            c->now.outputs_stale = RA_FEEDTHROUGH;
    }
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    Instance *c = instance(component);
    if (c == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL))
        return fail(c, "fmi2GetReal: vr or value is NULL");
    for (size_t i = 0; i < nvr; i++) {
        const ra_variable *v;
        if (vr[i] >= RA_N_VARIABLES)
            return fail(c, "fmi2GetReal: unknown value reference %u", (unsigned)vr[i]);
        v = &RA_VARIABLES[vr[i]];
        /* direct feedthrough: outputs follow the inputs without a step */
        if (v->causality == RA_OUTPUT && c->now.outputs_stale &&
            (c->now.phase == PHASE_INITIALIZATION || c->now.phase == PHASE_STEPPING) &&
            run_step(c, "fmi2GetReal", 0.0) != fmi2OK)
            return fmi2Error;
        value[i] = load(&c->now, v);
    }
    return fmi2OK;
}

static fmi2Status no_variables(Instance *c, const char *function, size_t nvr) {
    if (c == NULL) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(c, "%s: the FMU has no variables of this type", function);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    (void)vr, (void)value;
    return no_variables(instance(c), "fmi2GetInteger", nvr);
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    (void)vr, (void)value;
    return no_variables(instance(c), "fmi2GetBoolean", nvr);
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    (void)vr, (void)value;
    return no_variables(instance(c), "fmi2GetString", nvr);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    (void)vr, (void)value;
    return no_variables(instance(c), "fmi2SetInteger", nvr);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    (void)vr, (void)value;
    return no_variables(instance(c), "fmi2SetBoolean", nvr);
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    (void)vr, (void)value;
    return no_variables(instance(c), "fmi2SetString", nvr);
}

/* ---- FMU states: a copy of the records ---------------------------------------------------- */

fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *FMUstate) {
    Instance *c = instance_in(component, "fmi2GetFMUstate", IN_ANY & ~IN_ERROR);
    Snapshot *s;
    if (c == NULL) return fmi2Error;
    if (FMUstate == NULL) return fail(c, "fmi2GetFMUstate: FMUstate is NULL");
    s = (Snapshot *)*FMUstate;
    if (s != NULL && s->magic != RA_SNAPSHOT_MAGIC)
        return fail(c, "fmi2GetFMUstate: *FMUstate is not a state of this FMU");
    if (s == NULL) {
        s = (Snapshot *)c->functions.allocateMemory(1, sizeof(Snapshot));
        if (s == NULL) return fail(c, "fmi2GetFMUstate: out of memory");
    }
    memcpy(s, &c->now, sizeof(Snapshot));
    *FMUstate = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate FMUstate) {
    Instance *c = instance(component);
    const Snapshot *s = (const Snapshot *)FMUstate;
    if (c == NULL) return fmi2Error;
    if (s == NULL || s->magic != RA_SNAPSHOT_MAGIC)
        return fail(c, "fmi2SetFMUstate: FMUstate is not a state of this FMU");
    memcpy(&c->now, s, sizeof(Snapshot));
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component component, fmi2FMUstate *FMUstate) {
    Instance *c = instance(component);
    if (c == NULL) return fmi2Error;
    if (FMUstate == NULL) return fail(c, "fmi2FreeFMUstate: FMUstate is NULL");
    if (*FMUstate != NULL) {
        ((Snapshot *)*FMUstate)->magic = 0;
        c->functions.freeMemory(*FMUstate);
        *FMUstate = NULL;
    }
    return fmi2OK;
}

/* Serialised form: a header (magic, size, GUID checksum) and the snapshot's bytes. It is
 * meant for the same binary (a restart, a rollback across processes), not for another
 * platform. */
typedef struct {
    uint32_t magic;
    uint32_t size;
    uint64_t guid;
} SerialHeader;

static uint64_t guid_checksum(void) { /* FNV-1a of the GUID */
    uint64_t h = 14695981039346656037ull;
    for (const char *p = RA_GUID; *p != '\0'; p++) h = (h ^ (unsigned char)*p) * 1099511628211ull;
    return h;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component component, fmi2FMUstate FMUstate,
                                      size_t *size) {
    Instance *c = instance(component);
    (void)FMUstate;
    if (c == NULL) return fmi2Error;
    if (size == NULL) return fail(c, "fmi2SerializedFMUstateSize: size is NULL");
    *size = sizeof(SerialHeader) + sizeof(Snapshot);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component component, fmi2FMUstate FMUstate,
                                 fmi2Byte serializedState[], size_t size) {
    Instance *c = instance(component);
    const Snapshot *s = (const Snapshot *)FMUstate;
    SerialHeader header = {RA_SNAPSHOT_MAGIC, (uint32_t)sizeof(Snapshot), 0};
    if (c == NULL) return fmi2Error;
    if (s == NULL || s->magic != RA_SNAPSHOT_MAGIC)
        return fail(c, "fmi2SerializeFMUstate: FMUstate is not a state of this FMU");
    if (serializedState == NULL || size < sizeof header + sizeof(Snapshot))
        return fail(c, "fmi2SerializeFMUstate: the buffer must hold %u bytes",
                    (unsigned)(sizeof header + sizeof(Snapshot)));
    header.guid = guid_checksum();
    memcpy(serializedState, &header, sizeof header);
    memcpy(serializedState + sizeof header, s, sizeof(Snapshot));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component component, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate) {
    Instance *c = instance(component);
    SerialHeader header;
    Snapshot *s;
    if (c == NULL) return fmi2Error;
    if (serializedState == NULL || FMUstate == NULL)
        return fail(c, "fmi2DeSerializeFMUstate: serializedState or FMUstate is NULL");
    if (size != sizeof header + sizeof(Snapshot))
        return fail(c, "fmi2DeSerializeFMUstate: %u bytes given, a state of this FMU has %u",
                    (unsigned)size, (unsigned)(sizeof header + sizeof(Snapshot)));
    memcpy(&header, serializedState, sizeof header);
    if (header.magic != RA_SNAPSHOT_MAGIC || header.size != sizeof(Snapshot) ||
        header.guid != guid_checksum())
        return fail(c, "fmi2DeSerializeFMUstate: the bytes are not a state of this FMU");
    s = (Snapshot *)*FMUstate;
    if (s == NULL) {
        s = (Snapshot *)c->functions.allocateMemory(1, sizeof(Snapshot));
        if (s == NULL) return fail(c, "fmi2DeSerializeFMUstate: out of memory");
    }
    memcpy(s, serializedState + sizeof header, sizeof(Snapshot));
    *FMUstate = s;
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component component,
                                        const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    Instance *c = instance(component);
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown;
    (void)dvUnknown;
    if (c == NULL) return fmi2Error;
    return fail(c, "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative "
                   "is false)");
}

/* ---- co-simulation ------------------------------------------------------------------------ */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component component, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    Instance *c = instance(component);
    (void)vr, (void)nvr, (void)order, (void)value;
    if (c == NULL) return fmi2Error;
    return fail(c, "fmi2SetRealInputDerivatives: not provided (canInterpolateInputs is false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component component, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    Instance *c = instance(component);
    (void)vr, (void)nvr, (void)order, (void)value;
    if (c == NULL) return fmi2Error;
    return fail(c, "fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder is "
                   "0)");
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    Instance *c = instance_in(component, "fmi2DoStep", IN_STEPPING);
    (void)noSetFMUStatePriorToCurrentPoint;
    if (c == NULL) return fmi2Error;
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize))
        return fail(c, "fmi2DoStep: communicationStepSize must be > 0 and finite, got %g",
                    communicationStepSize);
    if (!isfinite(currentCommunicationPoint))
        return fail(c, "fmi2DoStep: currentCommunicationPoint = %g is not finite",
                    currentCommunicationPoint);
    if (run_step(c, "fmi2DoStep", communicationStepSize) != fmi2OK) return fmi2Error;
    c->now.time = currentCommunicationPoint + communicationStepSize;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component component) {
    Instance *c = instance(component);
    if (c == NULL) return fmi2Error;
    return fail(c, "fmi2CancelStep: fmi2DoStep never returns fmi2Pending");
}

static fmi2Status no_status(fmi2Component component, const char *function) {
    Instance *c = instance(component);
    if (c == NULL) return fmi2Error;
    log_status(c, fmi2Warning, "%s: no such status (fmi2DoStep never returns fmi2Pending)",
               function);
    return fmi2Discard;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetStatus");
}

fmi2Status fmi2GetRealStatus(fmi2Component component, const fmi2StatusKind s, fmi2Real *value) {
    Instance *c = instance(component);
    if (c != NULL && s == fmi2LastSuccessfulTime && value != NULL) {
        *value = c->now.time;
        return fmi2OK;
    }
    return no_status(component, "fmi2GetRealStatus");
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetIntegerStatus");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetBooleanStatus");
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s, (void)value;
    return no_status(c, "fmi2GetStringStatus");
}
