/*
 * TorsionBody: an FMI 2.0 co-simulation slave written directly against the FMI C API.
 *
 * A body of inertia J is tied by a torsional spring k and damper d to the flange of another
 * body.  Inputs are that flange's angle and speed; during doStep(t, h) the flange is taken to
 * move at its held speed, so the relative coordinate y = phi - (phi_in + w_in*s),
 * v = w - w_in obeys J y'' + d y' + k y = 0.  That ODE is integrated with classical RK4 over
 * n_sub equal substeps, and the flange angle input is advanced by w_in*h at the end of the
 * step.  Output flange.tau = -(k*(phi_in - phi) + d*(w_in - w)) is the torque on the other
 * body (direct feedthrough: recomputed whenever an input is set).
 *
 * Build macros:
 *   TORSION_BODY_GUID       string the instantiation token must equal (required)
 *   TORSION_BODY_FMU_STATE  if defined, fmi2Get/Set/FreeFMUstate copy the state; otherwise
 *                           they report fmi2Error (canGetAndSetFMUstate="false")
 *   TORSION_BODY_PHI0_DEG   if defined, the parameter body.phi0 is in degrees (its declared
 *                           unit "deg"), as tools that are not SI inside declare angles
 *   TORSION_BODY_FAULT      if defined, a misbehaviour a host must survive, from the first
 *                           doStep that starts at or after TORSION_BODY_FAULT_TIME [s]:
 *                           FAULT_SEGFAULT, FAULT_ABORT, FAULT_EXIT (doStep writes through a
 *                           null pointer, calls abort(), calls exit(3)), FAULT_GET_REAL
 *                           (fmi2GetReal fails), FAULT_TERMINATE (doStep returns fmi2Discard
 *                           and fmi2Terminated is true: the model asks to end the simulation);
 *                           and at any time FAULT_GET_STATE (fmi2GetFMUstate fails),
 *                           FAULT_INSTANTIATE (fmi2Instantiate returns NULL); from the fault
 *                           time on also FAULT_HANG (doStep never returns), FAULT_STOP (doStep
 *                           raises SIGSTOP), FAULT_WARNING (doStep logs a warning and returns
 *                           fmi2Warning), FAULT_LOG_WARNING (doStep logs in category
 *                           "logStatusWarning" and returns fmi2OK), FAULT_LONG_ERROR (doStep
 *                           logs 2000 lines, then one of 100000 characters, and returns
 *                           fmi2Error), FAULT_BY_N_SUB (n_sub 101, 102, 103 choose
 *                           FAULT_SEGFAULT, FAULT_HANG, FAULT_STOP; any other runs as built
 *                           without a fault); FAULT_TERMINATE_SEGFAULT (fmi2Terminate
 *                           writes through a null pointer); and FAULT_TERMINATE_AFTER (doStep
 *                           completes the step, then returns fmi2Discard with fmi2Terminated
 *                           true: fmi2LastSuccessfulTime is the step's end, as the Reference
 *                           FMU Stair ends on its last event)
 *   TORSION_BODY_INPUT_DERIVATIVES  if defined, fmi2SetRealInputDerivatives takes the first
 *                           derivative of flange.w (canInterpolateInputs="true"): over the
 *                           next steps the flange moves at w_in + a*s (a the derivative, until
 *                           set again), so the relative motion obeys J y'' + d y' + k y = -J a;
 *                           a derivative of flange.phi is accepted and not used (the flange's
 *                           angle follows its speed), other orders and variables are errors
 *   TORSION_BODY_FLAGS      if defined, two more outputs: the Boolean body.ahead (vr 0: the
 *                           body's angle is ahead of the flange's) and the String body.label
 *                           (vr 0: "TorsionBody")
 */

#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

#ifndef TORSION_BODY_GUID
#error "define TORSION_BODY_GUID to the GUID written into modelDescription.xml"
#endif

/* Real value references (the Integer n_sub has its own, distinct one). */
enum {
    VR_J = 0,       /* body.J */
    VR_K = 1,       /* spring.k */
    VR_D = 2,       /* spring.d */
    VR_PHI0 = 3,    /* body.phi0 */
    VR_W0 = 4,      /* body.w0 */
    VR_PHI_IN = 5,  /* flange.phi */
    VR_W_IN = 6,    /* flange.w */
    VR_PHI = 7,     /* body.phi */
    VR_W = 8,       /* body.w */
    VR_TAU = 9,     /* flange.tau */
    N_REALS = 10
};
#define VR_N_SUB 10 /* n_sub (Integer) */

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_STEP, MODE_TERMINATED } Mode;

