# cython: language_level=3, binding=True, boundscheck=False, wraparound=False
# cython: cdivision=False, initializedcheck=False
"""Compiled twins of the M739 hot paths: the verge's coupled kinematics and contact terms
(components.verge_geometry, components.verge_escapement), the train's response parts
(components.gear_train), one Dormand-Prince step with its dense output
(components.event_integration), and the whole loop between events (``advance``) for the
M739 verge core, its monolithic model and the M739 train's model.

Each function repeats its Python original operation for operation, in the same order,
so that results are the same bits: ``x ** 2`` is libm's pow as in CPython (built with
-fno-builtin, no fast math, no FMA contraction), a division by zero, an overflowing power
and the sine of an infinity raise what Python raises.  ``components.kernels`` loads this
module; without it the Python originals run.
"""

from libc.math cimport INFINITY, atan2, cos, fabs, fmod, isinf, pow, sin, sqrt

cdef enum:
    MAX_STATES = 32  # states one step can carry (the verge with its moments: 8)

cdef double TWO_PI = 2.0 * 3.141592653589793

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


cdef inline double _sin(double x) except? -2.0:
    if isinf(x):
        raise ValueError("math domain error")
    return sin(x)


cdef inline double _cos(double x) except? -2.0:
    if isinf(x):
        raise ValueError("math domain error")
    return cos(x)


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


# -- components.verge_geometry ----------------------------------------------------------
cpdef tuple kinem(double phi, double alpha, double a, double b, double c):
    cdef double cap_a = a * _cos(alpha) + b * _cos(phi - alpha)
    cdef double cap_b = a * _sin(alpha) - b * _sin(phi - alpha)
    cdef double cap_c = c * _sin(alpha)
    cdef double disc = cap_a * cap_a + cap_b * cap_b - cap_c * cap_c
    cdef double psi, spa, cpa, arg, sarg, carg, g, p, q, u, v
    if disc < 0.0:
        disc = 0.0
    psi = 2.0 * atan2(cap_a - _sqrt(disc), cap_b + cap_c)
    if psi < 0.0:
        psi += TWO_PI
    spa = _sin(psi + alpha)
    cpa = _cos(psi + alpha)
    arg = phi - alpha - psi
    sarg = _sin(arg)
    carg = _cos(arg)
    g = (b * _sin(phi) - c * _sin(psi)) / spa
    p = b * carg
    q = a * cpa + p
    u = p / q
    v = (a * p * p * spa - b * _pow(p - q, 2.0) * sarg) / (q * q * q)
    return psi, g, u, v, p, b * sarg, c * _cos(alpha) + g


cpdef double sliding_velocity(
    double phi, double psi, double phi_dot, double psi_dot, double alpha, double b, double c
) except? -2.0:
    return -(phi_dot * b * _sin(phi - psi - alpha) + psi_dot * c * _sin(alpha))


# -- components.verge_escapement --------------------------------------------------------
cdef tuple _contact(
    object k, int face, double psi, int s4, int s5, int direction,
    double a1p, double b1p, double d1p,
):
    cdef double mu1 = k.mu1
    cdef double mu = k.mu_abs * direction
    cdef double alpha = k.alpha[face]
    cdef double spa = _sin(psi + alpha), cpa = _cos(psi + alpha)
    cdef double chi = psi + alpha + <double>k.beta3
    cdef double sc = _sin(chi), cc = _cos(chi)
    cdef double dn = 1.0 + mu * mu
    cdef double rho3 = k.d.rho3
    cdef double c1p = k.c1[face]
    cdef double dn1 = k.dn1, rho_p = k.d.rho_p
    cdef double a1, a5, a9, a12, a17, a18
    if face == 1:
        a1 = fabs(-mu1 * (s4 + s5) * spa - (1.0 - s4 * s5 * mu1 * mu1) * cpa) / dn1
        a5 = fabs(mu1 * (s4 + s5) * cpa + (1.0 - s4 * s5 * mu1 * mu1) * spa) / dn1
        a9 = fabs((mu1 * s4 + mu) * sc + (1.0 - mu * mu1 * s4) * cc) / dn
        a12 = fabs((1.0 - mu * mu1 * s4) * sc - (s4 * mu1 + mu) * cc) / dn
        a17 = a1p - mu1 * s4 * b1p + mu * rho3 * (a9 + a12)
        a18 = d1p - c1p * mu1 * s4 - rho_p * mu1 * s5 * (a1 + a5)
    else:
        a1 = fabs(mu1 * (s5 - s4) * spa + (1.0 + mu1 * mu1 * s4 * s5) * cpa) / dn1
        a5 = fabs(mu1 * (s5 - s4) * cpa - (1.0 + mu1 * mu1 * s4 * s5) * spa) / dn1
        a9 = fabs((mu1 * s4 - mu) * sc - (1.0 + s4 * mu * mu1) * cc) / dn
        a12 = fabs(-(1.0 + mu * mu1 * s4) * sc + (mu - mu1 * s4) * cc) / dn
        a17 = -a1p - mu1 * s4 * b1p + mu * rho3 * (a9 + a12)
        a18 = -(d1p + c1p * mu1 * s4 + rho_p * mu1 * s5 * (a1 + a5))
    return a17, a18


def contact_coefficients(
    k, int face, double psi, int s4, int s5, int direction, double a1p, double b1p, double d1p
):
    return _contact(k, face, psi, s4, s5, direction, a1p, b1p, d1p)


def coupled_terms(self, y):
    """VergeCore._coupled_terms."""
    k = self.k
    cdef double y0 = y[0], w = y[1]
    cdef double phi_off = self.phi_off, psic = self.psic
    cdef double phi_l = y0 + phi_off
    cdef int face = self.face
    cdef double alpha = k.alpha[face]
    cdef double kb = k.b, kc = k.c
    psi_, g_, u_, v_, a1p_, b1p_, d1p_ = kinem(phi_l, alpha, k.a, kb, kc)
    cdef double psi = psi_, g = g_, u = u_, v = v_
    cdef int s4 = self.s4, s5 = self.s5
    a19_, a20_, _ = k.pivot(s5, psi + psic)
    cdef double a19 = a19_, a20 = a20_
    cdef double a21 = s5 * a20
    a17_, a18_ = _contact(k, face, psi, s4, s5, self.train.direction, a1p_, b1p_, d1p_)
    cdef double a17 = a17_, a18 = a18_
    cdef double ipr = self._ipr(psi)
    j_, t_, c_ = self.train.response(y0, w)
    cdef double j = j_, t = t_, c = c_
    cdef double om2 = k.om2
    cdef double a52 = 2.0 * <double>k.om_abs * a20
    cdef double cent = <double>k.a54 * _sin(<double>k.gamma_pp - psi - psic)
    cdef double psi_d = u * w
    cdef double n = (ipr * v + a21 * u * u) * w * w + a52 * psi_d + om2 * a19 - cent
    cdef double den = j * a18 + c * a17 * ipr * u
    cdef double acc
    if self.train_stuck:
        acc = 0.0
    else:
        acc = (a18 * t - c * a17 * n) / den
    cdef double psi_dd = u * acc + v * w * w
    cdef double pn = (ipr * psi_dd + a21 * psi_d * psi_d + a52 * psi_d + om2 * a19 - cent) / a18
    cdef double vst = sliding_velocity(phi_l, psi, w, psi_d, alpha, kb, kc)
    cdef double t_static = -a17 * n / a18, j_esc = a17 * ipr * u / a18
    return acc, psi, psi_d, psi_dd, pn, -a17 * pn, g, u, vst, den / a18, cent, t_static, j_esc


