"""The compiled kernels (components.kernels) give the same bits as the Python code: the
M739 scenes and monolithic model are run with each path, in processes of their own (the
kernels are bound at import), and their outputs compared byte for byte."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from fmus.build import build_fmu
from fmus.kernel_build import kernel_plan

PROJECT = Path(__file__).resolve().parents[2]
needs_kernels = pytest.mark.skipif(
    kernel_plan().compiler is None, reason="no Cython or C compiler: no compiled kernels"
)

_MONOLITHIC = """
import hashlib, sys
from components.kernels import load_kernel
from orchestrator.scenes.m739.monolithic import run_m739
r = run_m739(t_stop=float(sys.argv[1]))
h = hashlib.sha256(repr((r.armed, r.turns, r.f23_max, r.f12_max, r.ff23_max, r.ff12_max,
                         r.pn_max, r.impacts, r.events, r.train_log)).encode())
for v in r.series.values():
    h.update(v.tobytes())
print(load_kernel("m739_kernel") is not None, h.hexdigest())
"""


def _env(pure: bool) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "MECHCOSIM_PURE_PYTHON"}
    env["PYTHONPATH"] = str(PROJECT)
    if pure:
        env["MECHCOSIM_PURE_PYTHON"] = "1"
    return env


def _monolithic(t_stop: float, pure: bool) -> tuple[bool, str]:
    out = subprocess.run(
        [sys.executable, "-c", _MONOLITHIC, str(t_stop)],
        env=_env(pure),
        capture_output=True,
        text=True,
        check=True,
        cwd=PROJECT,
    ).stdout.split()
    return out[-2] == "True", out[-1]


def _scene(scene: str, out: Path, pure: bool, *sets: str) -> dict[str, bytes]:
    command = [sys.executable, "-m", "orchestrator", "run", f"scenarios/{scene}", "--output"]
    command += [str(out), "--no-progress", "--no-plot", "--no-reference"]
    for s in sets:
        command += ["--set", s]
    subprocess.run(command, env=_env(pure), capture_output=True, check=True, cwd=PROJECT)
    return {f: (out / f).read_bytes() for f in ("timeseries.csv", "events.csv")}


@needs_kernels
def test_the_verge_and_train_fmus_ship_the_kernel() -> None:
    for name in ("VergeEscapement", "GearTrain"):
        with zipfile.ZipFile(build_fmu(name)) as z:
            assert any(n.endswith("/components/m739_kernel.so") for n in z.namelist()), name


@needs_kernels
def test_both_paths_agree_on_a_short_m739_run(tmp_path: Path) -> None:
    compiled, fast = _monolithic(0.005, pure=False)
    fallback, slow = _monolithic(0.005, pure=True)
    assert (compiled, fallback) == (True, False)
    assert fast == slow
    a = _scene("m739.toml", tmp_path / "c", False, "scene.stop=5 ms")
    b = _scene("m739.toml", tmp_path / "py", True, "scene.stop=5 ms")
    assert a == b
    assert a["timeseries.csv"].count(b"\n") > 10  # the run did move


@pytest.mark.slow
@needs_kernels
@pytest.mark.parametrize("scene", ["m739.toml", "m739_from_deck.toml"])
def test_both_paths_agree_on_the_m739_scenes(scene: str, tmp_path: Path) -> None:
    assert _scene(scene, tmp_path / "c", False) == _scene(scene, tmp_path / "py", True)


@pytest.mark.slow
@needs_kernels
def test_both_paths_agree_on_the_m739_monolithic_model() -> None:
    assert _monolithic(0.2, pure=False)[1] == _monolithic(0.2, pure=True)[1]
