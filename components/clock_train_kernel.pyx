# cython: language_level=3, binding=True, boundscheck=False, wraparound=False
# cython: cdivision=False, initializedcheck=False
"""Compiled twins of the clock-train hot paths: the train's kinematics and contact statics on
its current pieces (components.clock_train_kinematics.ClockMesh._pair_inverse and contact,
components.clock_gear_train.ClockTrainPhysics.evaluate, moments, response, power_terms,
forces, piece_distances, slide_indicators) and the whole loop between events
(components.event_integration.advance) for the clock train's model (_ClockModel, bare, with
its torque ramped or ending at its first event).

Each function repeats its Python original operation for operation, in the same order, so
that results are the same bits: ``x ** 2`` is libm's pow as in CPython (built with
-fno-builtin, no fast math, no FMA contraction), ``math.hypot`` is CPython's own (called,
not libm's), a division by zero and the sine of an infinity raise what Python raises.  The
physics remembers its last kinematics and response (``_memo``, ``_rmemo``; the normal-force
signs read the last position); the compiled loop leaves them as the Python loop would.
``components.kernels`` loads this module; without it the Python originals run.
"""

import math

from libc.math cimport INFINITY, acos, atan2, cos, fabs, fmod, isinf, pow, remainder, sin, sqrt

cdef enum:
    MAX_STATES = 8  # the train's states, with the ramped torque: 4
    N_IND = 7  # _ClockModel's indicators
    N_EV = 20  # evaluate: 8 kinematic values, then 6 statics of each mesh

cdef double TWO_PI = 2.0 * math.pi
cdef object PY_HYPOT = math.hypot  # CPython's, correctly rounded where libm's is not

cdef int LOSS_NONE = 0, LOSS_POINT = 1, LOSS_CYCLE = 2
cdef dict PHASE = {"ror": 0, "rof": 1}
cdef tuple PHASE_NAMES = ("ror", "rof")

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
    return sin(x)


cdef inline double _cos(double x) except? -2.0:
    if isinf(x):
        raise ValueError("math domain error")
    return cos(x)


cdef inline double _sqrt(double x) except? -2.0:
    if x < 0.0:
        raise ValueError("math domain error")
    return sqrt(x)


cdef inline double _acos(double x) except? -2.0:
    if x > 1.0 or x < -1.0:
        raise ValueError("math domain error")
    return acos(x)


cdef inline double _remainder(double x, double y) except? -2.0:
    """math.remainder for a finite divisor: exact, as libm's."""
    if isinf(x):
        raise ValueError("math domain error")
    return remainder(x, y)


cdef inline double _hypot(double x, double y) except? -2.0:
    return PY_HYPOT(x, y)


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


# -- components.clock_train_kinematics.ClockMesh ----------------------------------------
cdef class MeshGeometry:
    """One mesh's constants, each computed by the Python expression it stands for."""

    cdef object mesh
    cdef double ag, dg, dp, ap, be, alpha_p, rho_g, rho_p, b
    cdef double k, c_sin, c_cos, f0, kb  # RoR: 2 ag ap, the D and E offsets, F's constant, 2 ap b
    cdef double t0, sign, gear_pitch, pinion_pitch, opx, opy
    cdef double lo[2]
    cdef double hi[2]
    cdef double inv_sign[2]  # _sign("inv", phase); 0: not asked yet
    cdef bint bounded

    def __init__(self, mesh):
        self.mesh = mesh
        ag, b, be, dg, dp = mesh.a_g, mesh.b, mesh.beta1, mesh.delta_g, mesh.delta_p
        ap, ll = mesh.a_p, mesh.rho_g + mesh.rho_p
        self.ag, self.b, self.be, self.dg, self.dp, self.ap = ag, b, be, dg, dp, ap
        self.alpha_p, self.rho_g, self.rho_p = mesh.alpha_p, mesh.rho_g, mesh.rho_p
        self.k = 2 * ag * ap
        self.c_sin = 2 * ag * b * math.sin(be + dg)
        self.c_cos = 2 * ag * b * math.cos(be + dg)
        self.f0 = ll**2 - ag**2 - ap**2 - b**2
        self.kb = 2 * ap * b
        self.sign = mesh.sign
        self.gear_pitch = mesh.gear_pitch
        self.pinion_pitch = mesh.pinion_pitch
        self.opx, self.opy = mesh.b * math.cos(mesh.beta1), mesh.b * math.sin(mesh.beta1)
        self.inv_sign[0] = self.inv_sign[1] = 0.0
        self.bounded = False

    cdef int bounds(self) except -1:
        """transition()[0] and the piece bounds, asked of the mesh when first needed."""
        self.t0 = self.mesh.transition()[0]
        self.lo[0], self.hi[0] = self.mesh.piece_bounds("ror")
        self.lo[1], self.hi[1] = self.mesh.piece_bounds("rof")
        self.bounded = True
        return 0

    cdef double root_sign(self, int ph) except? -2.0:
        if self.inv_sign[ph] == 0.0:
            self.inv_sign[ph] = self.mesh._sign("inv", PHASE_NAMES[ph])
        return self.inv_sign[ph]

    cdef int pair_inverse(self, double phi2p, int ph, double* o) except -1:
        """ClockMesh._pair_inverse (with _inverse_def, _solve, _near, _derivatives):
        o = v, DER, second derivative."""
        cdef double ag = self.ag, b = self.b, be = self.be, dg = self.dg, dp = self.dp
        cdef double sq, cq, sr, cr, k, d, e, f, dd, de, df, ddd, dde, ddf
        cdef double r, v, sign, sx, cx, g_x, d1, g_uu, g_ux, g_xx
        if ph == 0:
            sq, cq = _sin(phi2p - dp + dg), _cos(phi2p - dp + dg)
            sr, cr = _sin(phi2p - dp - be), _cos(phi2p - dp - be)
            k = self.k
            d = -k * sq - self.c_sin
            e = -k * cq - self.c_cos
            f = self.f0 - self.kb * cr
            dd, de, df = -k * cq, k * sq, self.kb * sr
            ddd, dde, ddf = k * sq, k * cq, self.kb * cr
        else:
            sq, cq = _sin(phi2p + self.alpha_p + dg), _cos(phi2p + self.alpha_p + dg)
            sr, cr = _sin(phi2p + self.alpha_p - be), _cos(phi2p + self.alpha_p - be)
            d, e, f = ag * cq, -ag * sq, self.rho_g - b * sr
            dd, de, df = -ag * sq, -ag * cq, -b * cr
            ddd, dde, ddf = -ag * cq, ag * sq, b * sr
        sign = self.root_sign(ph)  # asked before the root is solved, as in the Python code
        # _solve
        r = _hypot(d, e)
        if fabs(f) > r:
            raise ValueError("no contact: A^2 + B^2 < C^2 (the pair cannot be assembled here)")
        v = atan2(d, e) + sign * _acos(f / r)
        if not self.bounded:
            self.bounds()
        # _near
        v = self.t0 + _remainder(v - self.t0, TWO_PI)
        # _derivatives
        sx, cx = _sin(v), _cos(v)
        g_x = d * cx - e * sx
        d1 = -(dd * sx + de * cx - df) / g_x
        g_uu = ddd * sx + dde * cx - ddf
        g_ux = dd * cx - de * sx
        g_xx = -(d * sx + e * cx)
        o[0] = v
        o[1] = d1
        o[2] = -(g_uu + 2.0 * g_ux * d1 + g_xx * d1 * d1) / g_x
        return 0

    cdef int statics(
        self, double x, double v, int ph, double der, double px, double py, double* o
    ) except -1:
        """ClockTrainPhysics._statics with ClockMesh.contact: o = cross(r_g, n),
        cross(r_p, n), r_g.n, r_p.n, slide, DER."""
        cdef double cgx = self.ag * _cos(v - self.dg)
        cdef double cgy = self.ag * _sin(v - self.dg)
        cdef double opx = self.opx, opy = self.opy
        cdef double nx, ny, r, ex, ey, side, cx, cy, rpx, rpy, gn, pn
        if ph == 0:
            nx = opx + self.ap * _cos(x - self.dp) - cgx
            ny = opy + self.ap * _sin(x - self.dp) - cgy
            r = _hypot(nx, ny)
            nx, ny = nx / r, ny / r
        else:
            ex, ey = _cos(x + self.alpha_p), _sin(x + self.alpha_p)
            side = ex * (cgy - opy) - ey * (cgx - opx)
            if side >= 0.0:
                nx, ny = ey, -ex
            else:
                nx, ny = -ey, ex
        cx, cy = cgx + self.rho_g * nx, cgy + self.rho_g * ny
        rpx, rpy = cx - px, cy - py
        gn, pn = cx * nx + cy * ny, rpx * nx + rpy * ny
        o[0] = cx * ny - cy * nx
        o[1] = rpx * ny - rpy * nx
        o[2] = gn
        o[3] = pn
        o[4] = gn - pn / der
        o[5] = der
        return 0


