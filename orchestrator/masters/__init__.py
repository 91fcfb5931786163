"""Master algorithms.  Each takes (system, scene, recorder, stats, progress) and runs the scene."""

from __future__ import annotations

from orchestrator.masters.fixed_step import run_gauss_seidel, run_jacobi
from orchestrator.masters.regime_aware import run_regime_aware

MASTERS = {
    "jacobi": run_jacobi,
    "gauss-seidel": run_gauss_seidel,
    "regime-aware": run_regime_aware,
}
#: Masters whose accuracy is set by master.tolerance rather than by the macro step.
TOLERANCE_MASTERS: tuple[str, ...] = ("regime-aware",)
