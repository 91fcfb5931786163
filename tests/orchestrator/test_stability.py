"""Stability suite: the regime-aware master's row of every stiff or extreme case."""

from __future__ import annotations

import pytest

from orchestrator.studies.stability import case_files, run_suite

EXPECTED_STABLE = {
    "m739_friction_zero",
    "m739_jam",
    "m739_pallet_inertia_div100",
    "m739_pallet_inertia_x100",
    "m739_spin_x4",
    "press_feed_brake_below_min",
    "press_feed_brake_near_min",
    "press_feed_coupler_x100",
    "press_feed_hertz_clutch",
    "two_inertias_huge_step",
}


#: The case of the default run: stiff contact, an impact every cycle and the verge's
#: free flight, in about 4 s (the full suite takes a minute on two cores: ``-m slow``).
REPRESENTATIVE = "m739_pallet_inertia_div100"


def _rows(tmp_path_factory, fmu_cache, cases=None, hold="auto"):
    import os

    os.environ["MECHCOSIM_FMU_CACHE"] = str(fmu_cache)
    out = tmp_path_factory.mktemp("stability")
    overrides = {"master.input_hold": hold}
    rows = run_suite(
        out_dir=out, masters=("regime-aware",), workers=2, cases=cases, overrides=overrides
    )
    return {r.case: r for r in rows}


#: Both schemes of the regime-aware master on every case (the default, "auto", picks the
#: single pass for the escapement cases and the midpoint hold for the others).
@pytest.fixture(scope="module", params=["midpoint", "extrapolated"])
def rows(request, tmp_path_factory, fmu_cache):
    return _rows(tmp_path_factory, fmu_cache, hold=request.param)


def test_representative_case_is_stable_within_its_stated_error(tmp_path_factory, fmu_cache) -> None:
    row = _rows(tmp_path_factory, fmu_cache, (REPRESENTATIVE,))[REPRESENTATIVE]
    assert row.status == "completed", row.diagnosis
    assert row.stable, row.diagnosis


@pytest.mark.slow
def test_every_case_has_a_row(rows) -> None:
    assert set(rows) == {f.stem for f in case_files()}


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(EXPECTED_STABLE))
def test_regime_aware_master_is_stable_within_its_stated_error(rows, case) -> None:
    row = rows[case]
    assert row.status == "completed", row.diagnosis
    assert row.stable, row.diagnosis


@pytest.mark.slow
def test_elastic_impacts_stay_energy_consistent(rows) -> None:
    # Restitution 1 makes the tooth bounce; the run keeps its energy balance.  Its
    # trajectory error is now just inside the case's bound (9.0e-4 against 1e-3 with the
    # midpoint hold; it was outside with inputs held at the step start), too narrow a
    # margin to claim: only the energy balance is asserted.
    row = rows["m739_elastic_impacts"]
    assert row.status == "completed"
    assert row.energy_residual < 1e-3
