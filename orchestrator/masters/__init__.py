"""Master algorithms.  Each takes (system, scene, recorder, stats, progress) and runs the
scene with the typed settings its [master] table was read into (orchestrator.master_settings)."""

from __future__ import annotations

from orchestrator.master_settings import TOLERANCE_MASTERS
from orchestrator.masters.fixed_step import run_gauss_seidel, run_jacobi
from orchestrator.masters.regime_aware import run_regime_aware

MASTERS = {
    "jacobi": run_jacobi,
    "gauss-seidel": run_gauss_seidel,
    "regime-aware": run_regime_aware,
}
__all__ = ["MASTERS", "TOLERANCE_MASTERS"]
