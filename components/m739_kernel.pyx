# cython: language_level=3, binding=True, boundscheck=False, wraparound=False
# cython: cdivision=False, initializedcheck=False
"""Compiled twins of the M739 hot paths: the verge's coupled kinematics and contact terms
(components.verge_geometry, components.verge_escapement), the train's response parts
(components.gear_train) and one Dormand-Prince step with its dense output
(components.event_integration).

Each function repeats its Python original operation for operation, in the same order,
so that results are the same bits: ``x ** 2`` is libm's pow as in CPython (built with
-fno-builtin, no fast math, no FMA contraction), a division by zero, an overflowing power
and the sine of an infinity raise what Python raises.  ``components.kernels`` loads this
module; without it the Python originals run.
"""

from libc.math cimport atan2, cos, fabs, fmod, isinf, pow, sin, sqrt

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