# -- components.gear_train --------------------------------------------------------------
def train_parts(self, double phi, double phi_dot):
    """TrainPhysics._parts."""
    d = self.d
    mu_, dn_, a15c_, a16_, a31c_, a42c_, a43_, a44c_, _, _, _, _ = self._k
    cdef double mu = mu_, dn = dn_, a15c = a15c_, a16 = a16_, a31c = a31c_
    cdef double a42c = a42c_, a43 = a43_, a44c = a44c_
    cdef int s1 = self.s1, s2 = self.s2
    cdef double al1 = <double>self.al1_in + <double>self.span1 * (
        <double>self.du1 * phi + <double>self.u1_start - <double>self.n1
    )
    cdef double al2 = <double>self.al2_in + <double>self.span2 * (
        <double>self.du2 * phi + <double>self.u2_start - <double>self.n2
    )
    cdef double a1 = al1 * <double>d.rb1_cap
    cdef double a2 = al2 * <double>d.rb2_cap
    cdef double a15 = a15c - mu * s2 * (<double>self.d2 - a2)
    cdef double a31 = a31c - mu * s1 * a1
    cdef double a42 = a42c - mu * s1 * (<double>self.d1 - a1)
    cdef double a44 = a44c - mu * s2 * a2
    cdef double n31 = self.n31
    cdef double big_phi = <double>d.phi1c + n31 * phi
    cdef double sp = _sin(big_phi), cp = _cos(big_phi)
    cdef double m1 = d.m1, r1 = d.r1, rho1 = d.rho1
    cdef double m1r = m1 * <double>d.rc1
    cdef double x = m1r * (mu * cp - sp)
    cdef double a24 = fabs(m1 * r1 + m1r * (cp + mu * sp)) / dn
    cdef double a28 = fabs(mu * m1 * r1 + x) / dn
    cdef double a25 = fabs(m1r * (cp + mu * sp)) / dn
    cdef double a29 = fabs(x) / dn
    cdef double a2526 = a25 + a29
    cdef double mu_abs = self.mu_abs
    cdef double a32 = mu * rho1 * <double>self.om2 * (a24 + a28)
    cdef double a33 = 2.0 * mu_abs * rho1 * <double>self.om_abs * a2526
    cdef double a34 = mu * rho1 * a2526
    cdef int i1r_sign = self.i1r_sign
    cdef double i1r = <double>d.i1 + i1r_sign * mu_abs * rho1 * (
        fabs(m1r * (sp - mu * cp)) / dn + fabs(m1r * (mu * sp + cp)) / dn
    )
    if i1r < 0.0:
        i1r = 0.0
    cdef double w1 = n31 * phi_dot
    cdef double a35 = self.a35, t2 = self.t2
    cdef double k = (<double>d.i2 * <double>self.n32 - a42 * i1r * n31 / a31) / a44
    cdef double f0 = (a42 * (-a32 - a33 * w1 - a34 * w1 * w1 - a35 * sp) / a31 - t2 * a43) / a44
    cdef double j_ref = <double>d.i3 - a15 * k
    cdef double t_ref = a15 * f0 - <double>self.t3 * a16
    return j_ref, t_ref, f0, k, a42, a43, a44


# -- components.event_integration -------------------------------------------------------
cdef object STEP_TYPE = tuple
cdef object WIDE_STEP = None


def use_step_type(step_type, wide_step):
    """The named tuple ``dp5_step`` returns (event_integration._Step), and the Python step
    for a model with more than MAX_STATES states."""
    global STEP_TYPE, WIDE_STEP
    STEP_TYPE = step_type
    WIDE_STEP = wide_step


cdef inline void _fill(double* out, object values, Py_ssize_t n) except *:
    cdef Py_ssize_t i
    for i in range(n):
        out[i] = values[i]


def dp5_step(deriv, y, k1, double h, control):
    """event_integration._dp5_step."""
    cdef Py_ssize_t n = len(y), i, m
    cdef double Y[MAX_STATES]
    cdef double K1[MAX_STATES]
    cdef double K2[MAX_STATES]
    cdef double K3[MAX_STATES]
    cdef double K4[MAX_STATES]
    cdef double K5[MAX_STATES]
    cdef double K6[MAX_STATES]
    cdef double K7[MAX_STATES]
    cdef double Y1[MAX_STATES]
    cdef double e, sc, lo, hi, acc, err, rtol
    if n > MAX_STATES:
        return WIDE_STEP(deriv, y, k1, h, control)
    _fill(Y, y, n)
    _fill(K1, k1, n)
    _fill(K2, deriv([Y[i] + h * A21 * K1[i] for i in range(n)]), n)
    _fill(K3, deriv([Y[i] + h * (A31 * K1[i] + A32 * K2[i]) for i in range(n)]), n)
    _fill(K4, deriv([Y[i] + h * (A41 * K1[i] + A42 * K2[i] + A43 * K3[i]) for i in range(n)]), n)
    _fill(
        K5,
        deriv([
            Y[i] + h * (A51 * K1[i] + A52 * K2[i] + A53 * K3[i] + A54 * K4[i])
            for i in range(n)
        ]),
        n,
    )
    _fill(
        K6,
        deriv([
            Y[i] + h * (A61 * K1[i] + A62 * K2[i] + A63 * K3[i] + A64 * K4[i] + A65 * K5[i])
            for i in range(n)
        ]),
        n,
    )
    for i in range(n):
        Y1[i] = Y[i] + h * (B1 * K1[i] + B3 * K3[i] + B4 * K4[i] + B5 * K5[i] + B6 * K6[i])
    y1 = [Y1[i] for i in range(n)]
    k7 = deriv(y1)
    _fill(K7, k7, n)
    rtol = control.rtol
    scales = control.scales
    m = len(scales)
    acc = 0.0
    for i in range(m):
        e = h * (E1 * K1[i] + E3 * K3[i] + E4 * K4[i] + E5 * K5[i] + E6 * K6[i] + E7 * K7[i])
        lo = fabs(Y[i])
        hi = fabs(Y1[i])
        sc = rtol * (<double>scales[i] + (hi if hi > lo else lo))
        acc += _pow(e / sc, 2.0)
    err = _sqrt(acc / m)
    if err != err:
        raise ArithmeticError("non-finite error estimate")
    dy = [Y1[i] - Y[i] for i in range(n)]
    r3 = [h * K1[i] - (Y1[i] - Y[i]) for i in range(n)]
    r4 = [(Y1[i] - Y[i]) - h * K7[i] - (h * K1[i] - (Y1[i] - Y[i])) for i in range(n)]
    r5 = [
        h * (D1 * K1[i] + D3 * K3[i] + D4 * K4[i] + D5 * K5[i] + D6 * K6[i] + D7 * K7[i])
        for i in range(n)
    ]
    return STEP_TYPE(y1, k7, err, (y, dy, r3, r4, r5))


def dense_state(tuple dense, double theta):
    """event_integration.dense_state."""
    y0, dy, r3, r4, r5 = dense
    cdef double s1 = 1.0 - theta
    cdef Py_ssize_t i, n = len(y0)
    return [
        <double>y0[i] + theta * (
            <double>dy[i] + s1 * (<double>r3[i] + theta * (<double>r4[i] + s1 * <double>r5[i]))
        )
        for i in range(n)
    ]


# -- the loop between events, compiled for the M739 verge -------------------------------
# event_integration.advance for a VergeCore (with its held train or the live train physics,
# bare, with the torque's moments appended, or ending at its first event): the steps, the
# error control, the event location, the re-step and the accept hooks run here on C arrays
# with the model's smooth parts (deriv, indicators) in C; the model's events, the instant's
# other events and an observer are the Python code's.  The mode is read from the Python
# objects at the start and after each call into Python, so both see the same model.

cdef dict CLASSES = dict.fromkeys((
    "verge_core", "monolithic", "held_train", "live_train", "moments", "until_first_event",
    "torque_at", "verge_budget_spent", "train_model", "ramped_load",
))
cdef object COMPONENT_ERROR = RuntimeError
cdef object BUDGET_SPENT = RuntimeError  # event_integration.StepBudgetSpent
cdef object FIRE_AT_INSTANT = None
cdef object FIRST_STEP = None

cdef double SAFETY = 0.9, GROW_MAX = 5.0, SHRINK_MIN = 0.2, EXPONENT = 0.2
cdef double SHRINK_ON_FAILURE = 0.25, H_MIN_RELATIVE = 1e-14, H_MIN_ABSOLUTE = 1e-16


def use_integration(component_error, budget_spent, fire_at_instant, first_step):
    """event_integration's errors and the helpers its compiled loop calls back."""
    global COMPONENT_ERROR, BUDGET_SPENT, FIRE_AT_INSTANT, FIRST_STEP
    COMPONENT_ERROR, BUDGET_SPENT = component_error, budget_spent
    FIRE_AT_INSTANT, FIRST_STEP = fire_at_instant, first_step


def use_classes(**classes):
    """The classes the compiled loop recognises (by role): verge_core, monolithic,
    held_train, live_train, moments, until_first_event, torque_at, verge_budget_spent."""
    CLASSES.update(classes)


cdef inline int _fidx(int face):
    return 1 if face == 1 else 0


cdef int _kinem_c(
    double phi, double alpha, double a, double b, double c, double* o
) except -1:
    """kinem into o: psi, g, u, v, a1p, b1p, d1p."""
    cdef double cap_a = a * _cos(alpha) + b * _cos(phi - alpha)
    cdef double cap_b = a * _sin(alpha) - b * _sin(phi - alpha)
    cdef double cap_c = c * _sin(alpha)
    cdef double disc = cap_a * cap_a + cap_b * cap_b - cap_c * cap_c
    cdef double psi, spa, cpa, arg, sarg, carg, g, p, q
    if disc < 0.0:
        disc = 0.0
    psi = 2.0 * atan2(cap_a - _sqrt(disc), cap_b + cap_c)
    if psi < 0.0:
        psi += TWO_PI
    spa = _sin(psi + alpha)
    cpa = _cos(psi + alpha)
    arg = phi - alpha - psi
    sarg = _sin(arg)
    carg = _cos(arg)
    g = (b * _sin(phi) - c * _sin(psi)) / spa
    p = b * carg
    q = a * cpa + p
    o[0] = psi
    o[1] = g
    o[2] = p / q
    o[3] = (a * p * p * spa - b * _pow(p - q, 2.0) * sarg) / (q * q * q)
    o[4] = p
    o[5] = b * sarg
    o[6] = c * _cos(alpha) + g
    return 0