#: mesh id -> (mesh, its geometry): the meshes of the trains in use (a few; cleared past 64)
cdef dict GEOMETRY = {}


cdef MeshGeometry _geometry(object mesh):
    entry = GEOMETRY.get(id(mesh))
    if entry is not None and entry[0] is mesh:
        return entry[1]
    if len(GEOMETRY) >= 64:
        GEOMETRY.clear()
    g = MeshGeometry(mesh)
    GEOMETRY[id(mesh)] = (mesh, g)
    return g


# -- components.clock_gear_train.ClockTrainPhysics --------------------------------------
cdef class _Clock:
    """One ClockTrainPhysics as C values: its constants and its mode."""

    cdef MeshGeometry g1, g2
    cdef double psi0, kappa2
    cdef double px[2]
    cdef double py[2]
    cdef double i1, i2, i3, a35, phi1c, theta1_0, mu
    cdef double pivot[3]
    cdef double rho[2][2]
    cdef double eta[2][2]
    cdef int loss_model
    # the mode
    cdef int direction
    cdef int k[2]
    cdef int ph[2]
    cdef int sg[2]
    cdef int sigma[2]
    cdef object pieces

    cdef int load_kinematics(self, object p) except -1:
        """What evaluate reads: the meshes, the phase offsets, the pieces."""
        m1, m2 = p.meshes
        self.g1, self.g2 = _geometry(m1), _geometry(m2)
        self.psi0, self.kappa2 = p.psi0, p.kappa2
        (self.px[0], self.py[0]), (self.px[1], self.py[1]) = p.pinion_pivot
        return self.load_pieces(p)

    cdef int load_pieces(self, object p) except -1:
        pieces = p.pieces
        self.pieces = pieces
        (k1, ph1, sg1), (k2, ph2, sg2) = pieces
        self.k[0], self.k[1] = k1, k2
        self.ph[0], self.ph[1] = PHASE[ph1], PHASE[ph2]
        self.sg[0], self.sg[1] = sg1, sg2
        return 0

    cdef int load_statics(self, object p) except -1:
        """What moments reads: the loss model and the friction mode."""
        self.loss_model, self.mu = p.loss_model, p.mu
        self.direction = p.direction
        self.sigma[0], self.sigma[1] = p.sigma
        (self.rho[0][0], self.rho[0][1]), (self.rho[1][0], self.rho[1][1]) = p.rho
        if self.loss_model == LOSS_CYCLE and p.eta_cycle is not None:
            (self.eta[0][0], self.eta[0][1]), (self.eta[1][0], self.eta[1][1]) = p.eta_cycle
        return 0

    cdef int load_bodies(self, object p) except -1:
        """What response, power_terms and forces read besides."""
        self.i1, self.i2, self.i3 = p.i1, p.i2, p.i3
        self.a35, self.phi1c, self.theta1_0 = p.a35, p.phi1c, p.theta1_0
        self.pivot[0], self.pivot[1], self.pivot[2] = p.pivot
        return 0

    cdef int load(self, object p) except -1:
        self.load_kinematics(p)
        self.load_statics(p)
        return self.load_bodies(p)

    cdef int evaluate(self, double phi, double* ev) except -1:
        """ClockTrainPhysics.evaluate: theta1, theta2, r1, r1', r2, r2', x1, x2, then
        statics1 (6) and statics2 (6)."""
        cdef double o1[3]
        cdef double o2[3]
        cdef MeshGeometry m1 = self.g1, m2 = self.g2
        cdef int k1 = self.k[0], k2 = self.k[1]
        cdef double psi = self.psi0 + phi
        cdef double x2 = m2.sign * psi - k2 * m2.pinion_pitch
        cdef double theta2, r2, r2p, x1, theta1
        m2.pair_inverse(x2, self.ph[1], o2)
        theta2 = m2.sign * (o2[0] - k2 * m2.gear_pitch) - self.kappa2
        r2, r2p = o2[1], m2.sign * o2[2]
        x1 = m1.sign * theta2 - k1 * m1.pinion_pitch
        m1.pair_inverse(x1, self.ph[0], o1)
        theta1 = m1.sign * (o1[0] - k1 * m1.gear_pitch)
        ev[0] = theta1
        ev[1] = theta2
        ev[2] = o1[1] * r2
        ev[3] = m1.sign * o1[2] * r2 * r2 + o1[1] * r2p
        ev[4] = r2
        ev[5] = r2p
        ev[6] = x1
        ev[7] = x2
        m1.statics(x1, o1[0], self.ph[0], o1[1], self.px[0], self.py[0], ev + 8)
        m2.statics(x2, o2[0], self.ph[1], o2[1], self.px[1], self.py[1], ev + 14)
        return 0

    cdef int moments(self, int i, double* st, double* o) except -1:
        """ClockTrainPhysics.moments: o = m_g, m_p, iq."""
        cdef int s
        cdef double iq, mg, mp
        if self.loss_model == LOSS_NONE or self.mu == 0.0:
            o[0], o[1], o[2] = st[0], st[1], st[5]
            return 0
        s = self.sigma[i] * self.direction
        if self.loss_model == LOSS_CYCLE:
            iq = self.eta[i][0 if s > 0 else 1] * st[5]
            o[0], o[1], o[2] = st[1] / iq, st[1], iq
            return 0
        mg = st[0] + s * self.mu * (self.sg[i] * st[2] + self.rho[i][0])
        mp = st[1] + s * self.mu * (self.sg[i] * st[3] + self.rho[i][1])
        o[0], o[1], o[2] = mg, mp, mp / mg
        return 0

    cdef int response(self, double* ev, double phi_dot, double* o) except -1:
        """ClockTrainPhysics.response from the kinematics ev: o = J_ref, T_ref."""
        cdef double m[3]
        cdef double iq1, iq2, p1, p2, p3, w2, m1, r1, r1p, r2, r2p
        r1, r1p, r2, r2p = ev[2], ev[3], ev[4], ev[5]
        self.moments(0, ev + 8, m)
        iq1 = m[2]
        self.moments(1, ev + 14, m)
        iq2 = m[2]
        p1 = self.direction * self.pivot[0]
        p2 = self.direction * self.pivot[1]
        p3 = self.direction * self.pivot[2]
        w2 = phi_dot * phi_dot
        m1 = -self.a35 * _sin(self.phi1c + ev[0] - self.theta1_0)
        o[0] = self.i3 + self.i2 * r2 * iq2 + self.i1 * r1 * iq1 * iq2
        o[1] = (
            iq1 * iq2 * (m1 - p1 - self.i1 * r1p * w2) + iq2 * (p2 - self.i2 * r2p * w2) - p3
        )
        return 0

    cdef int power_terms(self, double* ev, double* o) except -1:
        """ClockTrainPhysics.power_terms from the kinematics ev."""
        cdef double m1 = -self.a35 * _sin(self.phi1c + ev[0] - self.theta1_0)
        cdef double r1 = ev[2], r2 = ev[4]
        cdef double j0 = self.i3 + self.i2 * r2 * r2 + self.i1 * r1 * r1
        o[0] = m1 * r1
        o[1] = j0
        o[2] = self.i1 * r1 * ev[3] + self.i2 * r2 * ev[5]
        return 0

    cdef int forces(
        self, double* ev, double j, double t, double phi_dot, double phi_ddot, double* o
    ) except -1:
        """ClockTrainPhysics.forces from the response (j, t) and the kinematics ev."""
        cdef double a[3]
        cdef double b[3]
        cdef double t_esc = j * phi_ddot - t
        cdef double p2, p3, n1, n2, th2_dd
        self.moments(0, ev + 8, a)
        self.moments(1, ev + 14, b)
        p2, p3 = self.direction * self.pivot[1], self.direction * self.pivot[2]
        n2 = (t_esc - p3 - self.i3 * phi_ddot) / b[1]
        th2_dd = ev[4] * phi_ddot + ev[5] * phi_dot * phi_dot
        n1 = (self.i2 * th2_dd - n2 * b[0] - p2) / a[1]
        o[0], o[1] = n1, n2
        return 0

    cdef tuple ev_tuple(self, double* ev):
        return (
            ev[0], ev[1], ev[2], ev[3], ev[4], ev[5], ev[6], ev[7],
            (ev[8], ev[9], ev[10], ev[11], ev[12], ev[13]),
            (ev[14], ev[15], ev[16], ev[17], ev[18], ev[19]),
        )