/* Everything an FMU state snapshot has to hold. */
typedef struct {
    fmi2Real r[N_REALS];
    fmi2Integer n_sub;
    fmi2Real time;
    Mode mode;
    fmi2Boolean terminated; /* the model asked to end the simulation */
    fmi2Real dw_in;         /* the derivative of flange.w set (0: held) */
} ModelState;

/* Values of TORSION_BODY_FAULT (macros: the preprocessor compares them). */
#define FAULT_SEGFAULT 1
#define FAULT_ABORT 2
#define FAULT_EXIT 3
#define FAULT_GET_REAL 4
#define FAULT_TERMINATE 5
#define FAULT_GET_STATE 6
#define FAULT_INSTANTIATE 7
#define FAULT_HANG 8
#define FAULT_STOP 9
#define FAULT_WARNING 10
#define FAULT_LOG_WARNING 11
#define FAULT_LONG_ERROR 12
#define FAULT_BY_N_SUB 13
#define FAULT_TERMINATE_SEGFAULT 14
#define FAULT_TERMINATE_AFTER 15
#ifndef TORSION_BODY_FAULT_TIME
#define TORSION_BODY_FAULT_TIME 0.0
#endif

typedef struct {
    ModelState s;
    fmi2CallbackFunctions cb;
    char *instance_name;
    fmi2Boolean logging_on;
} Instance;

static void log_message(Instance *inst, fmi2Status status, const char *category,
                        const char *fmt, ...) {
    char buf[512];
    va_list args;
    if (inst == NULL || inst->cb.logger == NULL) return;
    if (status == fmi2OK && !inst->logging_on) return;
    va_start(args, fmt);
    vsnprintf(buf, sizeof buf, fmt, args);
    va_end(args);
    /* The logger's message is a printf format (FMI 2.0, 2.1.5): pass the text as an argument
       so that a '%' in it (say, in a GUID the caller sent) cannot be taken for a directive. */
    inst->cb.logger(inst->cb.componentEnvironment, inst->instance_name, status, category, "%s",
                    buf);
}

#define LOG_ERROR(inst, ...) log_message((inst), fmi2Error, "logStatusError", __VA_ARGS__)

static int is_parameter(fmi2ValueReference vr) { return vr <= VR_W0; }

#ifdef TORSION_BODY_PHI0_DEG
#define PHI0_TO_RAD (3.14159265358979323846 / 180.0)
#else
#define PHI0_TO_RAD 1.0
#endif

/* Outputs as a function of the current state and inputs.  Before the first step the body
   sits at its start values, so outputs track the parameters while they are being set. */
static void update_outputs(Instance *inst) {
    fmi2Real *r = inst->s.r;
    if (inst->s.mode == MODE_INSTANTIATED || inst->s.mode == MODE_INITIALIZATION) {
        r[VR_PHI] = PHI0_TO_RAD * r[VR_PHI0];
        r[VR_W] = r[VR_W0];
    }
    r[VR_TAU] = -(r[VR_K] * (r[VR_PHI_IN] - r[VR_PHI]) + r[VR_D] * (r[VR_W_IN] - r[VR_W]));
}

/* Start values, as declared in modelDescription.xml. */
static void set_start_values(Instance *inst) {
    fmi2Real *r = inst->s.r;
    r[VR_J] = 1e-4;
    r[VR_K] = 2.0;
    r[VR_D] = 2e-3;
    r[VR_PHI0] = 0.0;
    r[VR_W0] = 0.0;
    r[VR_PHI_IN] = 0.0;
    r[VR_W_IN] = 0.0;
    inst->s.n_sub = 10;
    inst->s.time = 0.0;
    inst->s.mode = MODE_INSTANTIATED;
    inst->s.terminated = fmi2False;
    inst->s.dw_in = 0.0;
    update_outputs(inst);
}