cdef inline double _vertex_c(
    double t0, double p0, double t1, double p1, double t2, double p2
) except? -2.0:
    """verge_escapement._vertex."""
    cdef double d01, d12, curvature, top
    if not (t0 < t1 and t1 < t2 and p1 >= p0 and p1 >= p2):
        return -INFINITY
    d01 = (p1 - p0) / (t1 - t0)
    d12 = (p2 - p1) / (t2 - t1)
    curvature = (d12 - d01) / (t2 - t0)
    if curvature >= 0.0:
        return -INFINITY
    top = 0.5 * (t0 + t1) - d01 / (2.0 * curvature)
    return p0 + (top - t0) * (d01 + curvature * (top - t1))


cdef class _Dense:
    """The dense output of one accepted step as a function of time (event_integration
    ._interpolant)."""

    cdef double r[5][MAX_STATES]
    cdef double t0, h
    cdef Py_ssize_t n

    def __call__(self, double t):
        cdef double theta = (t - self.t0) / self.h
        cdef double s1 = 1.0 - theta
        cdef Py_ssize_t i
        return [
            self.r[0][i] + theta * (
                self.r[1][i] + s1 * (self.r[2][i] + theta * (self.r[3][i] + s1 * self.r[4][i]))
            )
            for i in range(self.n)
        ]


cdef class Sampler:
    """The monolithic model's observer (orchestrator.scenes.m739.monolithic.simulate), run
    in C by the compiled loop; any other loop calls it as the Python observer it wraps.
    ``columns``: the lists t, phi, phi_dot, psi, psi_dot, regime, f12, f23, pn; ``count``:
    a one-element list, the index of the next sample (shared with the Python observer)."""

    cdef readonly object core, observe
    cdef readonly list columns, count
    cdef readonly double dt, psic0

    def __init__(self, core, observe, list columns, list count, double dt, double psic0):
        self.core, self.observe, self.columns, self.count = core, observe, columns, count
        self.dt, self.psic0 = dt, psic0

    def __call__(self, t0, t1, state_at):
        return self.observe(t0, t1, state_at)


