"""An FMU that ends the simulation in a step it completed (fmi2Discard, fmi2Terminated,
fmi2LastSuccessfulTime at the step's end, as the Reference FMU Stair does on its last
event): its last row is recorded at that time, as FMPy records it."""

from __future__ import annotations

from pathlib import Path

import foreign_fmus
import numpy as np
import pytest

from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

FAULT_TIME = 0.01  # the step from 10 ms to 11 ms is the last
ALONE = """
[scene]
name = "{name}"
stop = "20 ms"

[fmus.c]
fmu = "{fmu}"
parameters = {{ "body.J" = "1e-4 kg*m^2", "spring.k" = "2 N*m/rad", "body.phi0" = "0.1 rad" }}

[master]
algorithm = "jacobi"
step = "1 ms"

[output]
record = ["c.body.phi", "c.body.w"]
"""


@pytest.fixture(scope="module")
def fmus(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("last_time")
    try:
        return {
            "plain": foreign_fmus.build_torsion_body(d),
            "ends": foreign_fmus.build_torsion_body(
                d, fault="terminate_after", fault_time=FAULT_TIME
            ),
        }
    except foreign_fmus.ForeignFmuError as exc:
        pytest.skip(str(exc))


def _run(fmu: Path, name: str, d: Path):  # noqa: ANN202 - RunResult
    scene = d / f"{name}.toml"
    scene.write_text(ALONE.format(name=name, fmu=fmu))
    return run_scene(load_scene(scene), d / name, show_progress=False, plots=False)


def test_the_last_successful_time_is_recorded(fmus: dict[str, Path], tmp_path: Path) -> None:
    ended = _run(fmus["ends"], "ends", tmp_path)
    plain = _run(fmus["plain"], "plain", tmp_path)
    assert ended.status == "completed"
    assert ended.message.startswith("terminated by FMU 'c' at t = 0.011 s (last successful)")
    # rows at 0, 1, ..., 10 ms and the step the FMU completed before it ended: 11 ms
    assert len(ended.data) == 12 and ended.time_reached == pytest.approx(0.011, abs=1e-15)
    np.testing.assert_array_equal(ended.data, plain.data[:12])  # the same numbers, bit for bit


def test_fmpy_records_the_same_rows(fmus: dict[str, Path], tmp_path: Path) -> None:
    from fmpy import simulate_fmu

    ended = _run(fmus["ends"], "ends", tmp_path)
    theirs = simulate_fmu(
        str(fmus["ends"]),
        stop_time=0.02,
        output_interval=1e-3,
        start_values={"body.J": 1e-4, "spring.k": 2.0, "body.phi0": 0.1},
        output=["body.phi", "body.w"],
    )
    assert len(theirs) == len(ended.data)
    np.testing.assert_allclose(theirs["time"], ended.data[:, 0], rtol=0, atol=1e-15)
    # FMPy counts its time as n h, we add h up: step starts differ in the last bit
    np.testing.assert_allclose(theirs["body.phi"], ended.signal("c.body.phi"), rtol=1e-12)
