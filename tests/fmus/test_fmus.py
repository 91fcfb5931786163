"""Every FMU of the project meets the FMU rules (through fmpy, as another tool would)."""

from __future__ import annotations

import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from fmus.build import build_fmu, content_hash
from fmus.registry import FMU_RECORDS
from orchestrator.fmu_checks import state_round_trip_problems

NAMES = sorted(FMU_RECORDS)


@pytest.mark.parametrize("name", NAMES)
def test_validates_with_no_message(name: str, fmu_cache) -> None:
    assert validate_fmu(str(build_fmu(name, fmu_cache))) == []


@pytest.mark.parametrize("name", NAMES)
def test_declares_units_and_default_experiment(name: str, fmu_cache) -> None:
    md = read_model_description(str(build_fmu(name, fmu_cache)))
    assert md.defaultExperiment is not None
    declared = {v.name: v.unit for v in FMU_RECORDS[name].variables}
    for v in md.modelVariables:
        if v.type == "Real":
            expected = None if declared[v.name] == "1" else declared[v.name]
            assert v.unit == expected, v.name
    outputs = {v.name for v in md.modelVariables if v.causality == "output"}
    assert {u.variable.name for u in md.initialUnknowns} == outputs


@pytest.mark.parametrize("name", NAMES)
def test_runs_alone_in_fmpy(name: str, fmu_cache) -> None:
    result = simulate_fmu(str(build_fmu(name, fmu_cache)))
    assert len(result) > 10


@pytest.mark.parametrize("name", NAMES)
def test_state_round_trip_is_bit_identical(name: str, fmu_cache) -> None:
    assert state_round_trip_problems(build_fmu(name, fmu_cache)) == []


def test_build_is_cached_by_content(fmu_cache) -> None:
    first = build_fmu("Inertia", fmu_cache)
    mtime = first.stat().st_mtime_ns
    again = build_fmu("Inertia", fmu_cache)
    assert again == first and again.stat().st_mtime_ns == mtime
    assert content_hash(FMU_RECORDS["Inertia"])[:16] in first.name


def test_a_build_is_the_same_file_each_time(tmp_path) -> None:
    """Same sources, same environment: same bytes (entry dates, GUID and loader included)."""
    first = build_fmu("Inertia", tmp_path).read_bytes()
    again = build_fmu("Inertia", tmp_path, force=True).read_bytes()
    assert first == again
    guid = read_model_description(str(build_fmu("Inertia", tmp_path))).guid
    assert guid == read_model_description(str(build_fmu("Inertia", tmp_path / "b"))).guid


def test_many_instances_in_one_process(fmu_cache) -> None:
    # pythonfmu's runtime mishandles a reference on each instantiation; the slave
    # compensates, so instantiating many times in a process must stay safe.
    from orchestrator.fmu_instance import FmuInstance

    path = build_fmu("Inertia", fmu_cache)
    for k in range(25):
        fmu = FmuInstance(f"i{k}", path)
        fmu.initialize(0.0, 1.0, {"w0": 1.0})
        fmu.do_step(0.0, 0.5)
        assert fmu.get("phi") == pytest.approx(0.5)
        fmu.close()


def test_the_code_an_fmu_packs_follows_edits(tmp_path, monkeypatch) -> None:
    # The import scan is kept per file version: an edit that adds an import is seen at once
    # (same second, other size), and nothing is scanned again while nothing changes.
    import fmus.registry as registry

    monkeypatch.setattr(registry, "COMPONENTS_DIR", tmp_path)
    (tmp_path / "__init__.py").write_text("")
    (tmp_path / "b.py").write_text("X = 1\n")
    a = tmp_path / "a.py"
    a.write_text("Y = 2\n")
    component = "components.a.A"
    assert [p.name for p in registry.component_modules(component)] == ["__init__.py", "a.py"]
    a.write_text("from .b import X\n")
    modules = [p.name for p in registry.component_modules(component)]
    assert modules == ["__init__.py", "a.py", "b.py"]
    scans = registry._relative_imports.cache_info().misses
    registry.component_modules(component)
    assert registry._relative_imports.cache_info().misses == scans