cdef class _Loop:
    """event_integration.advance on C arrays for one model (a subclass gives its deriv,
    indicators, accept, and how its mode is read from and written back to Python), with
    the train physics' response parts (components.gear_train.TrainPhysics) for the models
    that carry the live train."""

    cdef object model
    cdef bint halted
    cdef Py_ssize_t n, n_ind
    # TrainPhysics: its mode and constants
    cdef int direction, i1r_sign, s1, s2
    cdef double n1, n2, phi_lo, phi_hi
    cdef double kmu, kdn, a15c, a16, a31c, a42c, a43, a44c
    cdef double al1_in, span1, du1, u1_start, al2_in, span2, du2, u2_start
    cdef double rb1_cap, rb2_cap, d1, d2, phi1c, n31, n32, m1, rc1, r1, rho1
    cdef double tr_om2, tr_om_abs, tr_mu_abs, i1, i2, i3, a35, t2, t3, i_stot

    cdef int deriv(self, double* y, double* out) except -1:
        return 0

    cdef int indicators(self, double* y, double* g) except -1:
        return 0

    cdef int accept(self, double* y, double t) except -1:
        return 0

    cdef int load(self) except -1:
        return 0

    cdef int store(self) except -1:
        return 0

    cdef bint sample_ready(self, Sampler sampler) except -1:
        return False

    cdef int sample(
        self, Sampler sampler, double r[5][MAX_STATES], double t0, double h, double t1
    ) except -1:
        return 0

    cdef int setup_live(self, object tr) except -1:
        """The train physics' constants."""
        td = tr.d
        self.al1_in, self.span1, self.du1, self.u1_start = (
            tr.al1_in, tr.span1, tr.du1, tr.u1_start
        )
        self.al2_in, self.span2, self.du2, self.u2_start = (
            tr.al2_in, tr.span2, tr.du2, tr.u2_start
        )
        self.rb1_cap, self.rb2_cap, self.d1, self.d2 = td.rb1_cap, td.rb2_cap, tr.d1, tr.d2
        self.phi1c, self.n31, self.n32 = td.phi1c, tr.n31, tr.n32
        self.m1, self.rc1, self.r1, self.rho1 = td.m1, td.rc1, td.r1, td.rho1
        self.tr_om2, self.tr_om_abs, self.tr_mu_abs = tr.om2, tr.om_abs, tr.mu_abs
        self.i1, self.i2, self.i3 = td.i1, td.i2, td.i3
        self.a35, self.t2, self.t3 = tr.a35, tr.t2, tr.t3
        self.i_stot = tr.i_stot
        return 0

    cdef int load_live(self, object tr) except -1:
        """The train physics' mode."""
        self.direction = tr.direction
        self.i1r_sign, self.s1, self.s2 = tr.i1r_sign, tr.s1, tr.s2
        self.n1, self.n2 = tr.n1, tr.n2
        self.phi_lo, self.phi_hi = tr.phi_lo, tr.phi_hi
        (self.kmu, self.kdn, self.a15c, self.a16, self.a31c, self.a42c, self.a43,
         self.a44c) = tr._k[:8]
        return 0

    # -- the train --------------------------------------------------------------------
    cdef int parts(self, double phi, double phi_dot, double* o) except -1:
        """TrainPhysics._parts: j_ref, t_ref, f0, k, a42, a43, a44."""
        cdef double mu = self.kmu, dn = self.kdn
        cdef double al1 = self.al1_in + self.span1 * (self.du1 * phi + self.u1_start - self.n1)
        cdef double al2 = self.al2_in + self.span2 * (self.du2 * phi + self.u2_start - self.n2)
        cdef double a1 = al1 * self.rb1_cap
        cdef double a2 = al2 * self.rb2_cap
        cdef double a15 = self.a15c - mu * self.s2 * (self.d2 - a2)
        cdef double a31 = self.a31c - mu * self.s1 * a1
        cdef double a42 = self.a42c - mu * self.s1 * (self.d1 - a1)
        cdef double a44 = self.a44c - mu * self.s2 * a2
        cdef double n31 = self.n31
        cdef double big_phi = self.phi1c + n31 * phi
        cdef double sp = _sin(big_phi), cp = _cos(big_phi)
        cdef double m1 = self.m1, r1 = self.r1, rho1 = self.rho1
        cdef double m1r = m1 * self.rc1
        cdef double x = m1r * (mu * cp - sp)
        cdef double a24 = fabs(m1 * r1 + m1r * (cp + mu * sp)) / dn
        cdef double a28 = fabs(mu * m1 * r1 + x) / dn
        cdef double a25 = fabs(m1r * (cp + mu * sp)) / dn
        cdef double a29 = fabs(x) / dn
        cdef double a2526 = a25 + a29
        cdef double mu_abs = self.tr_mu_abs
        cdef double a32 = mu * rho1 * self.tr_om2 * (a24 + a28)
        cdef double a33 = 2.0 * mu_abs * rho1 * self.tr_om_abs * a2526
        cdef double a34 = mu * rho1 * a2526
        cdef double i1r = self.i1 + self.i1r_sign * mu_abs * rho1 * (
            fabs(m1r * (sp - mu * cp)) / dn + fabs(m1r * (mu * sp + cp)) / dn
        )
        if i1r < 0.0:
            i1r = 0.0
        cdef double w1 = n31 * phi_dot
        cdef double k = (self.i2 * self.n32 - a42 * i1r * n31 / a31) / a44
        cdef double f0 = (
            a42 * (-a32 - a33 * w1 - a34 * w1 * w1 - self.a35 * sp) / a31 - self.t2 * self.a43
        ) / a44
        o[0] = self.i3 - a15 * k
        o[1] = a15 * f0 - self.t3 * self.a16
        o[2] = f0
        o[3] = k
        o[4] = a42
        o[5] = self.a43
        o[6] = a44
        return 0

    # -- one Dormand-Prince step ------------------------------------------------------
    cdef double dp5(
        self, double* y, double* k1, double h, double rtol, double* scales, Py_ssize_t m,
        double* y1, double* k7, double r[5][MAX_STATES],
    ) except? -2.0:
        """event_integration._dp5_step: y1, k7, the dense output r; returns err."""
        cdef Py_ssize_t n = self.n, i
        cdef double k2[MAX_STATES]
        cdef double k3[MAX_STATES]
        cdef double k4[MAX_STATES]
        cdef double k5[MAX_STATES]
        cdef double k6[MAX_STATES]
        cdef double z[MAX_STATES]
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

    # -- calls into the Python code ---------------------------------------------------
    cdef list pylist(self, double* y):
        return [y[i] for i in range(self.n)]

    cdef double locate(
        self, double r[5][MAX_STATES], double h, Py_ssize_t idx, double g_lo, double g_hi,
        double tol_t, double* y_hi,
    ) except? -2.0:
        """event_integration._locate: the offset, the state into y_hi."""
        cdef double lo = 0.0, hi = 1.0, tol = tol_t / h, th, gt, s1
        cdef double yt[MAX_STATES]
        cdef double g[16]
        cdef bint found = False
        cdef int side = 0, it
        cdef Py_ssize_t i, n = self.n
        for it in range(80):
            if hi - lo <= tol:
                break
            th = hi - g_hi * (hi - lo) / (g_hi - g_lo)
            if not (lo < th and th < hi):
                th = 0.5 * (lo + hi)
            s1 = 1.0 - th
            for i in range(n):
                yt[i] = r[0][i] + th * (r[1][i] + s1 * (r[2][i] + th * (r[3][i] + s1 * r[4][i])))
            self.indicators(yt, g)
            gt = g[idx]
            if gt < 0.0:
                hi, g_hi = th, gt
                for i in range(n):
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
            for i in range(n):
                y_hi[i] = r[0][i] + hi * (
                    r[1][i] + s1 * (r[2][i] + hi * (r[3][i] + s1 * r[4][i]))
                )
        return hi * h

    cdef object run(
        self, list y, double h_total, object control, double h_try, double tol_t,
        long max_events, object observe,
    ):
        """event_integration.advance, operation for operation."""
        cdef Py_ssize_t n = self.n, n_ind = self.n_ind, i, m, first
        cdef double Y[MAX_STATES]
        cdef double K1[MAX_STATES]
        cdef double Y1[MAX_STATES]
        cdef double K7[MAX_STATES]
        cdef double YB[MAX_STATES]
        cdef double YL[MAX_STATES]
        cdef double YT[MAX_STATES]
        cdef double KT[MAX_STATES]
        cdef double SC[MAX_STATES]
        cdef double RT[5][MAX_STATES]
        cdef double G0[16]
        cdef double G1[16]
        cdef double GT[16]
        cdef double t = 0.0, h, h_next, h_min, h_step, left, end, err, factor, x
        cdef double th_best, th, tn, rtol = control.rtol, h_max = control.h_max
        cdef double t_first = -1.0, t_event = -1.0
        cdef long n_events = 0, steps = 0, rejected = 0, max_steps = 0
        cdef bint has_max = control.max_steps is not None
        cdef _Dense dense = _Dense()
        cdef int nudge_i
        cdef Py_ssize_t j
        cdef double nudges[4]
        nudges[0], nudges[1], nudges[2], nudges[3] = 0.0, 1.0, 4.0, 16.0
        if has_max:
            max_steps = control.max_steps
        scales = control.scales
        m = len(scales)
        for i in range(m):
            SC[i] = scales[i]
        for i in range(n):
            Y[i] = y[i]
        recent = []
        dense.n = n
        model = self.model
        sampler = observe if type(observe) is Sampler and self.sample_ready(observe) else None
        try:
            self.indicators(Y, G0)
            self.deriv(Y, K1)
            end = h_total * (1.0 - 1e-14)
            if h_try > 0.0:
                h = h_try
            else:
                h = FIRST_STEP(self.pylist(Y), self.pylist(K1), control)
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
                    err = self.dp5(Y, K1, h_step, rtol, SC, m, Y1, K7, dense.r)
                    self.indicators(Y1, G1)
                except (ArithmeticError, ValueError) as exc:
                    if h_step <= 1e3 * tol_t:
                        raise COMPONENT_ERROR(
                            f"model evaluation failed at a tiny step: {exc}"
                        ) from exc
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
                for i in range(n):
                    YB[i] = Y1[i]
                for i in range(n_ind):
                    if G0[i] >= 0.0 and G1[i] < 0.0:
                        if G0[i] == 0.0:
                            th = 0.0
                            for j in range(n):
                                YL[j] = Y[j]
                        else:
                            th = self.locate(dense.r, h_step, i, G0[i], G1[i], tol_t, YL)
                        if first < 0 or th < th_best:
                            first, th_best = i, th
                            for j in range(n):
                                YB[j] = YL[j]
                if 0.0 < th_best and th_best < h_step:
                    for nudge_i in range(4):
                        tn = th_best + nudges[nudge_i] * tol_t
                        try:
                            self.dp5(Y, K1, tn, rtol, SC, m, YT, KT, RT)
                        except (ArithmeticError, ValueError):
                            break
                        self.indicators(YT, GT)
                        if GT[first] < 0.0:
                            th_best = tn
                            for j in range(n):
                                YB[j] = YT[j]
                            break
                if sampler is not None:
                    self.sample(sampler, dense.r, t, h_step, t + th_best)
                elif observe is not None:
                    dense.t0, dense.h = t, h_step
                    observe(t, t + th_best, dense)
                    dense = _Dense()
                    dense.n = n
                if first < 0:
                    for i in range(n):
                        Y[i] = Y1[i]
                        K1[i] = K7[i]
                    t += h_step
                    for i in range(n_ind):
                        G0[i] = G1[i]
                    h = h_next
                    self.accept(Y, t)
                    if self.halted:
                        break
                    continue
                for i in range(n):
                    Y[i] = YB[i]
                t += th_best
                if th_best > 0.0:
                    self.accept(Y, t)
                self.store()
                y_after, fired, g = FIRE_AT_INSTANT(
                    model, self.pylist(Y), first, t, tuple([G0[i] for i in range(n_ind)])
                )
                self.load()
                for i in range(n):
                    Y[i] = y_after[i]
                for i in range(n_ind):
                    G0[i] = g[i]
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
                if self.halted:
                    break
        finally:
            self.store()
        return self.pylist(Y), t_first, t_event, n_events, h_next, steps, rejected


