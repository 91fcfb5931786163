/*
 * PiController: an FMI 2.0 co-simulation slave written directly against the FMI C API, with
 * the initialization of a controller exported from a Modelica tool whose initial equations
 * have a solution only for a zero set point.
 *
 * Inputs u_s (set point) and u_m (measurement); the error e = u_s - u_m is integrated in x
 * (held over a step, so x += e*h is exact) and the output is y = kp*e + ki*x (direct
 * feedthrough: recomputed whenever an input is set).  fmi2ExitInitializationMode fails with
 * fmi2Error unless u_s is 0 then.
 *
 * Build macros: PI_CONTROLLER_GUID, the string the instantiation token must equal;
 * PI_CONTROLLER_FORGETS_INTEGRATOR, fmi2SetFMUstate restores everything but the integrator x
 * (a faulty state restore: a rolled-back step keeps its integral); with
 * PI_CONTROLLER_FORGETS_AFTER_JUMP as well, it does so only once the set point has left the
 * value it had at the first step (a fault that shows only after a set-point jump, as a
 * limiter flag restored wrongly does).
 */

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"

#ifndef PI_CONTROLLER_GUID
#error "define PI_CONTROLLER_GUID to the GUID written into modelDescription.xml"
#endif

enum { VR_KP = 0, VR_KI = 1, VR_US = 2, VR_UM = 3, VR_Y = 4, VR_X = 5, N_REALS = 6 };

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_STEP, MODE_TERMINATED } Mode;

typedef struct {
    fmi2Real r[N_REALS];
    fmi2Real time;
    Mode mode;
} ModelState;

typedef struct {
    ModelState s;
    fmi2CallbackFunctions cb;
    char *instance_name;
    /* Not part of the state: the set point at the first step, and whether it has left it. */
    fmi2Real first_set_point;
    int stepped, jumped;
} Instance;

static void log_error(Instance *inst, const char *fmt, ...) {
    char buf[512];
    va_list args;
    if (inst == NULL || inst->cb.logger == NULL) return;
    va_start(args, fmt);
    vsnprintf(buf, sizeof buf, fmt, args);
    va_end(args);
    /* The text itself as the format: it holds no '%' (numbers are written with %g), and a
       host whose logger does not expand printf arguments still shows it. */
    inst->cb.logger(inst->cb.componentEnvironment, inst->instance_name, fmi2Error,
                    "logStatusError", buf);
}

static void update_output(Instance *inst) {
    fmi2Real *r = inst->s.r;
    r[VR_Y] = r[VR_KP] * (r[VR_US] - r[VR_UM]) + r[VR_KI] * r[VR_X];
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)on;
    (void)n;
    (void)cat;
    return c == NULL ? fmi2Error : fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                              fmi2String resources, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    Instance *inst;
    (void)resources;
    (void)visible;
    (void)loggingOn;
    if (functions == NULL || functions->allocateMemory == NULL || functions->freeMemory == NULL)
        return NULL;
    if (type != fmi2CoSimulation || guid == NULL || strcmp(guid, PI_CONTROLLER_GUID) != 0)
        return NULL;
    inst = (Instance *)functions->allocateMemory(1, sizeof(Instance));
    if (inst == NULL) return NULL;
    inst->cb = *functions;
    inst->instance_name = (char *)functions->allocateMemory(strlen(name) + 1, 1);
    if (inst->instance_name == NULL) {
        functions->freeMemory(inst);
        return NULL;
    }
    strcpy(inst->instance_name, name);
    inst->s.r[VR_KP] = 2e-3;
    inst->s.r[VR_KI] = 1e-2;
    inst->s.r[VR_US] = 0.0;
    inst->s.r[VR_UM] = 0.0;
    inst->s.r[VR_X] = 0.0;
    inst->s.time = 0.0;
    inst->first_set_point = 0.0;
    inst->stepped = 0;
    inst->jumped = 0;
    inst->s.mode = MODE_INSTANTIATED;
    update_output(inst);
    return inst;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return;
    inst->cb.freeMemory(inst->instance_name);
    inst->cb.freeMemory(inst);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDefined, fmi2Real tol,
                               fmi2Real start, fmi2Boolean stopDefined, fmi2Real stop) {
    Instance *inst = (Instance *)c;
    (void)tolDefined;
    (void)tol;
    (void)stopDefined;
    (void)stop;
    if (inst == NULL) return fmi2Error;
    inst->s.time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    inst->s.mode = MODE_INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    if (inst->s.r[VR_US] != 0.0) {
        log_error(inst, "the initial equations have no solution for the set point u_s = %g "
                        "(it must be 0 during initialization)", inst->s.r[VR_US]);
        return fmi2Error;
    }
    inst->s.r[VR_X] = 0.0;
    update_output(inst);
    inst->s.mode = MODE_STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    Instance *inst = (Instance *)c;
    if (inst == NULL) return fmi2Error;
    inst->s.mode = MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) { return c == NULL ? fmi2Error : fmi2Error; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fmi2Error;
        value[i] = inst->s.r[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    Instance *inst = (Instance *)c;
    size_t i;
    if (inst == NULL) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        if (vr[i] > VR_UM) return fmi2Error; /* parameters and inputs only */
        if (vr[i] <= VR_KI && inst->s.mode == MODE_STEP) return fmi2Error;
        inst->s.r[vr[i]] = value[i];
    }
    update_output(inst);
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)c; (void)vr; (void)v;
    return n == 0 ? fmi2OK : fmi2Error;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)c; (void)vr; (void)v;
    return n == 0 ? fmi2OK : fmi2Error;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)c; (void)vr; (void)v;
    return n == 0 ? fmi2OK : fmi2Error;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    (void)c; (void)vr; (void)v;
    return n == 0 ? fmi2OK : fmi2Error;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)c; (void)vr; (void)v;
    return n == 0 ? fmi2OK : fmi2Error;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)c; (void)vr; (void)v;
    return n == 0 ? fmi2OK : fmi2Error;
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Instance *inst = (Instance *)c;
    ModelState *copy;
    if (inst == NULL || state == NULL) return fmi2Error;
    copy = (ModelState *)(*state != NULL ? *state : inst->cb.allocateMemory(1, sizeof(ModelState)));
    if (copy == NULL) return fmi2Error;
    *copy = inst->s;
    *state = copy;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    Instance *inst = (Instance *)c;
    if (inst == NULL || state == NULL) return fmi2Error;
