# cython: language_level=3, binding=True, boundscheck=False, wraparound=False
# cython: cdivision=False, initializedcheck=False
"""Compiled twins of the press feed's hot paths: the RSSR rocker kinematics
(components.rssr_kinematics), the coupler equation and the rocker motion
(components.crank_coupler_drive), the drive's loop between events (event_integration.advance
for its _CouplerMotion), and the monolithic reference's right-hand side, signals and
observer (orchestrator.scenes.press_feed.monolithic._Nonlinear).

Each function repeats its Python original operation for operation, in the same order, so
that results are the same bits: ``x ** y`` is libm's pow as in CPython (built with
-fno-builtin, no fast math, no FMA contraction), a division by zero and the sine of an
infinity raise what Python raises.  ``components.kernels`` loads this module; without it
the Python originals run.
"""

from libc.math cimport INFINITY, atan, fabs, fmod, isinf, pow, sqrt
from libc.math cimport cos as c_cos, sin as c_sin

import numpy as np

cdef enum:
    NY = 5  # the drive's state: phi1, q, q', W_in, W_diss
    NY_REFERENCE = 11  # the monolithic reference's (monolithic.NY)

# Dormand-Prince 5(4) coefficients (components.event_integration).
cdef double A21 = 1.0 / 5.0
cdef double A31 = 3.0 / 40.0, A32 = 9.0 / 40.0
cdef double A41 = 44.0 / 45.0, A42 = -56.0 / 15.0, A43 = 32.0 / 9.0
cdef double A51 = 19372.0 / 6561.0, A52 = -25360.0 / 2187.0
cdef double A53 = 64448.0 / 6561.0, A54 = -212.0 / 729.0
cdef double A61 = 9017.0 / 3168.0, A62 = -355.0 / 33.0, A63 = 46732.0 / 5247.0
cdef double A64 = 49.0 / 176.0, A65 = -5103.0 / 18656.0
cdef double B1 = 35.0 / 384.0, B3 = 500.0 / 1113.0, B4 = 125.0 / 192.0
cdef double B5 = -2187.0 / 6784.0, B6 = 11.0 / 84.0
cdef double E1 = 71.0 / 57600.0, E3 = -71.0 / 16695.0, E4 = 71.0 / 1920.0
cdef double E5 = -17253.0 / 339200.0, E6 = 22.0 / 525.0, E7 = -1.0 / 40.0
cdef double D1 = -12715105075.0 / 11282082432.0
cdef double D3 = 87487479700.0 / 32700410799.0
cdef double D4 = -10690763975.0 / 1880347072.0
cdef double D5 = 701980252875.0 / 199316789632.0
cdef double D6 = -1453857185.0 / 822651844.0
cdef double D7 = 69997945.0 / 29380423.0

cdef double SAFETY = 0.9, GROW_MAX = 5.0, SHRINK_MIN = 0.2, EXPONENT = 0.2
cdef double SHRINK_ON_FAILURE = 0.25, H_MIN_RELATIVE = 1e-14, H_MIN_ABSOLUTE = 1e-16


cdef inline double _sin(double x) except? -2.0:
    if isinf(x):
        raise ValueError("math domain error")
    return c_sin(x)


cdef inline double _cos(double x) except? -2.0:
    if isinf(x):
        raise ValueError("math domain error")
    return c_cos(x)


cdef inline double _sqrt(double x) except? -2.0:
    if x < 0.0:
        raise ValueError("math domain error")
    return sqrt(x)


cdef double _pow(double x, double y) except? -2.0:
    """CPython's float ** float for the real cases: libm's pow on |x|, the sign after."""
    cdef bint negate = False
    cdef double r
    if y == 0.0:
        return 1.0
    if x == 0.0 and y < 0.0:
        raise ZeroDivisionError("0.0 cannot be raised to a negative power")
    if x < 0.0:
        if fmod(y, 1.0) != 0.0:
            raise ValueError("negative number cannot be raised to a fractional power")
        x = -x
        negate = fmod(fabs(y), 2.0) == 1.0
    if x == 1.0:
        return -1.0 if negate else 1.0
    r = pow(x, y)
    if isinf(r) and not isinf(x) and not isinf(y):
        raise OverflowError("(34, 'Numerical result out of range')")
    return -r if negate else r