cdef class _VergeRun(_Loop):
    """One call of the compiled loop: the model's constants and mode as C values."""

    cdef object core, train
    cdef bint monolithic, live, moments, has_budget
    cdef bint bare  # the core's own deriv and indicators only (verge_deriv, verge_indicators)
    cdef Py_ssize_t n_own
    cdef long long budget
    # VergeConstants
    cdef double a, b, c, mu1, mu_abs, om2, om_abs, beta3, gamma_pp, dn1, ip, a54
    cdef double rho3, rho_p, rcp, mp, r4
    cdef double alpha[2]
    cdef double c1[2]
    # VergeCore's mode
    cdef int face, s4, s5, ipr_sign
    cdef bint coupled, train_stuck, verge_stuck
    cdef double phi_off, psic, phi_stop
    # the train: held response or live physics
    cdef double j_ref, t_ref, c_load, j_phi, t_phi, t_w, phi0, w0
    # monolithic: the raised contact indicator and the force maxima
    cdef bint has_shift
    cdef int shift_face
    cdef double shift_phi_off, shift
    cdef double f23_max, f12_max, ff23_max, ff12_max, pn_max
    # VergeCore.accept: the normal force's peak and its last two points
    cdef double pn_peak
    cdef int n_points
    cdef double pts[2][2]

    cdef int setup(self, object model, object core, bint moments, Py_ssize_t n_own) except -1:
        self.model, self.core, self.train = model, core, core.train
        self.monolithic = type(core) is CLASSES["monolithic"] and not self.bare
        self.live = type(self.train) is CLASSES["live_train"]
        self.moments = moments
        self.n_own = n_own
        self.n = n_own + (3 if moments else 0)
        self.n_ind = 10 if self.live else 9
        k = core.k
        d = k.d
        self.a, self.b, self.c = k.a, k.b, k.c
        self.mu1, self.mu_abs = k.mu1, k.mu_abs
        self.om2, self.om_abs = k.om2, k.om_abs
        self.beta3, self.gamma_pp, self.dn1 = k.beta3, k.gamma_pp, k.dn1
        self.ip, self.a54 = k.ip, k.a54
        self.rho3, self.rho_p, self.rcp, self.mp, self.r4 = d.rho3, d.rho_p, d.rcp, d.mp, d.r4
        self.alpha[1], self.alpha[0] = k.alpha.get(1), k.alpha.get(-1)
        self.c1[1], self.c1[0] = k.c1.get(1), k.c1.get(-1)
        self.phi_stop = core.phi_stop
        if self.live:
            self.setup_live(self.train)
        self.load()
        return 0

    cdef int load(self) except -1:
        """The mode, as the Python code left it."""
        core, tr = self.core, self.train
        self.face, self.s4, self.s5, self.ipr_sign = core.face, core.s4, core.s5, core.ipr_sign
        self.coupled, self.train_stuck = core.coupled, core.train_stuck
        self.verge_stuck = core.verge_stuck
        self.phi_off, self.psic = core.phi_off, core.psic
        self.direction = tr.direction
        budget = core.budget
        self.has_budget = budget is not None
        if self.has_budget:
            self.budget = budget
        if self.live:
            self.load_live(tr)
        else:
            self.j_ref, self.t_ref, self.c_load = tr.j_ref, tr.t_ref, tr.c_load
            self.j_phi, self.t_phi, self.t_w = tr.j_phi, tr.t_phi, tr.t_w
            self.phi0, self.w0 = tr.phi0, tr.w0
        if self.bare:
            return 0
        if self.monolithic:
            shift = core.gap_shift
            self.has_shift = shift is not None
            if self.has_shift:
                self.shift_face, self.shift_phi_off, self.shift = shift
            self.f23_max, self.f12_max, self.pn_max = core.f23_max, core.f12_max, core.pn_max
            self.ff23_max, self.ff12_max = core.ff23_max, core.ff12_max
        else:
            self.pn_peak = core.pn_peak
            points = core.pn_points
            self.n_points = len(points)
            for i in range(self.n_points):
                self.pts[i][0], self.pts[i][1] = points[i]
        self.halted = bool(getattr(self.model, "halted", False))
        return 0

    cdef int store(self) except -1:
        """What the loop changed, for the Python code."""
        core = self.core
        core.budget = self.budget if self.has_budget else None
        if self.monolithic:
            core.f23_max, core.f12_max, core.pn_max = self.f23_max, self.f12_max, self.pn_max
            core.ff23_max, core.ff12_max = self.ff23_max, self.ff12_max
        else:
            core.pn_peak = self.pn_peak
            core.pn_points = tuple(
                [(self.pts[i][0], self.pts[i][1]) for i in range(self.n_points)]
            )
        return 0

    cdef int response(self, double phi, double phi_dot, double* o) except -1:
        """(J_ref, T_ref, c_load) of the train."""
        cdef double p[7]
        cdef double dp
        if self.live:
            self.parts(phi, phi_dot, p)
            o[0], o[1], o[2] = p[0], p[1], 1.0
        else:
            dp = phi - self.phi0
            o[0] = self.j_ref + self.j_phi * dp
            o[1] = self.t_ref + self.t_phi * dp + self.t_w * (phi_dot - self.w0)
            o[2] = self.c_load
        return 0

    # -- the verge --------------------------------------------------------------------
    cdef int pivot(self, int s5, double psi_c, double* o) except -1:
        """VergeConstants.pivot: A19, A20, A22 (independent of psi_c for r_cp = 0, where
        the Python code remembers its first values)."""
        cdef double mu1 = self.mu1, dn1 = self.dn1, g = self.gamma_pp
        cdef double mp = self.mp, r4 = self.r4, rcp = self.rcp, rho_p = self.rho_p
        cdef double sp = 0.0, cp = 0.0, a2, a6, a3, a4
        if rcp != 0.0:
            sp, cp = _sin(psi_c), _cos(psi_c)
        a2 = fabs(mp * (r4 * (_sin(g) - mu1 * s5 * _cos(g)) + rcp * (sp - mu1 * s5 * cp)))
        a6 = fabs(mp * (-r4 * (_cos(g) + mu1 * s5 * _sin(g)) - rcp * (cp + mu1 * s5 * sp)))
        a3 = fabs(mp * rcp * (sp - mu1 * s5 * cp)) / dn1
        a4 = fabs(mp * rcp * (cp + mu1 * s5 * sp)) / dn1
        o[0] = rho_p * mu1 * s5 * (a2 + a6) / dn1
        o[1] = rho_p * mu1 * (a3 + a4)
        o[2] = rho_p * mu1 * (a4 + a3)
        return 0

    cdef double ipr(self, double psi) except? -2.0:
        cdef double pv[3]
        cdef double v
        self.pivot(1, psi + self.psic, pv)
        v = self.ip + self.ipr_sign * pv[2]
        return v if v > 0.0 else 0.0

    cdef int coupled_terms(self, double y0, double w, double* o) except -1:
        """VergeCore._coupled_terms into o[0:13]."""
        cdef double kn[7]
        cdef double pv[3]
        cdef double tr[3]
        cdef int face = self.face, fi = _fidx(face)
        cdef double phi_l = y0 + self.phi_off
        cdef double alpha = self.alpha[fi]
        cdef double psi, g, u, v, a1p, b1p, d1p, a19, a20, a21, a17, a18, ipr, j, t, c
        cdef double a52, cent, psi_d, n, den, acc, psi_dd, pn, vst
        cdef int s4 = self.s4, s5 = self.s5
        cdef double mu1, mu, spa, cpa, chi, sc, cc, dn, c1p, a1, a5, a9, a12
        _kinem_c(phi_l, alpha, self.a, self.b, self.c, kn)
        psi, g, u, v, a1p, b1p, d1p = kn[0], kn[1], kn[2], kn[3], kn[4], kn[5], kn[6]
        self.pivot(s5, psi + self.psic, pv)
        a19, a20 = pv[0], pv[1]
        a21 = s5 * a20
        # contact_coefficients
        mu1 = self.mu1
        mu = self.mu_abs * self.direction
        spa, cpa = _sin(psi + alpha), _cos(psi + alpha)
        chi = psi + alpha + self.beta3
        sc, cc = _sin(chi), _cos(chi)
        dn = 1.0 + mu * mu
        c1p = self.c1[fi]
        if face == 1:
            a1 = fabs(-mu1 * (s4 + s5) * spa - (1.0 - s4 * s5 * mu1 * mu1) * cpa) / self.dn1
            a5 = fabs(mu1 * (s4 + s5) * cpa + (1.0 - s4 * s5 * mu1 * mu1) * spa) / self.dn1
            a9 = fabs((mu1 * s4 + mu) * sc + (1.0 - mu * mu1 * s4) * cc) / dn
            a12 = fabs((1.0 - mu * mu1 * s4) * sc - (s4 * mu1 + mu) * cc) / dn
            a17 = a1p - mu1 * s4 * b1p + mu * self.rho3 * (a9 + a12)
            a18 = d1p - c1p * mu1 * s4 - self.rho_p * mu1 * s5 * (a1 + a5)
        else:
            a1 = fabs(mu1 * (s5 - s4) * spa + (1.0 + mu1 * mu1 * s4 * s5) * cpa) / self.dn1
            a5 = fabs(mu1 * (s5 - s4) * cpa - (1.0 + mu1 * mu1 * s4 * s5) * spa) / self.dn1
            a9 = fabs((mu1 * s4 - mu) * sc - (1.0 + s4 * mu * mu1) * cc) / dn
            a12 = fabs(-(1.0 + mu * mu1 * s4) * sc + (mu - mu1 * s4) * cc) / dn
            a17 = -a1p - mu1 * s4 * b1p + mu * self.rho3 * (a9 + a12)
            a18 = -(d1p + c1p * mu1 * s4 + self.rho_p * mu1 * s5 * (a1 + a5))
        ipr = self.ipr(psi)
        self.response(y0, w, tr)
        j, t, c = tr[0], tr[1], tr[2]
        a52 = 2.0 * self.om_abs * a20
        cent = self.a54 * _sin(self.gamma_pp - psi - self.psic)
        psi_d = u * w
        n = (ipr * v + a21 * u * u) * w * w + a52 * psi_d + self.om2 * a19 - cent
        den = j * a18 + c * a17 * ipr * u
        if self.train_stuck:
            acc = 0.0
        else:
            acc = (a18 * t - c * a17 * n) / den
        psi_dd = u * acc + v * w * w
        pn = (ipr * psi_dd + a21 * psi_d * psi_d + a52 * psi_d + self.om2 * a19 - cent) / a18
        vst = -(w * self.b * _sin(phi_l - psi - alpha) + psi_d * self.c * _sin(alpha))
        o[0] = acc
        o[1] = psi
        o[2] = psi_d
        o[3] = psi_dd
        o[4] = pn
        o[5] = -a17 * pn
        o[6] = g
        o[7] = u
        o[8] = vst
        o[9] = den / a18
        o[10] = cent
        o[11] = -a17 * n / a18
        o[12] = a17 * ipr * u / a18
        return 0

    cdef int free_terms(self, double* y, double* o) except -1:
        """VergeCore.free_terms: phi_dd, psi_dd, cent."""
        cdef double pv[3]
        cdef double tr[3]
        cdef double psi = y[2], psi_d = y[3], cent, psi_dd, a52
        cent = self.a54 * _sin(self.gamma_pp - psi - self.psic)
        if self.verge_stuck:
            psi_dd = 0.0
        else:
            self.pivot(self.s5, psi + self.psic, pv)
            a52 = 2.0 * self.om_abs * pv[1]
            psi_dd = (
                -self.s5 * pv[1] * psi_d * psi_d - a52 * psi_d - self.om2 * pv[0] + cent
            ) / self.ipr(psi)
        if self.train_stuck:
            o[0] = 0.0
        else:
            self.response(y[0], y[1], tr)
            o[0] = tr[1] / tr[0]
        o[1] = psi_dd
        o[2] = cent
        return 0

    cdef int deriv(self, double* y, double* out) except -1:
        """VergeCore.deriv (and WithMoments' appended states)."""
        cdef double o[13]
        cdef double w = y[1], v = 0.0
        if self.coupled:
            self.coupled_terms(y[0], w, o)
            out[0] = w
            out[1] = o[0]
            out[2] = o[2]
            out[3] = o[3]
            out[4] = -o[5] * w - self.ip * o[2] * o[3] + o[10] * o[2]
            v = o[5]
        else:
            self.free_terms(y, o)
            out[0] = w
            out[1] = o[0]
            out[2] = y[3]
            out[3] = o[1]
            out[4] = -self.ip * y[3] * o[1] + o[2] * y[3]
        if self.moments:
            out[5] = 1.0
            out[6] = v
            out[7] = y[5] * v
        return 0

    cdef int indicators(self, double* y, double* g) except -1:
        """VergeCore.indicators (with the monolithic model's raised contact indicator)."""
        cdef double o[13]
        cdef int sigma = self.face, fi = _fidx(sigma)
        cdef double hi = 1.0, lo = 1.0, wheel, stop, phi_l, psi, alpha, arg, f, gp, acc, psi_dd
        if self.has_budget:
            self.budget -= 1
            if self.budget < 0:
                raise CLASSES["verge_budget_spent"]("internal step budget spent")
        if self.live:
            hi, lo = self.phi_hi - y[0], y[0] - self.phi_lo
        wheel = 1.0 if self.train_stuck else self.direction * y[1]
        stop = self.phi_stop - y[0]
        if self.coupled:
            self.coupled_terms(y[0], y[1], o)
            g[0] = sigma * o[6]
            g[1] = o[4]
            g[2] = self.s4 * o[8]
            g[3] = self.s5 * o[2]
            acc, psi_dd = o[0], o[3]
        else:
            phi_l = y[0] + self.phi_off
            psi = y[2]
            alpha = self.alpha[fi]
            arg = phi_l - psi - alpha
            f = self.a * _sin(psi + alpha) - self.b * _sin(arg) - self.c * _sin(alpha)
            gp = self.a * _cos(psi + alpha) + self.b * _cos(arg) - self.c * _cos(alpha)
            g[0] = sigma * gp
            g[1] = sigma * f
            g[2] = 1.0
            g[3] = 1.0 if self.verge_stuck else self.s5 * y[3]
            self.free_terms(y, o)
            acc, psi_dd = o[0], o[1]
            if (
                self.has_shift and self.shift_face == self.face
                and self.shift_phi_off == self.phi_off
            ):
                g[1] = g[1] + self.shift
        g[4] = wheel
        g[5] = hi
        g[6] = lo
        g[7] = stop
        g[8] = self.ipr_sign * self.s5 * psi_dd
        if self.live:
            g[9] = self.i1r_sign * self.direction * acc
        return 0

    cdef bint sample_ready(self, Sampler sampler) except -1:
        return sampler.core is self.core and self.live and self.n == 5

    cdef int sample(
        self, Sampler sampler, double r[5][MAX_STATES], double t0, double h, double t1
    ) except -1:
        """The monolithic model's observer (orchestrator.scenes.m739.monolithic.simulate):
        the samples every sample_dt on the dense output of the step, each with the forces."""
        cdef double y[MAX_STATES]
        cdef double o[13]
        cdef double p[7]
        cdef double t_base = self.core.t_base, dt = sampler.dt, t_abs, th, s1, body, acc, pn
        cdef double f12, f23
        cdef long count = sampler.count[0]
        cdef Py_ssize_t i
        cdef int regime
        cols = sampler.columns
        while count * dt - t_base <= t1:
            t_abs = count * dt
            th = ((t_abs - t_base) - t0) / h
            s1 = 1.0 - th
            for i in range(self.n):
                y[i] = r[0][i] + th * (r[1][i] + s1 * (r[2][i] + th * (r[3][i] + s1 * r[4][i])))
            body = y[2] + self.psic - sampler.psic0
            regime = 0 if not self.coupled else (1 if self.face == 1 else 2)
            if self.coupled:
                self.coupled_terms(y[0], y[1], o)
                acc, pn = o[0], o[4]
            else:
                self.free_terms(y, o)
                acc, pn = o[0], 0.0
            self.parts(y[0], y[1], p)
            f23 = p[2] + p[3] * acc
            f12 = (f23 * p[6] + self.t2 * p[5] - self.i2 * self.n32 * acc) / p[4]
            cols[0].append(t_abs)
            cols[1].append(y[0])
            cols[2].append(y[1])
            cols[3].append(atan2(_sin(body), _cos(body)))
            cols[4].append(y[3])
            cols[5].append(regime)
            cols[6].append(f12)
            cols[7].append(f23)
            cols[8].append(pn)
            count += 1
            sampler.count[0] = count
        return 0

    cdef int accept(self, double* y, double t) except -1:
        """VergeCore.accept (the normal force's peak), or the monolithic model's record
        (its force maxima; a self-locking point goes to the Python code, which halts)."""
        cdef double o[13]
        cdef double p[7]
        cdef double pn, peak, acc, f12, f23
        if self.monolithic:
            if self.coupled:
                self.coupled_terms(y[0], y[1], o)
                acc, pn = o[0], o[4]
                self.parts(y[0], y[1], p)
                if o[9] <= 0.0 or p[0] <= 0.0:
                    self.store()
                    self.core.accept([y[i] for i in range(self.n)], t)
                    self.load()
                    return 0
            else:
                self.free_terms(y, o)
                acc = o[0]
                self.parts(y[0], y[1], p)
            f23 = p[2] + p[3] * acc
            f12 = (f23 * p[6] + self.t2 * p[5] - self.i2 * self.n32 * acc) / p[4]
            if self.coupled:
                self.f23_max = f23 if f23 > self.f23_max else self.f23_max
                self.f12_max = f12 if f12 > self.f12_max else self.f12_max
                self.pn_max = pn if pn > self.pn_max else self.pn_max
            else:
                self.ff23_max = f23 if f23 > self.ff23_max else self.ff23_max
                self.ff12_max = f12 if f12 > self.ff12_max else self.ff12_max
            return 0
        if not self.coupled:
            self.n_points = 0
            return 0
        self.coupled_terms(y[0], y[1], o)
        pn = o[4]
        t += self.core.t_base
        if self.n_points == 2:
            peak = _vertex_c(
                self.pts[0][0], self.pts[0][1], self.pts[1][0], self.pts[1][1], t, pn
            )
            peak = peak if peak > pn else pn
        else:
            peak = pn
        self.pn_peak = peak if peak > self.pn_peak else self.pn_peak
        if self.n_points == 0:
            self.n_points = 1
        else:
            if self.n_points == 2:
                self.pts[0][0], self.pts[0][1] = self.pts[1][0], self.pts[1][1]
            self.n_points = 2
        self.pts[self.n_points - 1][0] = t
        self.pts[self.n_points - 1][1] = pn
        return 0



