"""Master algorithms, by the name a scene gives its ``master.algorithm``.

Each entry makes the stepping algorithm of one run from (system, scene, stats); the
algorithm reads its typed settings (orchestrator/master_settings.py) from
``scene.master.settings``, and the execution loop (orchestrator/execution.py) steps it.
"""

from __future__ import annotations

from orchestrator.master_settings import TOLERANCE_MASTERS
from orchestrator.masters.fixed_step import gauss_seidel, jacobi
from orchestrator.masters.macro_step import MacroStep, Master, MasterFactory
from orchestrator.masters.regime_aware_choice import regime_aware

MASTERS: dict[str, MasterFactory] = {
    "jacobi": jacobi,
    "gauss-seidel": gauss_seidel,
    "regime-aware": regime_aware,
}
__all__ = ["MASTERS", "TOLERANCE_MASTERS", "MacroStep", "Master", "MasterFactory"]