# -- the classes and constants of the Python code ---------------------------------------
cdef dict CLASSES = dict.fromkeys(("exact", "fourier", "coupler_motion", "advanced", "nonlinear"))
cdef object COMPONENT_ERROR = RuntimeError
cdef object BUDGET_SPENT = RuntimeError  # event_integration.StepBudgetSpent
cdef object FIRE_AT_INSTANT = None
cdef object FIRST_STEP = None
cdef double N_DAMP = 0.25
cdef int STICK = 0, SLIP_FORWARD = 1, SLIP_BACKWARD = 2


def use_classes(**classes):
    """The classes the compiled code recognises (by role): exact, fourier (the rocker
    models), coupler_motion (the drive's model over a step), nonlinear (the monolithic reference's machine)."""
    CLASSES.update(classes)


def use_integration(component_error, budget_spent, fire_at_instant, first_step):
    """event_integration's errors and the functions its compiled loop calls back."""
    global COMPONENT_ERROR, BUDGET_SPENT, FIRE_AT_INSTANT, FIRST_STEP
    COMPONENT_ERROR, BUDGET_SPENT = component_error, budget_spent
    FIRE_AT_INSTANT, FIRST_STEP = fire_at_instant, first_step


def use_reference(double n_damp, int stick, int slip_forward, int slip_backward):
    """The clutch's damping exponent and the brake's regime numbers of the reference."""
    global N_DAMP, STICK, SLIP_FORWARD, SLIP_BACKWARD
    N_DAMP, STICK, SLIP_FORWARD, SLIP_BACKWARD = n_damp, stick, slip_forward, slip_backward


# -- components.rssr_kinematics ---------------------------------------------------------
cdef struct Rocker:
    int kind  # 0: ExactRSSR, 1: ExactRSSR with a constant F2, 2: FourierRocker
    double a1, a4, s2, s3, A, c0, f2_gain, f2_const
    double fa0, fa1, fb1, f2


cdef int _load_rocker(object kin, Rocker* r) except -1:
    """The rocker model's constants; 1 for a model this kernel does not know."""
    if CLASSES["exact"] is not None and type(kin) is CLASSES["exact"]:
        r.a1, r.a4, r.s2, r.s3 = kin.a1, kin.a4, kin.s2, kin.s3
        r.A, r.c0, r.f2_gain = kin.A, kin.c0, kin.f2_gain
        if kin.f2_const is None:
            r.kind = 0
        else:
            r.kind = 1
            r.f2_const = kin.f2_const
        return 0
    if CLASSES["fourier"] is not None and type(kin) is CLASSES["fourier"]:
        r.kind = 2
        r.fa0, r.fa1, r.fb1, r.f2 = kin.a0, kin.a1, kin.b1, kin.f2
        return 0
    return 1


