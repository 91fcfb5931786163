"""Unit factors of the source documents' US customary units, and spin-rate conversions.

Every component works in SI; these convert the sources' inch, pound-force and rev/min data
once, where the data are defined.  The inch and the pound-force are exact by definition
(1 in = 0.0254 m; 1 lbf = 4.4482216152605 N).
"""

from __future__ import annotations

import math

INCH = 0.0254  # m per in
LBF = 4.4482216152605  # N per lbf
LBF_IN = LBF * INCH  # N.m per lbf.in (torque; also inertia lbf.in.s^2 -> kg.m^2)
LB_PER_IN = LBF / INCH  # N/m per lbf/in (stiffness; also mass lbf.s^2/in -> kg)
PSI = LBF / INCH**2  # Pa per lbf/in^2
DEG = math.pi / 180.0  # rad per degree
RPM = 2.0 * math.pi / 60.0  # rad/s per rev/min
RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)  # rev/min per rad/s


def rpm_to_rad_s(rpm: float) -> float:
    """Spin rate in rev/min to rad/s."""
    return rpm * 2.0 * math.pi / 60.0
