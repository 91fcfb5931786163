"""The rules every FMU of the project meets, as checks that return the problems found."""

from __future__ import annotations

from pathlib import Path

from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from fmus.build import build_fmu
from fmus.registry import FMU_RECORDS
from orchestrator.fmu_instance import FmuInstance


def check_fmu(name: str, cache_dir: Path | None = None) -> list[str]:
    """Build FMU ``name`` and check it: validation, units, standalone run, state round trip."""
    path = build_fmu(name, cache_dir)
    problems = [f"validation: {m}" for m in validate_fmu(str(path))]
    md = read_model_description(str(path))
    if md.defaultExperiment is None:
        problems.append("no DefaultExperiment")
    for v in md.modelVariables:
        if (
            v.type == "Real"
            and v.causality != "local"
            and v.unit is None
            and not _dimensionless(name, v.name)
        ):
            problems.append(f"variable {v.name!r} declares no unit")
    try:
        result = simulate_fmu(str(path))
        if len(result) < 2:
            problems.append("standalone run recorded no steps")
    except Exception as exc:  # any failure of a standalone run is a finding
        problems.append(f"standalone run failed: {exc}")
    problems.extend(state_round_trip_problems(path))
    return problems


def _dimensionless(fmu_name: str, var: str) -> bool:
    return FMU_RECORDS[fmu_name].component_class.variable(var).unit == "1"


def state_round_trip_problems(path: Path, steps: int = 20, h: float = 1e-4) -> list[str]:
    """Step, save, step, restore, step again: the outputs must be bit-identical."""
    fmu = FmuInstance("roundtrip", path)
    try:
        md = fmu.model_description
        outputs = [v for v in md.modelVariables if v.causality == "output"]
        real_refs = [v.valueReference for v in outputs if v.type == "Real"]
        int_refs = [v.valueReference for v in outputs if v.type == "Integer"]
        fmu.initialize(0.0, 1.0, {})
        t = 0.0
        for _ in range(steps):
            fmu.do_step(t, h)
            t += h
        saved = fmu.get_state()
        first = _advance(fmu, t, h, steps, real_refs, int_refs)
        fmu.set_state(saved)
        second = _advance(fmu, t, h, steps, real_refs, int_refs)
        fmu.free_state(saved)
    finally:
        fmu.close()
    if first != second:
        return ["restoring a saved state and stepping again gives different outputs"]
    return []


def _advance(
    fmu: FmuInstance, t: float, h: float, steps: int, real_refs: list[int], int_refs: list[int]
):
    trace = []
    for _ in range(steps):
        fmu.do_step(t, h)
        t += h
        trace.append((tuple(fmu.get_real(real_refs)), tuple(fmu.get_integer(int_refs))))
    return trace