cdef int _exact(Rocker* r, double phi1, double* o) except -1:
    """ExactRSSR._solve into o: phi4r, phi4r', phi4r'', F2, F2', F2''."""
    cdef double a1 = r.a1, a4 = r.a4, s2 = r.s2, s3 = r.s3, A = r.A
    cdef double sp = _sin(phi1), cp = _cos(phi1)
    cdef double B = 2.0 * a4 * (s3 + a1 * sp)
    cdef double C = r.c0 + 2.0 * a1 * s2 * cp + 2.0 * s3 * a1 * sp
    cdef double phi4 = 2.0 * atan((A + _sqrt(A * A + B * B - C * C)) / (B + C))
    cdef double B1 = 2.0 * a4 * a1 * cp
    cdef double B2 = -2.0 * a4 * a1 * sp
    cdef double C1 = -2.0 * a1 * s2 * sp + 2.0 * s3 * a1 * cp
    cdef double C2 = -2.0 * a1 * s2 * cp - 2.0 * s3 * a1 * sp
    cdef double s4 = _sin(phi4), c4 = _cos(phi4)
    cdef double D = A * c4 - B * s4
    cdef double d1 = -(B1 * c4 - C1) / D
    cdef double D1_ = -A * s4 * d1 - B1 * s4 - B * c4 * d1
    cdef double d2 = -(B2 * c4 - B1 * s4 * d1 - C2 + D1_ * d1) / D
    cdef double D2_, g
    o[0], o[1], o[2] = phi4, d1, d2
    if r.kind == 1:
        o[3], o[4], o[5] = r.f2_const, 0.0, 0.0
        return 0
    D2_ = (
        -A * c4 * d1 * d1
        - A * s4 * d2
        - B2 * s4
        - 2.0 * B1 * c4 * d1
        + B * s4 * d1 * d1
        - B * c4 * d2
    )
    g = r.f2_gain
    o[3] = -g / D
    o[4] = g * D1_ / (D * D)
    o[5] = g * (D2_ / (D * D) - 2.0 * D1_ * D1_ / (D * D * D))
    return 0


cdef int _kin(Rocker* r, double phi1, double* o) except -1:
    """The rocker model's tuple at phi1 (ExactRSSR / FourierRocker __call__)."""
    cdef double c, s
    if r.kind != 2:
        return _exact(r, phi1, o)
    c, s = _cos(phi1), _sin(phi1)
    o[0] = r.fa0 + r.fa1 * c + r.fb1 * s
    o[1] = -r.fa1 * s + r.fb1 * c
    o[2] = -r.fa1 * c - r.fb1 * s
    o[3], o[4], o[5] = r.f2, 0.0, 0.0
    return 0


def exact_rssr_call(self, phi1):
    """ExactRSSR.__call__ (with its memo of the last angle)."""
    cdef Rocker r
    cdef double o[6]
    memo = self._memo
    if memo[0] == phi1:
        return memo[1]
    r.a1, r.a4, r.s2, r.s3 = self.a1, self.a4, self.s2, self.s3
    r.A, r.c0, r.f2_gain = self.A, self.c0, self.f2_gain
    r.kind = 0 if self.f2_const is None else 1
    if r.kind == 1:
        r.f2_const = self.f2_const
    _exact(&r, phi1, o)
    out = (o[0], o[1], o[2], self.f2_const if r.kind == 1 else o[3], o[4], o[5])
    self._memo = (phi1, out)
    return out


# -- components.crank_coupler_drive -----------------------------------------------------
cdef struct Drive:
    Rocker kin
    double omega, m_co, k_e, c_e, j_o4, rho_a, f1a0, f1a1, f1b1, phi4_max
    bint rigid


cdef object LAST_MODEL = None  # the DriveModel whose constants DRIVE holds (frozen)
cdef Drive DRIVE


cdef Drive* _drive(object m) except NULL:
    """The constants of DriveModel m (None where its rocker model is not known here)."""
    global LAST_MODEL
    if m is LAST_MODEL:
        return &DRIVE
    LAST_MODEL = None  # until every constant is read
    if _load_rocker(m.kin, &DRIVE.kin) != 0:
        return &DRIVE  # not known: the callers ask _known
    DRIVE.omega, DRIVE.m_co, DRIVE.k_e, DRIVE.c_e = m.omega, m.m_co, m.k_e, m.c_e
    DRIVE.j_o4, DRIVE.rho_a, DRIVE.phi4_max = m.j_o4, m.rho_a, m.phi4_max
    DRIVE.f1a0, DRIVE.f1a1, DRIVE.f1b1 = m.f1
    DRIVE.rigid = m.rigid
    LAST_MODEL = m
    return &DRIVE


cdef inline bint _known(object m):
    _drive(m)
    return m is LAST_MODEL