/* ---- common functions ------------------------------------------------------------------ */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    Instance *inst = (Instance *)c;
    (void)nCategories;
    (void)categories;
    if (inst == NULL) return fmi2Error;
    inst->logging_on = loggingOn;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    Instance *inst;
    size_t name_length;
    (void)fmuResourceLocation;
    (void)visible;
    if (functions == NULL || functions->allocateMemory == NULL || functions->freeMemory == NULL)
        return NULL;
    if (instanceName == NULL) instanceName = "";
    inst = (Instance *)functions->allocateMemory(1, sizeof(Instance));
    if (inst == NULL) return NULL;
    inst->cb = *functions;
    inst->logging_on = loggingOn;
    name_length = strlen(instanceName) + 1;
    inst->instance_name = (char *)functions->allocateMemory(name_length, 1);
    if (inst->instance_name == NULL) {
        functions->freeMemory(inst);
        return NULL;
    }
    memcpy(inst->instance_name, instanceName, name_length);

    if (fmuType != fmi2CoSimulation) {
        LOG_ERROR(inst, "TorsionBody supports co-simulation only");
        goto fail;
    }
    if (fmuGUID == NULL || strcmp(fmuGUID, TORSION_BODY_GUID) != 0) {
        LOG_ERROR(inst, "wrong GUID \"%s\", this binary expects \"%s\"",
                  fmuGUID ? fmuGUID : "(null)", TORSION_BODY_GUID);
        goto fail;
    }
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT == FAULT_INSTANTIATE
    LOG_ERROR(inst, "cannot open the license file %s (error %d)", "torsion.lic", 2);
    goto fail;
#endif

    set_start_values(inst);
    return inst;

fail:
    functions->freeMemory(inst->instance_name);
    functions->freeMemory(inst);
    return NULL;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *inst = (Instance *)c;
    fmi2CallbackFreeMemory free_memory;
    if (inst == NULL) return;
    free_memory = inst->cb.freeMemory;
    free_memory(inst->instance_name);
    free_memory(inst);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    Instance *inst = (Instance *)c;
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    if (inst == NULL) return fmi2Error;
    if (inst->s.mode != MODE_INSTANTIATED) {
        LOG_ERROR(inst, "fmi2SetupExperiment is allowed only right after instantiation");
        return fmi2Error;
    }
    inst->s.time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    if (inst->s.mode != MODE_INSTANTIATED) {
        LOG_ERROR(inst, "fmi2EnterInitializationMode called in the wrong state");
        return fmi2Error;
    }
    inst->s.mode = MODE_INITIALIZATION;
    update_outputs(inst);
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *inst = (Instance *)c;
    const fmi2Real *r;
    if (inst == NULL) return fmi2Error;
    r = inst->s.r;
    if (inst->s.mode != MODE_INITIALIZATION) {
        LOG_ERROR(inst, "fmi2ExitInitializationMode called outside initialization mode");
        return fmi2Error;
    }
    if (!(r[VR_J] > 0.0) || !(r[VR_K] >= 0.0) || !(r[VR_D] >= 0.0) || !isfinite(r[VR_J]) ||
        !isfinite(r[VR_K]) || !isfinite(r[VR_D])) {
        LOG_ERROR(inst, "need finite body.J > 0, spring.k >= 0, spring.d >= 0; got %g, %g, %g",
                  r[VR_J], r[VR_K], r[VR_D]);
        return fmi2Error;
    }
    if (inst->s.n_sub < 1) {
        LOG_ERROR(inst, "n_sub must be at least 1, got %d", inst->s.n_sub);
        return fmi2Error;
    }
    update_outputs(inst); /* body.phi, body.w <- start values */
    inst->s.mode = MODE_STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    inst->s.mode = MODE_TERMINATED;
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT == FAULT_TERMINATE_SEGFAULT
    {
        volatile int *volatile nowhere = NULL;
        *nowhere = 1;
    }
#endif
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    set_start_values(inst);
    return fmi2OK;
}

/* ---- variable access ------------------------------------------------------------------- */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL)) return fmi2Error;
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT == FAULT_GET_REAL
    if (inst->s.time >= TORSION_BODY_FAULT_TIME) {
        LOG_ERROR(inst, "fmi2GetReal: sensor %s lost at t = %g s", "flange.tau", inst->s.time);
        return fmi2Error;
    }
#endif
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) {
            LOG_ERROR(inst, "fmi2GetReal: unknown value reference %u", vr[i]);
            return fmi2Error;
        }
        value[i] = inst->s.r[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != VR_N_SUB) {
            LOG_ERROR(inst, "fmi2GetInteger: unknown value reference %u", vr[i]);
            return fmi2Error;
        }
        value[i] = inst->s.n_sub;
    }
    return fmi2OK;
}