cdef inline void _fill(double* out, object values, Py_ssize_t n) except *:
    cdef Py_ssize_t i
    for i in range(n):
        out[i] = values[i]


cdef _Clock _kinematics_of(object p):
    cdef _Clock c = _Clock.__new__(_Clock)
    c.load_kinematics(p)
    return c


# The physics' methods (assigned to ClockTrainPhysics by components.clock_gear_train): the
# same memos as the Python code, the arithmetic in C.
def evaluate(self, double phi):
    """ClockTrainPhysics.evaluate."""
    cdef double ev[N_EV]
    key = (phi, self.pieces)
    memo = self._memo
    if memo is not None and memo[0] == key:
        return memo[1]
    cdef _Clock c = _kinematics_of(self)
    c.evaluate(phi, ev)
    out = c.ev_tuple(ev)
    self._memo = (key, out)
    return out


def moments(self, int i, st):
    """ClockTrainPhysics.moments."""
    cdef double s[6]
    cdef double o[3]
    cdef _Clock c = _Clock.__new__(_Clock)
    _fill(s, st, 6)
    c.load_pieces(self)
    c.load_statics(self)
    c.moments(i, s, o)
    return o[0], o[1], o[2]


def response(self, double phi, double phi_dot):
    """ClockTrainPhysics.response."""
    cdef double ev[N_EV]
    cdef double o[2]
    key = (phi, phi_dot, (self.direction, self.pieces, self.sigma))
    memo = self._rmemo
    if memo is not None and memo[0] == key:
        return memo[1]
    _fill_ev(ev, evaluate(self, phi), True)
    cdef _Clock c = _Clock.__new__(_Clock)
    c.load_pieces(self)
    c.load_statics(self)
    c.load_bodies(self)
    c.response(ev, phi_dot, o)
    out = (o[0], o[1], 1.0)
    self._rmemo = (key, out)
    return out