#ifdef PI_CONTROLLER_FORGETS_INTEGRATOR
#ifdef PI_CONTROLLER_FORGETS_AFTER_JUMP
    if (!inst->jumped) {
        inst->s = *(ModelState *)state;
        return fmi2OK;
    }
#endif
    {
        /* The fault of a tool's export: the integrator is not part of what is restored,
           so a restored controller keeps the integral it had reached. */
        fmi2Real x = inst->s.r[VR_X];
        inst->s = *(ModelState *)state;
        inst->s.r[VR_X] = x;
        update_output(inst);
    }
#else
    inst->s = *(ModelState *)state;
#endif
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    Instance *inst = (Instance *)c;
    if (inst == NULL || state == NULL) return fmi2Error;
    if (*state != NULL) inst->cb.freeMemory(*state);
    *state = NULL;
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    (void)c; (void)s; (void)size;
    return fmi2Error;
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)c; (void)s; (void)b; (void)n;
    return fmi2Error;
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)c; (void)b; (void)n; (void)s;
    return fmi2Error;
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real dz[], fmi2Real du[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dz; (void)du;
    return fmi2Error;
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real v[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)v;
    return fmi2Error;
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real v[]) {
    (void)c; (void)vr; (void)n; (void)order; (void)v;
    return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    Instance *inst = (Instance *)c;
    fmi2Real *r;
    (void)noSetPrior;
    if (inst == NULL || inst->s.mode != MODE_STEP) return fmi2Error;
    if (!(h > 0.0)) {
        log_error(inst, "doStep: step size %g is not positive", h);
        return fmi2Error;
    }
    r = inst->s.r;
    if (!inst->stepped) {
        inst->first_set_point = r[VR_US];
        inst->stepped = 1;
    } else if (r[VR_US] != inst->first_set_point) {
        inst->jumped = 1;
    }
    r[VR_X] += (r[VR_US] - r[VR_UM]) * h;
    inst->s.time = t + h;
    update_output(inst);
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v) {
    (void)c; (void)k; (void)v;
    return fmi2Discard;
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v) {
    Instance *inst = (Instance *)c;
    if (inst == NULL || k != fmi2LastSuccessfulTime) return fmi2Discard;
    *v = inst->s.time;
    return fmi2OK;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v) {
    (void)c; (void)k; (void)v;
    return fmi2Discard;
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) {
    (void)c; (void)k; (void)v;
    return fmi2Discard;
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v) {
    (void)c; (void)k; (void)v;
    return fmi2Discard;
}