#ifdef TORSION_BODY_FLAGS

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != 0) {
            LOG_ERROR(inst, "fmi2GetBoolean: unknown value reference %u", vr[i]);
            return fmi2Error;
        }
        value[i] = inst->s.r[VR_PHI] > inst->s.r[VR_PHI_IN] ? fmi2True : fmi2False;
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != 0) {
            LOG_ERROR(inst, "fmi2GetString: unknown value reference %u", vr[i]);
            return fmi2Error;
        }
        value[i] = "TorsionBody";
    }
    return fmi2OK;
}

#else

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    Instance *inst = (Instance *)c;
    (void)vr;
    (void)value;
    if (inst == NULL) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    LOG_ERROR(inst, "TorsionBody has no Boolean variables");
    return fmi2Error;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    Instance *inst = (Instance *)c;
    (void)vr;
    (void)value;
    if (inst == NULL) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    LOG_ERROR(inst, "TorsionBody has no String variables");
    return fmi2Error;
}

#endif

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] > VR_W_IN) {
            LOG_ERROR(inst, "fmi2SetReal: value reference %u is not a parameter or input",
                      vr[i]);
            return fmi2Error;
        }
        /* fixed parameters may change only before the end of initialization */
        if (is_parameter(vr[i]) && inst->s.mode != MODE_INSTANTIATED &&
            inst->s.mode != MODE_INITIALIZATION) {
            LOG_ERROR(inst, "fmi2SetReal: parameter %u is fixed after initialization", vr[i]);
            return fmi2Error;
        }
    }
    for (i = 0; i < nvr; i++) inst->s.r[vr[i]] = value[i];
    update_outputs(inst);
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    if (nvr > 0 && (vr == NULL || value == NULL)) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] != VR_N_SUB) {
            LOG_ERROR(inst, "fmi2SetInteger: unknown value reference %u", vr[i]);
            return fmi2Error;
        }
        if (inst->s.mode != MODE_INSTANTIATED && inst->s.mode != MODE_INITIALIZATION) {
            LOG_ERROR(inst, "fmi2SetInteger: n_sub is fixed after initialization");
            return fmi2Error;
        }
    }
    for (i = 0; i < nvr; i++) inst->s.n_sub = value[i];
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    Instance *inst = (Instance *)c;
    (void)vr;
    (void)value;
    if (inst == NULL) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    LOG_ERROR(inst, "TorsionBody has no Boolean variables");
    return fmi2Error;
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    Instance *inst = (Instance *)c;
    (void)vr;
    (void)value;
    if (inst == NULL) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    LOG_ERROR(inst, "TorsionBody has no String variables");
    return fmi2Error;
}

/* ---- FMU state ------------------------------------------------------------------------- */

#ifdef TORSION_BODY_FMU_STATE

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    Instance *inst = (Instance *)c;
    ModelState *copy;
    if (inst == NULL || FMUstate == NULL) return fmi2Error;
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT == FAULT_GET_STATE
    LOG_ERROR(inst, "fmi2GetFMUstate: no memory for a snapshot of %d bytes", (int)sizeof(ModelState));
    return fmi2Error;
#endif
    copy = (ModelState *)*FMUstate;
    if (copy == NULL) { /* a new snapshot; an existing one is overwritten in place */
        copy = (ModelState *)inst->cb.allocateMemory(1, sizeof(ModelState));
        if (copy == NULL) {
            LOG_ERROR(inst, "fmi2GetFMUstate: out of memory");
            return fmi2Error;
        }
    }
    *copy = inst->s;
    *FMUstate = copy;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    if (FMUstate == NULL) {
        LOG_ERROR(inst, "fmi2SetFMUstate: null state");
        return fmi2Error;
    }
    inst->s = *(const ModelState *)FMUstate;
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    Instance *inst = (Instance *)c;
    if (inst == NULL || FMUstate == NULL) return fmi2Error;
    if (*FMUstate != NULL) inst->cb.freeMemory(*FMUstate);
    *FMUstate = NULL;
    return fmi2OK;
}

#else

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    (void)FMUstate;
    LOG_ERROR((Instance *)c, "this build of TorsionBody cannot get or set its FMU state");
    return fmi2Error;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate FMUstate) {
    (void)FMUstate;
    LOG_ERROR((Instance *)c, "this build of TorsionBody cannot get or set its FMU state");
    return fmi2Error;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *FMUstate) {
    (void)FMUstate;
    LOG_ERROR((Instance *)c, "this build of TorsionBody cannot get or set its FMU state");
    return fmi2Error;
}