def power_terms(self, double phi):
    """ClockTrainPhysics.power_terms."""
    cdef double ev[N_EV]
    cdef double o[3]
    _fill_ev(ev, evaluate(self, phi), False)
    cdef _Clock c = _Clock.__new__(_Clock)
    c.load_bodies(self)
    c.power_terms(ev, o)
    return o[0], o[1], o[2]


def forces(self, double phi, double phi_dot, double phi_ddot):
    """ClockTrainPhysics.forces."""
    cdef double ev[N_EV]
    cdef double o[2]
    j, t, _ = response(self, phi, phi_dot)
    _fill_ev(ev, evaluate(self, phi), True)
    cdef _Clock c = _Clock.__new__(_Clock)
    c.load_pieces(self)
    c.load_statics(self)
    c.load_bodies(self)
    c.forces(ev, j, t, phi_dot, phi_ddot, o)
    return o[0], o[1]


def piece_distances(self, double phi):
    """ClockTrainPhysics.piece_distances."""
    ev = evaluate(self, phi)
    (_, ph1, _), (_, ph2, _) = self.pieces
    lo1, hi1 = self.bounds[0][ph1]
    lo2, hi2 = self.bounds[1][ph2]
    cdef double x1 = ev[6], x2 = ev[7]
    return x1 - <double>lo1, <double>hi1 - x1, x2 - <double>lo2, <double>hi2 - x2


cdef int _fill_ev(double* ev, tuple t, bint statics) except -1:
    """The C form of evaluate's tuple (its statics too where asked)."""
    _fill(ev, t, 8)
    if statics:
        _fill(ev + 8, t[8], 6)
        _fill(ev + 14, t[9], 6)
    return 0


# -- the loop between events ---------------------------------------------------------------
# event_integration.advance for the clock train's model (bare, with its torque ramped or
# ending at its first event) and for the clock-train S&A's monolithic model: the steps, the
# error control, the event location, the re-step and the accept hooks run here on C arrays
# with the model's smooth parts (deriv, indicators) in C; the model's events, the instant's
# other events and an observer are the Python code's.  The mode is read from the Python
# objects at the start and after each call into Python, and what the loop changed (peaks,
# memos) is written back before each, so both see the same model.

cdef enum:
    MAX_IND = 16  # indicators: the train's model 7, the monolithic model 11

cdef dict CLASSES = dict.fromkeys((
    "physics", "model", "ramped_load", "until_first_event", "monolithic", "verge_budget_spent",
    "sampler",
))
cdef object COMPONENT_ERROR = RuntimeError
cdef object BUDGET_SPENT = RuntimeError  # event_integration.StepBudgetSpent
cdef object FIRE_AT_INSTANT = None
cdef object FIRST_STEP = None


def use_integration(component_error, budget_spent, fire_at_instant, first_step):
    """event_integration's errors and the helpers its compiled loop calls back."""
    global COMPONENT_ERROR, BUDGET_SPENT, FIRE_AT_INSTANT, FIRST_STEP
    COMPONENT_ERROR, BUDGET_SPENT = component_error, budget_spent
    FIRE_AT_INSTANT, FIRST_STEP = fire_at_instant, first_step


def use_classes(**classes):
    """The classes the compiled loop recognises (by role): physics (ClockTrainPhysics),
    model (_ClockModel), ramped_load, until_first_event, monolithic (the clock-train S&A's
    monolithic model), verge_budget_spent (the verge's StepBudgetSpent), sampler (the M739
    kernel's Sampler: the monolithic model's observer, whose samples this loop takes)."""
    CLASSES.update(classes)


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


cdef class _Loop:
    """event_integration.advance on C arrays for one model (a subclass gives its deriv,
    indicators, accept, and how its mode is read from and written back to Python)."""

    cdef object model
    cdef bint halted
    cdef Py_ssize_t n, n_ind

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

    cdef bint samples(self, object observe) except -1:
        """Whether the loop takes the observer's samples itself (``sample``)."""
        return False

    cdef int sample(
        self, object observe, double r[5][MAX_STATES], double t0, double h, double t1
    ) except -1:
        return 0

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

    cdef list pylist(self, double* y):
        return [y[i] for i in range(self.n)]

    cdef double locate(
        self, double r[5][MAX_STATES], double h, Py_ssize_t idx, double g_lo, double g_hi,
        double tol_t, double* y_hi,
    ) except? -2.0:
        """event_integration._locate: the offset, the state into y_hi."""
        cdef double lo = 0.0, hi = 1.0, tol = tol_t / h, th, gt, s1
        cdef double yt[MAX_STATES]
        cdef double g[MAX_IND]
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
        cdef double G0[MAX_IND]
        cdef double G1[MAX_IND]
        cdef double GT[MAX_IND]
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
        sampled = self.samples(observe)
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
                if sampled:
                    self.sample(observe, dense.r, t, h_step, t + th_best)
                elif observe is not None:
                    dense.t0, dense.h = t, h_step
                    self.store()
                    observe(t, t + th_best, dense)
                    self.load()
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
                    last = recent[max(0, len(recent) - 20):]
                    which = ", ".join(str(i) for i in sorted(set(last)))
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