cdef class _TrainRun(_Loop):
    """gear_train._TrainModel (the M739 train with a held escapement load), bare, with its
    torque ramped over the step (train_component.RampedLoad) or ending at its first event."""

    cdef object train_model
    cdef bint stuck, ramped
    cdef double t_esc, j_esc, rate
    cdef double peaks[4]

    cdef int setup(self, object model, object train_model, object ramp) except -1:
        self.model, self.train_model = model, train_model
        self.ramped = ramp is not None
        self.rate = ramp.rate if self.ramped else 0.0
        self.n = 4 if self.ramped else 3
        self.n_ind = 4
        self.setup_live(train_model.p)
        self.load()
        return 0

    cdef int load(self) except -1:
        m = self.train_model
        self.load_live(m.p)
        self.stuck = m.stuck
        self.t_esc, self.j_esc = m.t_esc, m.j_esc
        self.peaks[0], self.peaks[1], self.peaks[2], self.peaks[3] = m.peaks
        self.halted = bool(getattr(self.model, "halted", False))
        return 0

    cdef int store(self) except -1:
        m = self.train_model
        m.peaks = (self.peaks[0], self.peaks[1], self.peaks[2], self.peaks[3])
        m.t_esc = self.t_esc
        return 0

    cdef double accel(self, double phi, double phi_dot) except? -2.0:
        """TrainLoadModel.accel (c_load = 1 for this train)."""
        cdef double p[7]
        self.parts(phi, phi_dot, p)
        return (p[1] + 1.0 * self.t_esc) / (p[0] + 1.0 * self.j_esc)

    cdef int deriv(self, double* y, double* out) except -1:
        cdef double a, phi = y[0], w = y[1]
        if self.ramped:
            self.t_esc = y[3]  # RampedLoad.enter
            out[3] = self.rate
        if self.stuck:
            out[0] = out[1] = out[2] = 0.0
            return 0
        a = self.accel(phi, w)
        out[0] = w
        out[1] = a
        out[2] = w * (
            self.t_esc - self.j_esc * a
            + -self.n31 * self.a35 * _sin(self.phi1c + self.n31 * phi)
            - self.i_stot * a
        )
        return 0

    cdef int indicators(self, double* y, double* g) except -1:
        if self.ramped:
            self.t_esc = y[3]
        g[0] = self.phi_hi - y[0]
        g[1] = y[0] - self.phi_lo
        if self.stuck:
            g[2] = g[3] = 0.0
            return 0
        g[2] = self.direction * y[1]
        g[3] = self.i1r_sign * self.direction * self.accel(y[0], y[1])
        return 0

    cdef int accept(self, double* y, double t) except -1:
        """TrainLoadModel.accept: the mesh-force peaks."""
        cdef double p[7]
        cdef double a, f12, f23
        if self.ramped:
            self.t_esc = y[3]
        if self.stuck:
            return 0
        a = self.accel(y[0], y[1])
        self.parts(y[0], y[1], p)
        f23 = p[2] + p[3] * a
        f12 = (f23 * p[6] + self.t2 * p[5] - self.i2 * self.n32 * a) / p[4]
        if self.t_esc != 0.0 or self.j_esc != 0.0:
            if f12 > self.peaks[0] or f23 > self.peaks[1]:
                self.peaks[0] = f12 if f12 > self.peaks[0] else self.peaks[0]
                self.peaks[1] = f23 if f23 > self.peaks[1] else self.peaks[1]
        elif f12 > self.peaks[2] or f23 > self.peaks[3]:
            self.peaks[2] = f12 if f12 > self.peaks[2] else self.peaks[2]
            self.peaks[3] = f23 if f23 > self.peaks[3] else self.peaks[3]
        return 0