#endif

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate FMUstate, size_t *size) {
    (void)FMUstate;
    (void)size;
    LOG_ERROR((Instance *)c, "TorsionBody cannot serialize its FMU state");
    return fmi2Error;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate FMUstate,
                                 fmi2Byte serializedState[], size_t size) {
    (void)FMUstate;
    (void)serializedState;
    (void)size;
    LOG_ERROR((Instance *)c, "TorsionBody cannot serialize its FMU state");
    return fmi2Error;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte serializedState[],
                                   size_t size, fmi2FMUstate *FMUstate) {
    (void)serializedState;
    (void)size;
    (void)FMUstate;
    LOG_ERROR((Instance *)c, "TorsionBody cannot serialize its FMU state");
    return fmi2Error;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    LOG_ERROR((Instance *)c, "TorsionBody provides no directional derivatives");
    return fmi2Error;
}

/* ---- co-simulation --------------------------------------------------------------------- */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
#ifdef TORSION_BODY_INPUT_DERIVATIVES
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (order[i] != 1 || (vr[i] != VR_W_IN && vr[i] != VR_PHI_IN) || !isfinite(value[i])) {
            LOG_ERROR(inst, "fmi2SetRealInputDerivatives: order %d of value reference %u is "
                      "not taken (first derivatives of flange.phi and flange.w only)",
                      (int)order[i], (unsigned)vr[i]);
            return fmi2Error;
        }
    }
    for (i = 0; i < nvr; i++)
        if (vr[i] == VR_W_IN) inst->s.dw_in = value[i];
    return fmi2OK;
#else
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    LOG_ERROR((Instance *)c, "TorsionBody cannot interpolate inputs");
    return fmi2Error;
#endif
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    LOG_ERROR((Instance *)c, "TorsionBody provides no output derivatives");
    return fmi2Error;
}

/* Right-hand side of the relative motion: y' = v, v' = -(d v + k y) / J (- a, the flange's
 * acceleration, where input derivatives are taken). */