cdef class _ClockRun(_Loop):
    """The clock train's model (_ClockModel with a held escapement load), bare, with its
    torque ramped over the step (train_component.RampedLoad) or ending at its first event."""

    cdef object train_model, phys
    cdef _Clock c
    cdef bint stuck, ramped, point_branches
    cdef double t_esc, j_esc, rate
    cdef double peaks[4]
    # the physics' memos as the Python calls would leave them: the last kinematics and
    # response asked for (their phi, phi_dot)
    cdef bint ev_asked, r_asked
    cdef double ev_phi, r_phi, r_w

    cdef int setup(self, object model, object train_model, object ramp) except -1:
        self.model, self.train_model, self.phys = model, train_model, train_model.p
        self.ramped = ramp is not None
        self.rate = ramp.rate if self.ramped else 0.0
        self.n = 4 if self.ramped else 3
        self.n_ind = N_IND
        self.c = _Clock.__new__(_Clock)
        self.load()
        return 0

    cdef int load(self) except -1:
        """The mode, as the Python code left it."""
        m, p = self.train_model, self.phys
        self.c.load(p)
        self.point_branches = self.c.loss_model == LOSS_POINT and self.c.mu != 0.0
        self.stuck = m.stuck
        self.t_esc, self.j_esc = m.t_esc, m.j_esc
        self.peaks[0], self.peaks[1], self.peaks[2], self.peaks[3] = m.peaks
        self.halted = bool(getattr(self.model, "halted", False))
        self.ev_asked = self.r_asked = False
        return 0

    cdef int store(self) except -1:
        """What the loop changed, for the Python code: the peaks, the held torque and the
        physics' memos."""
        cdef double ev[N_EV]
        cdef double o[2]
        m, p, c = self.train_model, self.phys, self.c
        m.peaks = (self.peaks[0], self.peaks[1], self.peaks[2], self.peaks[3])
        m.t_esc = self.t_esc
        if self.ev_asked:
            c.evaluate(self.ev_phi, ev)
            p._memo = ((self.ev_phi, c.pieces), c.ev_tuple(ev))
            self.ev_asked = False
        if self.r_asked:
            c.evaluate(self.r_phi, ev)
            c.response(ev, self.r_w, o)
            key = (self.r_phi, self.r_w, (p.direction, c.pieces, p.sigma))
            p._rmemo = (key, (o[0], o[1], 1.0))
            self.r_asked = False
        return 0

    cdef inline double accel(
        self, double* ev, double phi, double phi_dot, double* r
    ) except? -2.0:
        """TrainLoadModel.accel (c_load = 1) on the kinematics ev at phi; the response
        (J_ref, T_ref) into r."""
        self.c.response(ev, phi_dot, r)
        self.r_asked, self.r_phi, self.r_w = True, phi, phi_dot
        return (r[1] + 1.0 * self.t_esc) / (r[0] + 1.0 * self.j_esc)

    cdef int deriv(self, double* y, double* out) except -1:
        """_ClockModel.deriv."""
        cdef double ev[N_EV]
        cdef double pt[3]
        cdef double r[2]
        cdef double a, phi = y[0], w = y[1]
        if self.ramped:
            self.t_esc = y[3]  # RampedLoad.enter
            out[3] = self.rate
        if self.stuck:
            out[0] = out[1] = out[2] = 0.0
            return 0
        self.c.evaluate(phi, ev)
        self.ev_asked, self.ev_phi = True, phi
        a = self.accel(ev, phi, w, r)
        self.c.power_terms(ev, pt)
        out[0] = w
        out[1] = a
        out[2] = w * ((self.t_esc - self.j_esc * a) + pt[0] - pt[1] * a - pt[2] * w * w)
        return 0

    cdef int indicators(self, double* y, double* g) except -1:
        """_ClockModel.indicators."""
        cdef double ev[N_EV]
        cdef double f[2]
        cdef double r[2]
        cdef double phi = y[0], w, a
        cdef MeshGeometry m1 = self.c.g1, m2 = self.c.g2
        cdef int ph1 = self.c.ph[0], ph2 = self.c.ph[1]
        if self.ramped:
            self.t_esc = y[3]
        self.c.evaluate(phi, ev)
        self.ev_asked, self.ev_phi = True, phi
        if self.c.direction > 0:
            g[0], g[1] = ev[6] - m1.lo[ph1], ev[7] - m2.lo[ph2]
        else:
            g[0], g[1] = m1.hi[ph1] - ev[6], m2.hi[ph2] - ev[7]
        if self.point_branches:
            g[2], g[3] = self.c.sg[0] * ev[12], self.c.sg[1] * ev[18]
        else:
            g[2] = g[3] = 1.0
        if self.stuck:
            g[4] = g[5] = g[6] = 0.0
            return 0
        w = y[1]
        g[4] = self.c.direction * w
        a = self.accel(ev, phi, w, r)
        if self.c.loss_model == LOSS_NONE or self.c.mu == 0.0:
            g[5] = g[6] = 1.0
            return 0
        self.c.forces(ev, r[0], r[1], w, a, f)
        g[5], g[6] = self.c.sigma[0] * f[0], self.c.sigma[1] * f[1]
        return 0

    cdef int accept(self, double* y, double t) except -1:
        """TrainLoadModel.accept: the mesh-force peaks."""
        cdef double ev[N_EV]
        cdef double f[2]
        cdef double r[2]
        cdef double a, f12, f23
        if self.ramped:
            self.t_esc = y[3]
        if self.stuck:
            return 0
        self.c.evaluate(y[0], ev)
        self.ev_asked, self.ev_phi = True, y[0]
        a = self.accel(ev, y[0], y[1], r)
        self.c.forces(ev, r[0], r[1], y[1], a, f)
        f12, f23 = f[0], f[1]
        if self.t_esc != 0.0 or self.j_esc != 0.0:
            if f12 > self.peaks[0] or f23 > self.peaks[1]:
                self.peaks[0] = f12 if f12 > self.peaks[0] else self.peaks[0]
                self.peaks[1] = f23 if f23 > self.peaks[1] else self.peaks[1]
        elif f12 > self.peaks[2] or f23 > self.peaks[3]:
            self.peaks[2] = f12 if f12 > self.peaks[2] else self.peaks[2]
            self.peaks[3] = f23 if f23 > self.peaks[3] else self.peaks[3]
        return 0