cdef int _coupler(
    Drive* d, double phi1, double q, double qd, double torque, double* k, double* o
) except -1:
    """coupler_derivatives into o: q'', theta4, theta4', P_in, P_diss."""
    cdef double w = d.omega
    cdef double v_r = w * (k[1] + k[4] * q)
    cdef double a_r = w * w * (k[2] + k[5] * q) + 2.0 * w * k[4] * qd
    cdef double qdd, f1, phi4e_dd
    if d.rigid:
        qdd = 0.0
        f1 = 0.0
    else:
        f1 = d.rho_a * w * w * (d.f1a0 + d.f1a1 * _cos(phi1) + d.f1b1 * _sin(phi1))
        qdd = (f1 - d.c_e * qd - d.k_e * q + k[3] * (torque - d.j_o4 * a_r)) / (
            d.m_co + d.j_o4 * k[3] * k[3]
        )
    phi4e_dd = a_r + k[3] * qdd
    o[0] = qdd
    o[1] = d.phi4_max - (k[0] + k[3] * q)
    o[2] = -(v_r + k[3] * qd)
    o[3] = f1 * qd + (d.j_o4 * phi4e_dd - torque) * v_r
    o[4] = d.c_e * qd * qd
    return 0


cdef inline double _rocker_speed(Drive* d, double q, double qd, double* k):
    """rocker_motion's theta4'."""
    return -(d.omega * (k[1] + k[4] * q) + k[3] * qd)


cdef int _kin_of(Drive* d, double phi1, object kin, double* k) except -1:
    """The kinematics tuple given, or the rocker model's at phi1."""
    cdef Py_ssize_t i
    if kin is None:
        return _kin(&d.kin, phi1, k)
    for i in range(6):
        k[i] = kin[i]
    return 0


def coupler_derivatives(m, phi1, q, qd, torque, kin=None):
    """crank_coupler_drive.coupler_derivatives."""
    cdef double k[6]
    cdef double o[5]
    if not _known(m):
        return PYTHON["coupler_derivatives"](m, phi1, q, qd, torque, kin)
    _kin_of(&DRIVE, phi1, kin, k)
    _coupler(&DRIVE, phi1, q, qd, torque, k, o)
    return o[0], o[1], o[2], o[3], o[4]


def rocker_motion(m, phi1, q, qd, kin=None):
    """crank_coupler_drive.rocker_motion."""
    cdef double k[6]
    cdef double dq = q
    if not _known(m):
        return PYTHON["rocker_motion"](m, phi1, q, qd, kin)
    _kin_of(&DRIVE, phi1, kin, k)
    return DRIVE.phi4_max - (k[0] + k[3] * dq), _rocker_speed(&DRIVE, dq, qd, k)


cdef dict PYTHON = {}


def use_python(**functions):
    """The Python originals, for a drive whose rocker model is not known here."""
    PYTHON.update(functions)