def _train_run(model, y):
    """The compiled loop for gear_train's train model, or None."""
    cdef _TrainRun run
    inner = model
    if type(inner) is CLASSES["until_first_event"]:
        inner = inner.model
    ramp = None
    if type(inner) is CLASSES["ramped_load"]:
        ramp, inner = inner, inner.model
        if ramp.n != 3:
            return None
    if type(inner) is not CLASSES["train_model"] or type(inner.p) is not CLASSES["live_train"]:
        return None
    if len(y) != (4 if ramp is not None else 3):
        return None
    run = _TrainRun()
    run.setup(model, inner, ramp)
    return run


# VergeCore's own deriv and indicators for the Python code that calls them (its events, the
# component's step): the same C functions, the mode read for each call.
cdef dict PYTHON_VERGE = {}


def use_python_verge(**functions):
    """VergeCore's Python deriv and indicators, for a core whose train is neither kind."""
    PYTHON_VERGE.update(functions)


# The constants of the last VergeConstants a held-train core was run with: a component's
# core keeps its constants (the snapshots share them), so each call reads only the mode.
cdef object _BARE_K = None
cdef _VergeRun _BARE_CONSTANTS = None


cdef _VergeRun _bare_run(object core, object y):
    global _BARE_K, _BARE_CONSTANTS
    cdef _VergeRun run, known
    cdef bint held
    train = core.train
    if CLASSES["verge_core"] is None or len(y) < 5:
        return None
    held = type(train) is CLASSES["held_train"]
    if not held and type(train) is not CLASSES["live_train"]:
        return None
    run = _VergeRun()
    run.bare = True
    k = core.k
    if held and k is _BARE_K:
        known = _BARE_CONSTANTS
        run.model, run.core, run.train = None, core, train
        run.monolithic = run.live = run.moments = False
        run.n_own = run.n = 5
        run.n_ind = 9
        run.a, run.b, run.c = known.a, known.b, known.c
        run.mu1, run.mu_abs, run.om2, run.om_abs = known.mu1, known.mu_abs, known.om2, known.om_abs
        run.beta3, run.gamma_pp, run.dn1, run.ip = known.beta3, known.gamma_pp, known.dn1, known.ip
        run.a54, run.rho3, run.rho_p = known.a54, known.rho3, known.rho_p
        run.rcp, run.mp, run.r4 = known.rcp, known.mp, known.r4
        run.alpha[0], run.alpha[1], run.c1[0], run.c1[1] = (
            known.alpha[0], known.alpha[1], known.c1[0], known.c1[1]
        )
        run.phi_stop = core.phi_stop
        run.load()
        return run
    run.setup(None, core, False, 5)
    if held:
        _BARE_K, _BARE_CONSTANTS = k, run
    return run


def verge_indicators(self, y):
    """VergeCore.indicators."""
    cdef double Y[5]
    cdef double g[16]
    cdef Py_ssize_t i
    cdef _VergeRun run = _bare_run(self, y)
    if run is None:
        return PYTHON_VERGE["indicators"](self, y)
    for i in range(5):
        Y[i] = y[i]
    try:
        run.indicators(Y, g)
    finally:
        if run.has_budget:
            self.budget = run.budget
    return tuple([g[i] for i in range(run.n_ind)])


def verge_deriv(self, y):
    """VergeCore.deriv."""
    cdef double Y[5]
    cdef double out[5]
    cdef Py_ssize_t i
    cdef _VergeRun run = _bare_run(self, y)
    if run is None:
        return PYTHON_VERGE["deriv"](self, y)
    for i in range(5):
        Y[i] = y[i]
    run.deriv(Y, out)
    return [out[0], out[1], out[2], out[3], out[4]]


def advance(model, y, double h_total, control, double h_try, double tol_t, long max_events,
            observe):
    """event_integration.advance compiled for the M739 verge core and train model; None for
    any other model (the Python loop runs it)."""
    cdef _VergeRun run
    cdef _Loop train_run
    cdef bint moments = False
    cdef Py_ssize_t n_own
    if len(control.scales) > len(y):
        return None
    if CLASSES["train_model"] is not None and CLASSES["ramped_load"] is not None:
        train_run = _train_run(model, y)
        if train_run is not None:
            return train_run.run(list(y), h_total, control, h_try, tol_t, max_events, observe)
    if CLASSES["verge_core"] is None or CLASSES["moments"] is None:
        return None
    inner = model
    if type(inner) is CLASSES["until_first_event"]:
        inner = inner.model
    if type(inner) is CLASSES["moments"]:
        if getattr(inner.value, "__func__", None) is not CLASSES["torque_at"]:
            return None
        moments = True
        core = inner.model
        n_own = inner.n
    else:
        core = inner
        n_own = len(y)
    if type(core) is not CLASSES["verge_core"] and type(core) is not CLASSES["monolithic"]:
        return None
    train = core.train
    if type(train) is not CLASSES["held_train"] and type(train) is not CLASSES["live_train"]:
        return None
    if n_own != 5 or len(y) != n_own + (3 if moments else 0):
        return None
    run = _VergeRun()
    run.setup(model, core, moments, n_own)
    return run.run(list(y), h_total, control, h_try, tol_t, max_events, observe)


# -- components.verge_escapement.VergeEscapement: its Python around the loop --------------
# The component's inputs taken, the events the jump to them crossed, its outputs: the same
# C functions as the loop, the mode read for each call; the Python methods for a core whose
# train is neither kind.
cdef dict PYTHON_COMPONENT = {}


def use_python_component(**functions):
    """VergeEscapement's Python _take_inputs, _resync_events and _outputs."""
    PYTHON_COMPONENT.update(functions)