#ifdef TORSION_BODY_INPUT_DERIVATIVES
#define FLANGE_ACCELERATION(inst) ((inst)->s.dw_in)
#else
#define FLANGE_ACCELERATION(inst) 0.0
#endif
static fmi2Real relative_acceleration(const fmi2Real *r, fmi2Real y, fmi2Real v) {
    return -(r[VR_D] * v + r[VR_K] * y) / r[VR_J];
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    Instance *inst = (Instance *)c;
    fmi2Real *r;
    fmi2Real h = communicationStepSize, hs, y, v, a;
    fmi2Integer i, n;
    fmi2Status status = fmi2OK; /* fmi2Warning under FAULT_WARNING */
    (void)noSetFMUStatePriorToCurrentPoint;
    if (inst == NULL) return fmi2Error;
    r = inst->s.r;
    if (inst->s.mode != MODE_STEP) {
        LOG_ERROR(inst, "fmi2DoStep called outside step mode");
        return fmi2Error;
    }
    if (!isfinite(currentCommunicationPoint)) {
        LOG_ERROR(inst, "fmi2DoStep: currentCommunicationPoint must be finite, got %g",
                  currentCommunicationPoint);
        return fmi2Error;
    }
    if (!isfinite(h) || !(h > 0.0)) {
        LOG_ERROR(inst, "fmi2DoStep: communicationStepSize must be finite and > 0, got %g", h);
        return fmi2Error;
    }
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT <= FAULT_TERMINATE
    if (currentCommunicationPoint >= TORSION_BODY_FAULT_TIME - 1e-12) {
#if TORSION_BODY_FAULT == FAULT_SEGFAULT
        volatile int *volatile nowhere = NULL;
        *nowhere = 1;
#elif TORSION_BODY_FAULT == FAULT_ABORT
        abort();
#elif TORSION_BODY_FAULT == FAULT_EXIT
        exit(3);
#elif TORSION_BODY_FAULT == FAULT_TERMINATE
        inst->s.terminated = fmi2True;
        log_message(inst, fmi2Discard, "logStatusDiscard", "end stop reached at t = %g s",
                    currentCommunicationPoint);
        return fmi2Discard;
#endif
    }
#endif
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT >= FAULT_HANG && \
    TORSION_BODY_FAULT <= FAULT_BY_N_SUB
    if (currentCommunicationPoint >= TORSION_BODY_FAULT_TIME - 1e-12) {
        int fault = TORSION_BODY_FAULT;
        if (fault == FAULT_BY_N_SUB) {
            fault = inst->s.n_sub == 101   ? FAULT_SEGFAULT
                    : inst->s.n_sub == 102 ? FAULT_HANG
                    : inst->s.n_sub == 103 ? FAULT_STOP
                                           : 0;
        }
        if (fault == FAULT_SEGFAULT) {
            volatile int *volatile nowhere = NULL;
            *nowhere = 1;
        } else if (fault == FAULT_HANG) {
            volatile unsigned long spin = 0;
            for (;;) spin++;
        } else if (fault == FAULT_STOP) {
            raise(SIGSTOP);
        } else if (fault == FAULT_WARNING) {
            log_message(inst, fmi2Warning, "logStatusWarning", "step of %g s larger than advised",
                        h);
            status = fmi2Warning;
        } else if (fault == FAULT_LOG_WARNING) {
            log_message(inst, fmi2OK, "logStatusWarning", "spring beyond its linear range at t = %g s",
                        currentCommunicationPoint);
        } else if (fault == FAULT_LONG_ERROR) {
            static char line[100001];
            for (i = 0; i < 2000; i++) log_message(inst, fmi2OK, "logAll", "line %d", (int)i);
            memset(line, 'x', sizeof line - 1);
            line[sizeof line - 1] = '\0';
            inst->cb.logger(inst->cb.componentEnvironment, inst->instance_name, fmi2Error,
                            "logStatusError", "%s", line);
            return fmi2Error;
        }
    }
#endif

    n = inst->s.n_sub;
    hs = h / n;
    a = FLANGE_ACCELERATION(inst);
    y = r[VR_PHI] - r[VR_PHI_IN];
    v = r[VR_W] - r[VR_W_IN];
    for (i = 0; i < n; i++) {
        fmi2Real k1y, k1v, k2y, k2v, k3y, k3v, k4y, k4v;
        k1y = v;
        k1v = relative_acceleration(r, y, v) - a;
        k2y = v + 0.5 * hs * k1v;
        k2v = relative_acceleration(r, y + 0.5 * hs * k1y, v + 0.5 * hs * k1v) - a;
        k3y = v + 0.5 * hs * k2v;
        k3v = relative_acceleration(r, y + 0.5 * hs * k2y, v + 0.5 * hs * k2v) - a;
        k4y = v + hs * k3v;
        k4v = relative_acceleration(r, y + hs * k3y, v + hs * k3v) - a;
        y = y + hs / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y);
        v = v + hs / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
    if (!isfinite(y) || !isfinite(v)) {
        LOG_ERROR(inst, "fmi2DoStep: the state is no longer finite (step size too large?)");
        return fmi2Error;
    }
    r[VR_PHI_IN] = r[VR_PHI_IN] + r[VR_W_IN] * h;
#ifdef TORSION_BODY_INPUT_DERIVATIVES
    r[VR_PHI_IN] += 0.5 * a * h * h;
    r[VR_W_IN] += a * h;
#endif
    r[VR_PHI] = r[VR_PHI_IN] + y;
    r[VR_W] = r[VR_W_IN] + v;
    inst->s.time = currentCommunicationPoint + h;
    update_outputs(inst);
#if defined(TORSION_BODY_FAULT) && TORSION_BODY_FAULT == FAULT_TERMINATE_AFTER
    if (currentCommunicationPoint >= TORSION_BODY_FAULT_TIME - 1e-12) {
        inst->s.terminated = fmi2True;
        log_message(inst, fmi2Discard, "logStatusDiscard", "end stop reached at t = %g s",
                    inst->s.time);
        return fmi2Discard;
    }
#endif
    return status;
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    LOG_ERROR((Instance *)c, "fmi2CancelStep: TorsionBody never runs asynchronously");
    return fmi2Error;
}

/* The slave never runs asynchronously, so there is no pending status to report. */
static fmi2Status no_status(void) { return fmi2Discard; }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)c;
    (void)s;
    (void)value;
    return no_status();
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    Instance *inst = (Instance *)c;
    if (inst != NULL && s == fmi2LastSuccessfulTime && value != NULL) {
        *value = inst->s.time;
        return fmi2OK;
    }
    return no_status();
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)c;
    (void)s;
    (void)value;
    return no_status();
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    Instance *inst = (Instance *)c;
    if (inst != NULL && s == fmi2Terminated && value != NULL) {
        *value = inst->s.terminated;
        return fmi2OK;
    }
    return no_status();
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)c;
    (void)s;
    (void)value;
    return no_status();
}
