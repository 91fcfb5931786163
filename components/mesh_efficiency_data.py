"""Mesh data of Tepper (1981), ARLCD-TR-81020: Tables 1-22 (pp. 17-38) and Appendix E (p. 83).

The report gives every length in inches; they are converted to metres here, once.  Outside radii
are entered as the exact fractions (N + 2)/(2 Pd) that the 5-digit printed values round (derived
here: every tabulated outside radius is (N + 2)/(2 Pd) to 5 digits, and Table 19's ALFIN
reproduces only with the exact pinion radius).  Pressure angles are in radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .units import INCH


@dataclass(frozen=True)
class InvoluteMesh:
    """One involute mesh (Tables 5–13) and how its published run was made (Tables 14–22)."""

    table: int  # input table of the report
    output_table: int  # table of the printed program output
    name: str
    diametral_pitch: float  # 1/in, as in the source (enters only the cutter addendum)
    n_pinion: int
    gear_pitch_radius: float  # m
    pinion_pitch_radius: float  # m
    gear_outside_radius: float  # m
    pinion_outside_radius: float  # m
    gear_pivot_radius: float  # m
    pinion_pivot_radius: float  # m
    center_distance: float  # m
    driver: str  # "pinion" (program ISAD1) or "gear" (ISAD2), as the published run
    pressure_angle: float = math.radians(20.0)  # rad, standard (cutter)
    hob_tip_radius: float = 0.0  # m


def _mesh(table, out, name, pd, np_, rg, rp, rog, rop, pg, pp, cd, driver) -> InvoluteMesh:
    i = INCH
    return InvoluteMesh(table, out, name, pd, np_, rg * i, rp * i, rog * i, rop * i, pg * i,
                        pp * i, cd * i, driver)  # fmt: skip


# Tables 5–13 (inputs, inches) with the driver of the published runs (Tables 14–22).  Table 6
# marks the gear as driver, but the published run (Table 15, App. E) used ISAD1: pinion drives.
INVOLUTE_MESHES: dict[int, InvoluteMesh] = {
    m.table: m
    for m in (
        _mesh(5, 14, "drive plate & valve lock cam", 64.0, 64, 0.625, 0.5, 82 / 128, 66 / 128,
              0.062, 0.062, 1.128, "gear"),
        _mesh(6, 15, "drive arm pinion gear & main shaft", 80.0, 16, 0.45, 0.1, 0.4625, 0.1125,
              0.125, 0.090, 0.551, "pinion"),
        _mesh(7, 16, "differential gear & motor pinion", 80.0, 14, 0.25, 0.0875, 0.2625, 0.1,
              0.062, 0.062, 0.338, "pinion"),
        _mesh(9, 17, "differential pinion mesh", 80.0, 15, 0.09375, 0.09375, 0.10625, 0.10625,
              0.020, 0.020, 0.1875, "gear"),
        _mesh(8, 18, "differential gear & differential pinion", 80.0, 15, 0.25, 0.09375,
              0.2625, 0.10625, 0.062, 0.020, 0.3453, "pinion"),
        _mesh(10, 19, "idler gear & differential output pinion", 64.0, 14, 0.1875, 7 / 64,
              26 / 128, 0.125, 0.062, 0.062, 0.3005, "pinion"),
        _mesh(11, 20, "valve drive gear & idler pinion", 64.0, 24, 25 / 64, 0.1875, 0.40625,
              26 / 128, 0.094, 0.062, 0.5818, "pinion"),
        _mesh(12, 21, "output gear & valve drive pinion", 48.0, 12, 0.375, 0.125, 38 / 96,
              14 / 96, 0.125, 0.094, 0.5046, "pinion"),
        _mesh(13, 22, "valve gear & output pinion", 32.0, 12, 0.5625, 0.1875, 0.59375, 0.21875,
              0.125, 0.125, 0.751, "gear"),
    )
}  # fmt: skip


@dataclass(frozen=True)
class PrintedRun:
    """Printed output of a published run (Tables 14–22), inches and degrees as printed."""

    rf_in: float
    undercut: bool
    op_pressure_deg: float
    contact_ratio: float
    alin_deg: float
    alfin_deg: float


PRINTED_RUNS: dict[int, PrintedRun] = {
    5: PrintedRun(0.4826, False, 20.41, 1.62, 17.663, 20.462),
    6: PrintedRun(0.0942, True, 20.28, 1.49, 4.132, 13.948),
    7: PrintedRun(0.0826, True, 20.23, 1.32, 5.743, 14.955),
    9: PrintedRun(0.0884, True, 20.00, 1.41, 3.077, 12.812),
    8: PrintedRun(0.0884, True, 20.71, 1.41, 4.896, 14.461),
    10: PrintedRun(0.1032, True, 21.82, 1.31, 5.919, 13.946),
    11: PrintedRun(0.1762, False, 20.97, 1.45, 11.108, 17.868),
    12: PrintedRun(0.1184, True, 21.39, 1.17, 7.086, 12.461),
    13: PrintedRun(0.1774, True, 20.21, 1.18, 14.068, 15.866),
}

#: Runs whose printed ALFIN (Tables 15, 16, 18, 21, pp. 31-37) disagrees with eq. 20 + 23, as
#: recomputed here (ISAD1 form-radius branch); keyed by input table.
ALFIN_ANOMALY_TABLES = (6, 7, 8, 12)


@dataclass(frozen=True)
class ClockMeshData:
    """Clock (constant-curvature tooth) mesh, Tables 1–4; the gear drives in all four."""

    table: int
    name: str
    n_gear: int
    n_pinion: int
    gear_pitch_radius: float  # m
    pinion_pitch_radius: float  # m
    gear_center_distance: float  # m, pivot to centre of curvature a_G
    pinion_center_distance: float  # m, a_P
    gear_arc_radius: float  # m, rho_G
    pinion_arc_radius: float  # m, rho_P
    gear_tooth_thickness: float  # m, at the pitch circle
    pinion_tooth_thickness: float  # m
    gear_pivot_radius: float  # m
    pinion_pivot_radius: float  # m


def _clock(table, name, ng, np_, rg, rp, ag, ap, qg, qp, tg, tp, pg, pp) -> ClockMeshData:
    i = INCH
    return ClockMeshData(table, name, ng, np_, rg * i, rp * i, ag * i, ap * i, qg * i, qp * i,
                     tg * i, tp * i, pg * i, pp * i)  # fmt: skip


CLOCK_MESHES: dict[int, ClockMeshData] = {
    m.table: m
    for m in (
        _clock(1, "propulsion timer gear & pinion", 72, 18, 0.360, 0.090, 0.3577, 0.09012,
               0.0223, 0.008, 0.014, 0.012, 0.06237, 0.0155),
        _clock(2, "gear no. 1 & pinion no. 1", 55, 8, 0.20385, 0.02965, 0.20392, 0.02974,
               0.011, 0.007, 0.011, 0.0093, 0.0155, 0.01025),
        _clock(3, "50-tooth gear & escape wheel pinion", 50, 7, 0.18535, 0.02595, 0.18543,
               0.0245, 0.011, 0.007, 0.011, 0.009, 0.01025, 0.0085),
        _clock(4, "exoatmospheric timer gear & pinion", 112, 18, 0.560, 0.090, 0.55791,
               0.09012, 0.0223, 0.008, 0.014, 0.012, 0.078, 0.0155),
    )
}  # fmt: skip

#: Appendix E (Table 15 mesh, pinion drives), POINTEF printed per driver angle [deg] and mu.
#: None = lost in the OCR.  The dual-contact rows 4.13–13.13 share one value per mu.
APPENDIX_E_MU = (0.025, 0.05, 0.075, 0.1, 0.125, 0.15, 0.175, 0.2, 0.225, 0.25, 0.275, 0.3)
APPENDIX_E_DUAL = (.9637, .9295, .8972, .8666, .8378, None, .7849, .7606, .7377, .7160, .6955,
                   .6761)  # fmt: skip
APPENDIX_E_SINGLE = {
    14.03: (.9655, .9321, .8999, .8688, .8387, None, .7813, .7540, .7275, .7018, .6768, .6526),
    14.93: (.9659, .9330, .9012, .8704, .8406, None, .7838, .7567, .7304, .7049, .6801, .6560),
    15.83: (.9664, .9339, .9025, .8720, .8425, None, .7862, .7594, .7333, .7080, .6834, .6595),
    16.73: (.9669, .9348, .9037, .8736, .8445, None, .7887, .7621, .7362, .7111, .6867, .6629),
    17.63: (.9673, .9357, .9050, .8752, .8464, None, .7912, .7648, .7392, .7143, .6900, .6664),
    18.53: (.9678, .9365, .9062, .8769, None, None, .7937, .7676, .7422, .7174, .6934, .6699),
    19.43: (.9682, .9374, .9075, .8785, None, None, .7962, .7703, .7451, .7206, .6967, .6735),
    20.33: (.9687, .9383, .9088, .8801, None, None, .7988, .7731, .7482, .7238, .7002, .6771),
    21.23: (.9696, .9412, .9144, .8893, None, None, .8219, .8018, .7827, .7646, .7474, .7309),
    22.13: (.9692, .9403, .9132, .8877, None, None, .8196, .7993, .7800, .7617, .7443, .7277),
    23.03: (.9687, .9395, .9120, .8862, None, None, .8173, .7967, .7773, .7588, .7413, .7245),
    23.93: (.9683, .9386, .9108, .8847, None, None, .8150, .7942, .7746, .7559, .7382, .7214),
    24.83: (.9678, .9378, .9096, .8831, None, None, .8127, .7917, .7719, .7531, .7352, .7183),
    25.73: (.9674, .9369, .9084, .8816, None, None, .8104, .7892, .7692, .7503, .7323, .7151),
}  # fmt: skip
APPENDIX_E_CYCLE = (.9660, .9336, .9029, .8736, None, None, .7940, .7699, .7469, .7249, .7039,
                    .6837)  # fmt: skip
APPENDIX_E_MIN = (.9637, .9295, .8972, .8666, .8378, None, .7813, .7540, .7275, .7018, .6768,
                  .6526)  # fmt: skip
#: The end of dual contact the 1981 run actually used for this mesh [deg] (Table 15, p. 31; the
#: App. E point at 14.03 deg is already single contact).
APPENDIX_E_ALFIN_DEG = 13.948