def component_take_inputs(self):
    """VergeEscapement._take_inputs."""
    cdef double kn[7]
    cdef double phi_dot
    cdef int face
    core, held = self._core, self._held
    held.j_ref, held.t_ref, held.c_load, held.i_stot = (
        self.J_ref, self.T_ref, self.c_load, self.J_stot
    )
    held.j_phi, held.t_phi, held.t_w = self.J_ref_phi, self.T_ref_phi, self.T_ref_phi_dot
    phi, w = self.phi, self.phi_dot
    held.phi0, held.w0 = phi, w
    held.i_phi = self.J_stot_phi
    phi_dot = w
    if phi_dot != 0.0:
        held.direction = -1 if phi_dot < 0.0 else 1
    last = self._y
    if not core.coupled:
        return [phi, w, last[2], last[3], last[4]]
    # VergeCore._sync_kinematics
    k = core.k
    face = core.face
    _kinem_c(<double>phi + <double>core.phi_off, k.alpha[face], k.a, k.b, k.c, kn)
    return [phi, w, kn[0], kn[2] * phi_dot, last[4]]


def component_resync_events(self, y):
    """VergeEscapement._resync_events."""
    cdef double Y[5]
    cdef double g[16]
    cdef Py_ssize_t i, hit, n
    cdef _VergeRun run
    core = self._core
    for _ in range(8):
        run = _bare_run(core, y)
        g_end = self._g_end
        if run is None or len(g_end) != run.n_ind:
            return PYTHON_COMPONENT["resync_events"](self, y)
        for i in range(5):
            Y[i] = y[i]
        try:
            run.indicators(Y, g)
        finally:
            if run.has_budget:
                core.budget = run.budget
        n = run.n_ind
        hit = -1
        for i in range(n):
            if <double>g_end[i] >= 0.0 and 0.0 > g[i]:
                hit = i
                break
        if hit < 0:
            break
        y = core.event(y, hit, 0.0)
        self._g_end = core.indicators(y)
    return y


def component_outputs(self, y):
    """VergeEscapement._outputs."""
    cdef double Y[5]
    cdef double o[13]
    cdef double acc, psi, psi_d, u, pn, phi_l, alpha, arg, psi_y, g_arm, a1p, d1p, body
    cdef int sigma, fi
    cdef Py_ssize_t i
    core = self._core
    # (a core with a budget spends it on the indicators the Python code evaluates here)
    cdef _VergeRun run = None if core.budget is not None else _bare_run(core, y)
    if run is None:
        return PYTHON_COMPONENT["outputs"](self, y)
    for i in range(5):
        Y[i] = y[i]
    sigma = run.face
    fi = _fidx(sigma)
    alpha = run.alpha[fi]
    if run.coupled:
        run.coupled_terms(Y[0], Y[1], o)
        acc, psi, psi_d, pn, u = o[0], o[1], o[2], o[4], o[7]
        self.PN, self.T_esc, self.ind_pn = pn, o[5], pn
        self.T_esc_static, self.J_esc = o[11], o[12]
        self.J_load = run.ip * u * u
        self.ind_face_end = sigma * o[6]
        self.ind_gap = 0.0
        psi_local, psi_dot = psi, psi_d
    else:
        run.free_terms(Y, o)
        acc = o[0]
        psi_local, psi_dot = y[2], y[3]
        psi, psi_d = Y[2], Y[3]
        self.PN = self.T_esc = self.ind_pn = self.J_load = 0.0
        self.T_esc_static = self.J_esc = 0.0
        # VergeCore.indicators: its first two in free motion
        phi_l = Y[0] + run.phi_off
        arg = phi_l - psi - alpha
        self.ind_face_end = sigma * (
            run.a * _cos(psi + alpha) + run.b * _cos(arg) - run.c * _cos(alpha)
        )
        self.ind_gap = sigma * (
            run.a * _sin(psi + alpha) - run.b * _sin(arg) - run.c * _sin(alpha)
        )
    self.PN_peak = core.pn_peak
    # VergeCore.closing_speed (verge_geometry.face_arms)
    phi_l = Y[0] + run.phi_off
    psi_y = Y[2]
    g_arm = (run.b * _sin(phi_l) - run.c * _sin(psi_y)) / _sin(psi_y + alpha)
    a1p = run.b * _cos(phi_l - psi_y - alpha)
    d1p = run.c * _cos(alpha) + g_arm
    self.v_close = sigma * (a1p * Y[1] - d1p * Y[3])
    self.phi_ddot = acc
    self.phi_own, self.phi_dot_own = y[0], y[1]
    self.psi_local = psi_local
    self.psi_dot = psi_dot
    body = psi + run.psic - <double>core.k.d.psic
    self.psi = atan2(_sin(body), _cos(body))
    self.phi_local = Y[0] + run.phi_off
    self.face = core.face
    self.regime = core.regime
    self.impact_count = core.impacts
    last = core.last_impact
    self.phi_dot_post, self.psi_dot_post = last[2], last[3]
    self.stored_energy = 0.5 * run.ip * psi_d * psi_d
    self.external_work = run.a54 * (_cos(run.gamma_pp - psi - run.psic) - <double>self._cos0)
    self.dissipated_work = y[4]


# -- components.gear_train.GearTrain: its outputs ------------------------------------------
# The response, its slopes (components.train_component.TrainComponent._send_response) and the
# mesh forces from the same C function as the loop; the Python method for other physics.
cdef dict PYTHON_TRAIN = {}
cdef double SLOPE_STEP_ANGLE = 0.0, SLOPE_STEP_SPEED = 0.0
cdef object TRAIN_STUCK = None, TRAIN_FORWARD = None, TRAIN_BACKWARD = None


def use_python_train(outputs, slope_steps, regimes):
    """GearTrain's Python _outputs, the slopes' steps (angle, speed) and the regime codes
    (stuck, forward, backward)."""
    global SLOPE_STEP_ANGLE, SLOPE_STEP_SPEED, TRAIN_STUCK, TRAIN_FORWARD, TRAIN_BACKWARD
    PYTHON_TRAIN["outputs"] = outputs
    SLOPE_STEP_ANGLE, SLOPE_STEP_SPEED = slope_steps
    TRAIN_STUCK, TRAIN_FORWARD, TRAIN_BACKWARD = regimes


def train_outputs(self):
    """GearTrain._outputs."""
    cdef double P[7]
    cdef double N[7]
    cdef double phi, w, j_0, t_0, i_0, dp, dw, speed, acc, f12, f23
    cdef _Loop run
    p, m = self._phys, self._model
    if type(p) is not CLASSES["live_train"] or type(m) is not CLASSES["train_model"]:
        return PYTHON_TRAIN["outputs"](self)
    phi_o, w_o, wd = self._y
    phi, w = phi_o, w_o
    run = _Loop()
    run.setup_live(p)
    run.load_live(p)
    # TrainComponent._send_response
    run.parts(phi, w, P)
    j_0, t_0 = P[0], P[1]
    self.J_ref, self.T_ref, self.c_load = j_0, t_0, 1.0
    i_stot = p.i_stot
    self.J_stot = i_stot
    key = (phi_o, w_o, p.mode_key())
    if key != self._slopes_at:
        # TrainComponent._slopes_of
        i_0 = i_stot
        dp = SLOPE_STEP_ANGLE
        speed = fabs(w)
        dw = SLOPE_STEP_SPEED * (speed if speed > 1.0 else 1.0)
        run.parts(phi + dp, w, N)
        j_hi, t_hi, i_hi = N[0], N[1], <double>i_stot
        run.parts(phi, w + dw, N)
        self._slopes = ((j_hi - j_0) / dp, (t_hi - t_0) / dp, (N[1] - t_0) / dw, (i_hi - i_0) / dp)
        self._slopes_at = key
    self.J_ref_phi, self.T_ref_phi, self.T_ref_phi_dot, self.J_stot_phi = self._slopes
    # TrainLoadModel.accel (c_load = 1)
    acc = 0.0 if m.stuck else (t_0 + 1.0 * <double>m.t_esc) / (j_0 + 1.0 * <double>m.j_esc)
    self.phi, self.phi_dot, self.phi_ddot = phi_o, w_o, acc
    # TrainPhysics.forces
    f23 = P[2] + P[3] * acc
    f12 = (f23 * P[6] + run.t2 * P[5] - run.i2 * run.n32 * acc) / P[4]
    self.F12, self.F23 = f12, f23
    unloaded = self.T_esc == 0.0
    self.FF12 = f12 if unloaded else 0.0
    self.FF23 = f23 if unloaded else 0.0
    phi1c = self._data.phi1c
    self.rotor_angle = phi1c + run.n31 * phi
    self.s1, self.s2 = p.s1, p.s2
    self.indicator_mesh = run.phi_hi - phi if run.direction > 0 else phi - run.phi_lo
    if m.stuck:
        self.regime = TRAIN_STUCK
    else:
        self.regime = TRAIN_FORWARD if run.direction > 0 else TRAIN_BACKWARD
    self.stored_energy = 0.5 * run.i_stot * w * w
    self.external_work = run.a35 * (_cos(<double>phi1c + run.n31 * phi) - <double>self._cos0)
    self.dissipated_work = wd