# -- the drive's loop between events ----------------------------------------------------
cdef class _CouplerRun:
    """event_integration.advance for a _CouplerMotion, on C arrays."""

    cdef object motion
    cdef Drive d
    cdef double torque, rate, phi1_mid, direction

    cdef int deriv(self, double* y, double* out) except -1:
        """_CouplerMotion.deriv."""
        cdef double k[6]
        cdef double o[5]
        cdef double torque = self.torque
        if self.rate:
            torque += self.rate * (y[0] - self.phi1_mid) / self.d.omega
        _kin(&self.d.kin, y[0], k)
        _coupler(&self.d, y[0], y[1], y[2], torque, k, o)
        out[0] = self.d.omega
        out[1] = y[2]
        out[2] = o[0]
        out[3] = o[3]
        out[4] = o[4]
        return 0

    cdef int indicators(self, double* y, double* g) except -1:
        """_CouplerMotion.indicators."""
        cdef double k[6]
        _kin(&self.d.kin, y[0], k)
        g[0] = self.direction * _rocker_speed(&self.d, y[1], y[2], k)
        return 0

    cdef double dp5(
        self, double* y, double* k1, double h, double rtol, double* scales, Py_ssize_t m,
        double* y1, double* k7, double r[5][NY],
    ) except? -2.0:
        """event_integration._dp5_step: y1, k7, the dense output r; returns err."""
        cdef Py_ssize_t n = NY, i
        cdef double k2[NY]
        cdef double k3[NY]
        cdef double k4[NY]
        cdef double k5[NY]
        cdef double k6[NY]
        cdef double z[NY]
        cdef double e, sc, lo, hi, acc, err
        for i in range(n):
            z[i] = y[i] + h * A21 * k1[i]
        self.deriv(z, k2)
        for i in range(n):
            z[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
        self.deriv(z, k3)
        for i in range(n):
            z[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
        self.deriv(z, k4)
        for i in range(n):
            z[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
        self.deriv(z, k5)
        for i in range(n):
            z[i] = y[i] + h * (
                A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]
            )
        self.deriv(z, k6)
        for i in range(n):
            y1[i] = y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
        self.deriv(y1, k7)
        acc = 0.0
        for i in range(m):
            e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
            lo = fabs(y[i])
            hi = fabs(y1[i])
            sc = rtol * (scales[i] + (hi if hi > lo else lo))
            acc += _pow(e / sc, 2.0)
        err = _sqrt(acc / m)
        if err != err:
            raise ArithmeticError("non-finite error estimate")
        for i in range(n):
            r[0][i] = y[i]
            r[1][i] = y1[i] - y[i]
            r[2][i] = h * k1[i] - r[1][i]
            r[3][i] = r[1][i] - h * k7[i] - r[2][i]
            r[4][i] = h * (
                D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]
            )
        return err

    cdef double locate(
        self, double r[5][NY], double h, double g_lo, double g_hi, double tol_t, double* y_hi,
    ) except? -2.0:
        """event_integration._locate for the one indicator: the offset, the state in y_hi."""
        cdef double lo = 0.0, hi = 1.0, tol = tol_t / h, th, gt, s1
        cdef double yt[NY]
        cdef double g[1]
        cdef bint found = False
        cdef int side = 0, it
        cdef Py_ssize_t i
        for it in range(80):
            if hi - lo <= tol:
                break
            th = hi - g_hi * (hi - lo) / (g_hi - g_lo)
            if not (lo < th and th < hi):
                th = 0.5 * (lo + hi)
            s1 = 1.0 - th
            for i in range(NY):
                yt[i] = r[0][i] + th * (r[1][i] + s1 * (r[2][i] + th * (r[3][i] + s1 * r[4][i])))
            self.indicators(yt, g)
            gt = g[0]
            if gt < 0.0:
                hi, g_hi = th, gt
                for i in range(NY):
                    y_hi[i] = yt[i]
                found = True
                if side == -1:
                    g_lo *= 0.5
                side = -1
            else:
                lo, g_lo = th, gt
                if side == 1:
                    g_hi *= 0.5
                side = 1
        if not found:
            s1 = 1.0 - hi
            for i in range(NY):
                y_hi[i] = r[0][i] + hi * (r[1][i] + s1 * (r[2][i] + hi * (r[3][i] + s1 * r[4][i])))
        return hi * h

    cdef object run(
        self, object y, double h_total, object control, double h_try, double tol_t,
        long max_events,
    ):
        """event_integration.advance, operation for operation (no accept, no observer)."""
        cdef Py_ssize_t i, m, j
        cdef double Y[NY]
        cdef double K1[NY]
        cdef double Y1[NY]
        cdef double K7[NY]
        cdef double YB[NY]
        cdef double YL[NY]
        cdef double YT[NY]
        cdef double KT[NY]
        cdef double SC[NY]
        cdef double R[5][NY]
        cdef double RT[5][NY]
        cdef double G0[1]
        cdef double G1[1]
        cdef double GT[1]
        cdef double t = 0.0, h, h_next, h_min, h_step, left, end, err, factor, x
        cdef double th_best, th, tn, rtol = control.rtol, h_max = control.h_max
        cdef double t_first = -1.0, t_event = -1.0
        cdef long n_events = 0, steps = 0, rejected = 0, max_steps = 0
        cdef bint has_max = control.max_steps is not None
        cdef int nudge_i, first
        cdef double nudges[4]
        nudges[0], nudges[1], nudges[2], nudges[3] = 0.0, 1.0, 4.0, 16.0
        if has_max:
            max_steps = control.max_steps
        scales = control.scales
        m = len(scales)
        for i in range(m):
            SC[i] = scales[i]
        for i in range(NY):
            Y[i] = y[i]
        recent = []
        motion = self.motion
        self.indicators(Y, G0)
        self.deriv(Y, K1)
        end = h_total * (1.0 - 1e-14)
        if h_try > 0.0:
            h = h_try
        else:
            h = FIRST_STEP([Y[i] for i in range(NY)], [K1[i] for i in range(NY)], control)
        h_next = h
        h_min = H_MIN_RELATIVE * h_total
        if not h_min > H_MIN_ABSOLUTE:
            h_min = H_MIN_ABSOLUTE
        while t < end:
            if has_max and steps + rejected >= max_steps:
                raise BUDGET_SPENT(
                    f"spent its budget of {max_steps} internal steps (max_internal_steps) "
                    f"{t:.6g} s into a step of {h_total:.6g} s; take shorter communication "
                    "steps or give a larger budget"
                )
            left = h_total - t
            if t > 0.0 and left <= h_min:
                break
            if h_max < h:
                h = h_max
            h_step = left if h >= 0.99 * left else h
            if h_step < h_min and h_step < left:
                raise COMPONENT_ERROR(f"integration step underflow ({h_step:.3g} s)")
            try:
                err = self.dp5(Y, K1, h_step, rtol, SC, m, Y1, K7, R)
                self.indicators(Y1, G1)
            except (ArithmeticError, ValueError) as exc:
                if h_step <= 1e3 * tol_t:
                    raise COMPONENT_ERROR(f"model evaluation failed at a tiny step: {exc}") from exc
                h = h_step * SHRINK_ON_FAILURE
                rejected += 1
                continue
            if err > 1.0:
                x = SAFETY * _pow(err, -EXPONENT)
                h = h_step * (x if x > SHRINK_MIN else SHRINK_MIN)
                rejected += 1
                continue
            if err == 0.0:
                factor = GROW_MAX
            else:
                x = SAFETY * _pow(err, -EXPONENT)
                factor = x if x < GROW_MAX else GROW_MAX
            h_next = h_step * factor
            if h_step < h:
                if h > h_next:
                    h_next = h
            steps += 1
            first = -1
            th_best = h_step
            for i in range(NY):
                YB[i] = Y1[i]
            if G0[0] >= 0.0 and G1[0] < 0.0:
                if G0[0] == 0.0:
                    th = 0.0
                    for j in range(NY):
                        YL[j] = Y[j]
                else:
                    th = self.locate(R, h_step, G0[0], G1[0], tol_t, YL)
                first, th_best = 0, th
                for j in range(NY):
                    YB[j] = YL[j]
            if 0.0 < th_best and th_best < h_step:
                for nudge_i in range(4):
                    tn = th_best + nudges[nudge_i] * tol_t
                    try:
                        self.dp5(Y, K1, tn, rtol, SC, m, YT, KT, RT)
                    except (ArithmeticError, ValueError):
                        break
                    self.indicators(YT, GT)
                    if GT[0] < 0.0:
                        th_best = tn
                        for j in range(NY):
                            YB[j] = YT[j]
                        break
            if first < 0:
                for i in range(NY):
                    Y[i] = Y1[i]
                    K1[i] = K7[i]
                t += h_step
                G0[0] = G1[0]
                h = h_next
                continue
            for i in range(NY):
                Y[i] = YB[i]
            t += th_best
            y_after, fired, g = FIRE_AT_INSTANT(
                motion, [Y[i] for i in range(NY)], first, t, (G0[0],)
            )
            self.direction = motion.direction
            for i in range(NY):
                Y[i] = y_after[i]
            G0[0] = g[0]
            self.deriv(Y, K1)
            t_event = t
            if t_first < 0.0:
                t_first = t
            n_events += fired
            recent.append(first)
            if n_events > max_events:
                which = ", ".join(str(i) for i in sorted(set(recent[max(0, len(recent) - 20):])))
                raise COMPONENT_ERROR(
                    f"too many events inside one step (chattering: indicators {which}, "
                    f"{t:.6g} s into the step)"
                )
            h = h_next
        return [Y[i] for i in range(NY)], t_first, t_event, n_events, h_next, steps, rejected


def advance(motion, y, double h_total, control, double h_try, double tol_t, long max_events,
            observe):
    """event_integration.advance's loop compiled for the drive's _CouplerMotion (registered
    with its use_compiled_loop): Advanced's fields; None for any other model or rocker, or
    with an observer (the Python loop runs it)."""
    cdef _CouplerRun run
    if observe is not None or type(motion) is not CLASSES["coupler_motion"] or len(y) != NY:
        return None
    if len(control.scales) > NY or not _known(motion.m):
        return None
    run = _CouplerRun()
    run.motion = motion
    run.d = DRIVE
    run.torque, run.rate, run.phi1_mid = motion.torque, motion.rate, motion.phi1_mid
    run.direction = motion.direction  # changed only by its events, read back after each
    return run.run(y, h_total, control, h_try, tol_t, max_events)


def coupler_motion_deriv(self, y):
    """_CouplerMotion.deriv."""
    cdef _CouplerRun run
    cdef double Y[NY]
    cdef double out[NY]
    cdef Py_ssize_t i
    if len(y) != NY or not _known(self.m):
        return PYTHON["deriv"](self, y)
    run = _CouplerRun()
    run.d = DRIVE
    run.torque, run.rate, run.phi1_mid = self.torque, self.rate, self.phi1_mid
    for i in range(NY):
        Y[i] = y[i]
    run.deriv(Y, out)
    return [out[0], out[1], out[2], out[3], out[4]]


def coupler_motion_indicators(self, y):
    """_CouplerMotion.indicators."""
    cdef double k[6]
    cdef double y0 = y[0], y1 = y[1], y2 = y[2]
    if not _known(self.m):
        return PYTHON["indicators"](self, y)
    _kin(&DRIVE.kin, y0, k)
    return (self.direction * _rocker_speed(&DRIVE, y1, y2, k),)


# -- orchestrator.scenes.press_feed.monolithic._Nonlinear -------------------------------
cdef double _clutch_torque(double w, double wd, double k, double c_lin, double c_nl) except? -2.0:
    """sprag_clutch.clutch_torque on the reference's numpy values (w ** n is numpy's pow)."""
    cdef double t
    if w <= 0.0:
        return 0.0
    t = k * w * _sqrt(w) + (c_lin + c_nl * pow(w, N_DAMP)) * wd
    return t if t > 0.0 else 0.0


cdef struct Signals:
    double phi1, th4, th4d, w, rel, trq
    double k[6]


cdef int _signals(object self, double t, double* y, Signals* s) except -1:
    """_Nonlinear.signals into s."""
    m = self.m
    cdef Drive* d = _drive(m)
    cdef bint engaged = self.engaged
    s.phi1 = <double>self.phi1_0 + d.omega * t
    _kin(&d.kin, s.phi1, s.k)
    s.th4 = d.phi4_max - (s.k[0] + s.k[3] * y[0])
    s.th4d = _rocker_speed(d, y[0], y[1], s.k)
    s.rel = s.th4d - y[3]
    s.w = s.th4 - y[2] - <double>self.lock if engaged else 0.0
    if engaged:
        s.trq = _clutch_torque(s.w, s.rel, self.k, self.c_lin, self.c_nl)
    else:
        s.trq = 0.0
    return 0


cdef inline int _state(object y, double* out) except -1:
    cdef const double[:] v = np.asarray(y, dtype=np.float64)
    cdef Py_ssize_t i
    for i in range(4):
        out[i] = v[i]
    return 0


def nonlinear_signals(self, t, y):
    """_Nonlinear.signals."""
    cdef Signals s
    cdef double Y[4]
    if not _known(self.m):
        return PYTHON["signals"](self, t, y)
    _state(y, Y)
    _signals(self, t, Y, &s)
    kin = (s.k[0], s.k[1], s.k[2], s.k[3], s.k[4], s.k[5])
    return s.phi1, kin, s.th4, s.th4d, s.w, s.rel, s.trq


def nonlinear_observe(self, t, y):
    """_Nonlinear.observe: (windup, clutch torque)."""
    cdef Signals s
    cdef double Y[4]
    if not _known(self.m):
        return PYTHON["observe"](self, t, y)
    _state(y, Y)
    _signals(self, t, Y, &s)
    return s.w, s.trq


def nonlinear_rhs(self, t, y):
    """_Nonlinear.rhs."""
    cdef Signals s
    cdef double Y[4]
    cdef double o[5]
    cdef double th5d, t_b, acc
    cdef int brake
    cdef bint slipping, engaged
    if not _known(self.m):
        return PYTHON["rhs"](self, t, y)
    _state(y, Y)
    _signals(self, t, Y, &s)
    _coupler(&DRIVE, s.phi1, Y[0], Y[1], s.trq, s.k, o)
    brake = self.brake
    engaged = self.engaged
    t_b = self.t_b
    slipping = brake != STICK
    th5d = Y[3] if slipping else 0.0
    if brake == SLIP_FORWARD:
        acc = (s.trq - t_b) / <double>self.j5
    elif brake == SLIP_BACKWARD:
        acc = (s.trq + t_b) / <double>self.j5
    else:
        acc = 0.0
    out = np.empty(NY_REFERENCE)
    cdef double[:] v = out
    v[0] = Y[1]
    v[1] = o[0]
    v[2] = th5d
    v[3] = acc
    v[4] = o[3]
    v[5] = o[4]
    if engaged and not s.w <= 0.0:  # clutch_dissipation_rate
        v[6] = (s.trq - <double>self.k * s.w * _sqrt(s.w)) * s.rel
    else:
        v[6] = 0.0
    v[7] = t_b * fabs(th5d)
    v[8] = s.w if slipping else 0.0
    v[9] = s.trq if slipping else 0.0
    v[10] = 1.0 if slipping else 0.0
    return out


def nonlinear_observed(mach, times, states):
    """monolithic._observed for a _Nonlinear: (windup, clutch torque) at each sample."""
    cdef Signals s
    cdef double Y[4]
    cdef Py_ssize_t i, j, n
    cdef const double[:] ts
    cdef const double[:, :] ys
    if type(mach) is not CLASSES["nonlinear"] or not _known(mach.m):
        return PYTHON["observed"](mach, times, states)
    ts = np.asarray(times, dtype=np.float64)
    ys = np.asarray(states, dtype=np.float64)
    n = ts.shape[0]
    if ys.ndim != 2 or ys.shape[0] != n or ys.shape[1] < 4:
        return PYTHON["observed"](mach, times, states)
    out = []
    for i in range(n):
        for j in range(4):
            Y[j] = ys[i, j]
        _signals(mach, ts[i], Y, &s)
        out.append((s.w, s.trq))
    return out


def rocker_angles(m, phi1, q):
    """crank_coupler_drive.rocker_angles: theta4 at each sample."""
    cdef double k[6]
    cdef Py_ssize_t i, n
    cdef const double[:] ps
    cdef const double[:] qs
    cdef double[:] v
    if not _known(m):
        return PYTHON["rocker_angles"](m, phi1, q)
    ps = np.asarray(phi1, dtype=np.float64)
    qs = np.asarray(q, dtype=np.float64)
    n = ps.shape[0]
    if ps.ndim != 1 or qs.ndim != 1 or qs.shape[0] != n:
        return PYTHON["rocker_angles"](m, phi1, q)
    out = np.empty(n)
    v = out
    for i in range(n):
        _kin(&DRIVE.kin, ps[i], k)
        v[i] = DRIVE.phi4_max - (k[0] + k[3] * qs[i])
    return out