# -- the monolithic model: the M739 verge (components.verge_escapement.VergeCore, as the
# M739 kernel compiles it) on the live clock train --------------------------------------
cdef inline int _fidx(int face):
    return 1 if face == 1 else 0


cdef int _kinem_c(
    double phi, double alpha, double a, double b, double c, double* o
) except -1:
    """verge_geometry.kinem into o: psi, g, u, v, a1p, b1p, d1p."""
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


cdef inline double _min4(double a, double b, double c, double d):
    """Python's min(a, b, c, d): the first of the least (a NaN first stays)."""
    if b < a:
        a = b
    if c < a:
        a = c
    if d < a:
        a = d
    return a


cdef class _MonoRun(_Loop):
    """The clock-train S&A's monolithic model (orchestrator.scenes.clock_train.monolithic):
    VergeTrainMonolithic's deriv, indicators and accept with the live clock train.  The
    Python objects remember their last points (the verge its coupled terms, the train its
    kinematics and response; the train's normal-force signs read its last position): the
    loop keeps those memos as the Python calls would and writes them back."""

    cdef object core, phys
    cdef _Clock c
    cdef bint point_branches, no_branches
    # VergeConstants
    cdef double ka, kb, kc, mu1, mu_abs, om2, om_abs, beta3, gamma_pp, dn1, ip, a54
    cdef double rho3, rho_p, rcp, mp, r4, phi_stop
    cdef double alpha[2]
    cdef double c1[2]
    # VergeCore's mode
    cdef int face, s4, s5, ipr_sign
    cdef bint coupled, train_stuck, verge_stuck, has_budget
    cdef long long budget
    cdef double phi_off, psic
    # the raised contact indicator and the force maxima
    cdef bint has_shift
    cdef int shift_face
    cdef double shift_phi_off, shift
    cdef double f23_max, f12_max, ff23_max, ff12_max, pn_max
    # the memos: the train's kinematics (key phi), response (phi, phi_dot), the verge's
    # coupled terms (y0, y1); valid: for the mode in force; dirty: changed since load
    cdef bint ev_valid, ev_dirty, r_valid, r_dirty, ct_valid, ct_dirty
    cdef double ev_phi, r_phi, r_w, ct_y0, ct_y1
    cdef double ev_vals[N_EV]
    cdef double r_vals[2]
    cdef double ct_vals[13]

    cdef int setup(self, object core) except -1:
        self.model, self.core, self.phys = core, core, core.train
        self.n, self.n_ind = 5, 11
        self.c = _Clock.__new__(_Clock)
        k = core.k
        d = k.d
        self.ka, self.kb, self.kc = k.a, k.b, k.c
        self.mu1, self.mu_abs = k.mu1, k.mu_abs
        self.om2, self.om_abs = k.om2, k.om_abs
        self.beta3, self.gamma_pp, self.dn1 = k.beta3, k.gamma_pp, k.dn1
        self.ip, self.a54 = k.ip, k.a54
        self.rho3, self.rho_p, self.rcp, self.mp, self.r4 = d.rho3, d.rho_p, d.rcp, d.mp, d.r4
        self.alpha[1], self.alpha[0] = k.alpha.get(1), k.alpha.get(-1)
        self.c1[1], self.c1[0] = k.c1.get(1), k.c1.get(-1)
        self.phi_stop = core.phi_stop
        self.load()
        return 0

    cdef int load(self) except -1:
        """The mode and the memos, as the Python code left them."""
        core, p, c = self.core, self.phys, self.c
        c.load(p)
        self.point_branches = c.loss_model == LOSS_POINT and c.mu != 0.0
        self.no_branches = c.loss_model == LOSS_NONE or c.mu == 0.0
        self.face, self.s4, self.s5, self.ipr_sign = core.face, core.s4, core.s5, core.ipr_sign
        self.coupled, self.train_stuck = core.coupled, core.train_stuck
        self.verge_stuck = core.verge_stuck
        self.phi_off, self.psic = core.phi_off, core.psic
        budget = core.budget
        self.has_budget = budget is not None
        if self.has_budget:
            self.budget = budget
        shift = core.gap_shift
        self.has_shift = shift is not None
        if self.has_shift:
            self.shift_face, self.shift_phi_off, self.shift = shift
        self.f23_max, self.f12_max, self.pn_max = core.f23_max, core.f12_max, core.pn_max
        self.ff23_max, self.ff12_max = core.ff23_max, core.ff12_max
        self.halted = bool(core.halted)
        memo = p._memo
        self.ev_valid = memo is not None and memo[0][1] == c.pieces
        if self.ev_valid:
            self.ev_phi = memo[0][0]
            _fill_ev(self.ev_vals, memo[1], True)
        memo = p._rmemo
        self.r_valid = memo is not None and memo[0][2] == p.mode_key()
        if self.r_valid:
            self.r_phi, self.r_w = memo[0][0], memo[0][1]
            self.r_vals[0], self.r_vals[1] = memo[1][0], memo[1][1]
        memo = core.__dict__.get("_memo")
        self.ct_valid = memo is not None and memo[0][2] == core._mode_key()
        if self.ct_valid:
            self.ct_y0, self.ct_y1 = memo[0][0], memo[0][1]
            _fill(self.ct_vals, memo[1], 13)
        self.ev_dirty = self.r_dirty = self.ct_dirty = False
        return 0

    cdef int store(self) except -1:
        """What the loop changed, for the Python code."""
        core, p = self.core, self.phys
        core.budget = self.budget if self.has_budget else None
        core.f23_max, core.f12_max, core.pn_max = self.f23_max, self.f12_max, self.pn_max
        core.ff23_max, core.ff12_max = self.ff23_max, self.ff12_max
        if self.ev_dirty:
            p._memo = ((self.ev_phi, self.c.pieces), self.c.ev_tuple(self.ev_vals))
            self.ev_dirty = False
        if self.r_dirty:
            p._rmemo = ((self.r_phi, self.r_w, p.mode_key()), (self.r_vals[0], self.r_vals[1], 1.0))
            self.r_dirty = False
        if self.ct_dirty:
            core._memo = (
                (self.ct_y0, self.ct_y1, core._mode_key()),
                tuple([self.ct_vals[i] for i in range(13)]),
            )
            self.ct_dirty = False
        return 0

    # -- the train's memoised calls ---------------------------------------------------
    cdef double* evl(self, double phi) except NULL:
        """ClockTrainPhysics.evaluate(phi)."""
        cdef double ev[N_EV]
        cdef Py_ssize_t i
        if not (self.ev_valid and self.ev_phi == phi):
            self.c.evaluate(phi, ev)
            for i in range(N_EV):
                self.ev_vals[i] = ev[i]
            self.ev_valid, self.ev_phi, self.ev_dirty = True, phi, True
        return self.ev_vals

    cdef int resp(self, double phi, double w, double* o) except -1:
        """ClockTrainPhysics.response(phi, w): J_ref, T_ref."""
        cdef double r[2]
        if not (self.r_valid and self.r_phi == phi and self.r_w == w):
            self.c.response(self.evl(phi), w, r)
            self.r_vals[0], self.r_vals[1] = r[0], r[1]
            self.r_valid, self.r_phi, self.r_w, self.r_dirty = True, phi, w, True
        o[0], o[1] = self.r_vals[0], self.r_vals[1]
        return 0

    cdef int forces(self, double phi, double w, double a, double* o) except -1:
        """ClockTrainPhysics.forces(phi, w, a): N1, N2."""
        cdef double r[2]
        self.resp(phi, w, r)
        self.c.forces(self.evl(phi), r[0], r[1], w, a, o)
        return 0

    cdef int mesh_indicators(self, double phi, double* o) except -1:
        """ClockTrainPhysics.mesh_indicators(phi): ahead forward, ahead backward."""
        cdef double* ev = self.evl(phi)
        cdef MeshGeometry m1 = self.c.g1, m2 = self.c.g2
        cdef int ph1 = self.c.ph[0], ph2 = self.c.ph[1]
        cdef double a1 = ev[6] - m1.lo[ph1], b1 = m1.hi[ph1] - ev[6]
        cdef double a2 = ev[7] - m2.lo[ph2], b2 = m2.hi[ph2] - ev[7]
        cdef double s1 = self.c.sg[0] * ev[12], s2 = self.c.sg[1] * ev[18]
        if not self.point_branches:
            s1 = s2 = INFINITY
        o[0] = _min4(a1, a2, s1, s2)
        o[1] = _min4(b1, b2, s1, s2)
        return 0

    # -- the verge ----------------------------------------------------------------------
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

    cdef int coupled_terms(self, double y0, double w, double* out) except -1:
        """VergeCore.coupled_terms (its memo) into out[0:13]."""
        cdef double o[13]
        cdef double kn[7]
        cdef double pv[3]
        cdef double tr[2]
        cdef int face = self.face, fi = _fidx(face)
        cdef double phi_l, alpha, psi, g, u, v, a1p, b1p, d1p, a19, a20, a21, a17, a18, ipr
        cdef double j, t, c, a52, cent, psi_d, n, den, acc, psi_dd, pn, vst
        cdef int s4 = self.s4, s5 = self.s5
        cdef double mu1, mu, spa, cpa, chi, sc, cc, dn, c1p, a1, a5, a9, a12
        cdef Py_ssize_t i
        if self.ct_valid and self.ct_y0 == y0 and self.ct_y1 == w:
            for i in range(13):
                out[i] = self.ct_vals[i]
            return 0
        phi_l = y0 + self.phi_off
        alpha = self.alpha[fi]
        _kinem_c(phi_l, alpha, self.ka, self.kb, self.kc, kn)
        psi, g, u, v, a1p, b1p, d1p = kn[0], kn[1], kn[2], kn[3], kn[4], kn[5], kn[6]
        self.pivot(s5, psi + self.psic, pv)
        a19, a20 = pv[0], pv[1]
        a21 = s5 * a20
        # contact_coefficients
        mu1 = self.mu1
        mu = self.mu_abs * self.c.direction
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
        self.resp(y0, w, tr)
        j, t, c = tr[0], tr[1], 1.0
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
        vst = -(w * self.kb * _sin(phi_l - psi - alpha) + psi_d * self.kc * _sin(alpha))
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
        for i in range(13):
            self.ct_vals[i] = o[i]
            out[i] = o[i]
        self.ct_valid, self.ct_y0, self.ct_y1, self.ct_dirty = True, y0, w, True
        return 0

    cdef int free_terms(self, double* y, double* o) except -1:
        """VergeCore.free_terms: phi_dd, psi_dd, cent."""
        cdef double pv[3]
        cdef double tr[2]
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
            self.resp(y[0], y[1], tr)
            o[0] = tr[1] / tr[0]
        o[1] = psi_dd
        o[2] = cent
        return 0

    cdef int deriv(self, double* y, double* out) except -1:
        """VergeCore.deriv."""
        cdef double o[13]
        cdef double w = y[1]
        if self.coupled:
            self.coupled_terms(y[0], w, o)
            out[0] = w
            out[1] = o[0]
            out[2] = o[2]
            out[3] = o[3]
            out[4] = -o[5] * w - self.ip * o[2] * o[3] + o[10] * o[2]
        else:
            self.free_terms(y, o)
            out[0] = w
            out[1] = o[0]
            out[2] = y[3]
            out[3] = o[1]
            out[4] = -self.ip * y[3] * o[1] + o[2] * y[3]
        return 0

    cdef int indicators(self, double* y, double* g) except -1:
        """VergeTrainMonolithic.indicators: VergeCore's with the clock train's mesh and
        branch indicators, the contact indicator raised where it was armed."""
        cdef double o[13]
        cdef double d[5]
        cdef double mi[2]
        cdef double f[2]
        cdef int sigma = self.face, fi = _fidx(sigma)
        cdef double wheel, stop, phi_l, psi, alpha, arg, ff, gp
        if self.has_budget:
            self.budget -= 1
            if self.budget < 0:
                raise CLASSES["verge_budget_spent"]("internal step budget spent")
        self.mesh_indicators(y[0], mi)
        wheel = 1.0 if self.train_stuck else self.c.direction * y[1]
        stop = self.phi_stop - y[0]
        if self.coupled:
            self.coupled_terms(y[0], y[1], o)
            g[0] = sigma * o[6]
            g[1] = o[4]
            g[2] = self.s4 * o[8]
            g[3] = self.s5 * o[2]
        else:
            phi_l = y[0] + self.phi_off
            psi = y[2]
            alpha = self.alpha[fi]
            arg = phi_l - psi - alpha
            ff = self.ka * _sin(psi + alpha) - self.kb * _sin(arg) - self.kc * _sin(alpha)
            gp = self.ka * _cos(psi + alpha) + self.kb * _cos(arg) - self.kc * _cos(alpha)
            g[0] = sigma * gp
            g[1] = sigma * ff
            g[2] = 1.0
            g[3] = 1.0 if self.verge_stuck else self.s5 * y[3]
        g[4] = wheel
        g[5] = mi[0]
        g[6] = mi[1]
        g[7] = stop
        # _branch_indicators
        self.deriv(y, d)
        g[8] = self.ipr_sign * self.s5 * d[3]
        if self.no_branches:
            g[9] = g[10] = 1.0
        else:
            self.forces(y[0], y[1], d[1], f)
            g[9], g[10] = self.c.sigma[0] * f[0], self.c.sigma[1] * f[1]
        if (
            self.has_shift and not self.coupled and self.shift_face == self.face
            and self.shift_phi_off == self.phi_off
        ):
            g[1] = g[1] + self.shift
        return 0

    cdef bint samples(self, object observe) except -1:
        return (
            observe is not None
            and type(observe) is CLASSES["sampler"]
            and observe.core is self.core
        )

    cdef int sample(
        self, object sampler, double r[5][MAX_STATES], double t0, double h, double t1
    ) except -1:
        """The monolithic model's observer (orchestrator.scenes.m739.monolithic.simulate):
        the samples every sample_dt on the dense output of the step, each with the forces."""
        cdef double y[MAX_STATES]
        cdef double o[13]
        cdef double f[2]
        cdef double t_base = self.core.t_base, dt = sampler.dt, psic0 = sampler.psic0
        cdef double t_abs, th, s1, body, acc, pn
        count = sampler.count
        cdef long k = count[0]
        cdef Py_ssize_t i
        cdef int regime
        cols = sampler.columns
        while k * dt - t_base <= t1:
            t_abs = k * dt
            th = ((t_abs - t_base) - t0) / h
            s1 = 1.0 - th
            for i in range(self.n):
                y[i] = r[0][i] + th * (r[1][i] + s1 * (r[2][i] + th * (r[3][i] + s1 * r[4][i])))
            body = y[2] + self.psic - psic0
            regime = 0 if not self.coupled else (1 if self.face == 1 else 2)
            if self.coupled:
                self.coupled_terms(y[0], y[1], o)
                acc, pn = o[0], o[4]
            else:
                self.free_terms(y, o)
                acc, pn = o[0], 0.0
            self.forces(y[0], y[1], acc, f)
            cols[0].append(t_abs)
            cols[1].append(y[0])
            cols[2].append(y[1])
            cols[3].append(atan2(_sin(body), _cos(body)))
            cols[4].append(y[3])
            cols[5].append(regime)
            cols[6].append(f[0])
            cols[7].append(f[1])
            cols[8].append(pn)
            k += 1
            count[0] = k
        return 0

    cdef int accept(self, double* y, double t) except -1:
        """VergeTrainMonolithic.record: the force maxima (a self-locking point goes to the
        Python code, which halts)."""
        cdef double o[13]
        cdef double r[2]
        cdef double f[2]
        cdef double pn, acc, f12, f23
        if self.coupled:
            self.coupled_terms(y[0], y[1], o)
            acc, pn = o[0], o[4]
            self.resp(y[0], y[1], r)
            if o[9] <= 0.0 or r[0] <= 0.0:
                self.store()
                self.core.accept([y[i] for i in range(self.n)], t)
                self.load()
                return 0
            self.forces(y[0], y[1], acc, f)
            f12, f23 = f[0], f[1]
            self.f23_max = f23 if f23 > self.f23_max else self.f23_max
            self.f12_max = f12 if f12 > self.f12_max else self.f12_max
            self.pn_max = pn if pn > self.pn_max else self.pn_max
        else:
            self.free_terms(y, o)
            self.forces(y[0], y[1], o[0], f)
            f12, f23 = f[0], f[1]
            self.ff23_max = f23 if f23 > self.ff23_max else self.ff23_max
            self.ff12_max = f12 if f12 > self.ff12_max else self.ff12_max
        return 0


def advance(model, y, double h_total, control, double h_try, double tol_t, long max_events,
            observe):
    """event_integration.advance compiled for the clock train's model and the clock-train
    S&A's monolithic model; None for any other model (another loop, or the Python one,
    runs it)."""
    cdef _ClockRun run
    cdef _MonoRun mono
    if len(control.scales) > len(y):
        return None
    if type(model) is CLASSES["monolithic"] and type(model.train) is CLASSES["physics"]:
        if len(y) != 5:
            return None
        mono = _MonoRun()
        mono.setup(model)
        return mono.run(list(y), h_total, control, h_try, tol_t, max_events, observe)
    if CLASSES["model"] is None:
        return None
    inner = model
    if type(inner) is CLASSES["until_first_event"]:
        inner = inner.model
    ramp = None
    if type(inner) is CLASSES["ramped_load"]:
        ramp, inner = inner, inner.model
        if ramp.n != 3:
            return None
    if type(inner) is not CLASSES["model"] or type(inner.p) is not CLASSES["physics"]:
        return None
    if len(y) != (4 if ramp is not None else 3):
        return None
    run = _ClockRun()
    run.setup(model, inner, ramp)
    return run.run(list(y), h_total, control, h_try, tol_t, max_events, observe)
