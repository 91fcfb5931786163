"""Our FMUs in a host that is not Python: ``foreign/fmi_host.c``, compiled here, dlopens the
FMU's binary and calls the fmi2 functions, as the FMI Compliance Checker, OMSimulator or
libcosim's ``cosim`` do.  It runs as a process of its own with an empty environment (no
LD_PRELOAD, no PYTHONPATH, no PATH): the FMU finds and starts the Python that built it.

What it prints is compared with FMPy on the same FMU (one FMU alone) and with our Jacobi
master (the M739 train and verge coupled), value for value.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
from foreign_fmus import FOREIGN_DIR, c_compiler, fmi_headers_dir

import fmus.host_loader as host_loader
from fmus.build import build_fmu
from fmus.registry import FMU_RECORDS
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.studies.crosscheck import ToolRun, agreement

pytestmark = pytest.mark.skipif(
    not sys.platform.startswith("linux") or c_compiler() is None,
    reason="the C host is built on Linux with a C compiler",
)

HOST_SOURCE = FOREIGN_DIR / "fmi_host.c"
SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
#: each FMU alone: start values set in initialization mode, SI (as the m739 scene sets them)
ALONE = {
    "GearTrain": {"mu": 0.1, "spin": 30000 * 2 * math.pi / 60},
    "VergeEscapement": {"mu1": 0.1, "mu": 0.1, "spin": 30000 * 2 * math.pi / 60},
    "DetachedLever": {"switching_mode": 1},  # imports numpy
}
STEPS = 12
AGREE = 1e-12


@pytest.fixture(scope="module")
def host(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("c_host") / "fmi_host"
    command = [c_compiler(), "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror"]
    command += [f"-I{fmi_headers_dir()}", str(HOST_SOURCE), "-o", str(out), "-ldl", "-lpthread"]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return out


def run_host(host: Path, job: Path, env: dict[str, str] | None = None) -> list[str]:
    """Run the C host on ``job`` with only ``env`` in its environment; its output lines."""
    run = subprocess.run(
        [str(host), str(job)], env=env or {}, capture_output=True, text=True, timeout=600
    )
    assert run.returncode in (0, 1), (run.returncode, run.stdout[-3000:], run.stderr[-3000:])
    return run.stdout.splitlines()


def unpack(fmu: Path, dest: Path) -> Path:
    with zipfile.ZipFile(fmu) as z:
        z.extractall(dest)
    return dest


def fmu_lines(instance: str, path: Path, unpacked: Path, values: dict, outs: list) -> list[str]:
    md = read_model_description(str(path))
    variables = {v.name: v for v in md.modelVariables}
    lines = [f"fmu {instance} {unpacked} {md.coSimulation.modelIdentifier} {md.guid}"]
    for name, value in values.items():
        v = variables[name]
        kind = {"Real": "r", "Boolean": "b"}.get(v.type, "i")
        lines.append(f"set {kind} {v.valueReference} {float(value)!r}")
    for v in outs:
        lines.append(f"out {'r' if v.type == 'Real' else 'i'} {v.valueReference}")
    return lines


def outputs(path: Path) -> list:
    md = read_model_description(str(path))
    return [v for v in md.modelVariables if v.causality == "output" and v.type != "Boolean"]


def fmpy_run(
    path: Path, values: dict, outs: list, step: float, scratch: Path, steps: int = STEPS
) -> np.ndarray:
    """The C host's "run" lines, by FMPy (a Python host) on the same FMU."""
    md = read_model_description(str(path))
    variables = {v.name: v for v in md.modelVariables}
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=str(unpack(path, scratch)),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="fmpy",
    )
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for name, value in values.items():
        v = variables[name]
        if v.type == "Real":
            fmu.setReal([v.valueReference], [float(value)])
        else:
            fmu.setInteger([v.valueReference], [int(value)])
    fmu.exitInitializationMode()

    def row(t: float) -> list[float]:
        return [t] + [
            fmu.getReal([v.valueReference])[0]
            if v.type == "Real"
            else fmu.getInteger([v.valueReference])[0]
            for v in outs
        ]

    rows = [row(0.0)]
    for k in range(steps):
        fmu.doStep(currentCommunicationPoint=k * step, communicationStepSize=step)
        rows.append(row((k + 1) * step))
    fmu.terminate()
    fmu.freeInstance()
    return np.array(rows, dtype=float)


def table(lines: list[str], label: str) -> np.ndarray:
    return np.array([[float(x) for x in ln.split()[1:]] for ln in lines if ln.split()[0] == label])


def worst_disagreement(a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference over a column, relative to the column's scale (0 where both are
    zero throughout), over the columns."""
    assert a.shape == b.shape
    scale = np.maximum(np.max(np.abs(a), axis=0), np.max(np.abs(b), axis=0))
    diff = np.max(np.abs(a - b), axis=0)
    return float(np.max(np.where(scale > 0, diff / np.where(scale > 0, scale, 1), 0.0)))


def test_the_full_call_sequence_in_a_c_host_matches_fmpy(host: Path, tmp_path: Path) -> None:
    """GearTrain, VergeEscapement and DetachedLever (which needs numpy), one after the other
    in one C process: instantiate, set up, initialize with Real and Integer start values,
    step, get/set/free the FMU state, a refused step, reset, terminate, free, instantiate
    again, two instances side by side, an instance that failed fatally."""
    job = [f"sequence 0 {STEPS}"]
    expected = {}
    for name, values in ALONE.items():
        path = build_fmu(name)
        outs = outputs(path)
        step = float(read_model_description(str(path)).defaultExperiment.stepSize)
        expected[name] = fmpy_run(path, values, outs, step, tmp_path / f"{name}-fmpy")
        job += fmu_lines(name, path, unpack(path, tmp_path / name), values, outs)
        job.append(f"step {step!r}")
    (tmp_path / "job.txt").write_text("\n".join(job) + "\n")
    out = run_host(host, tmp_path / "job.txt")
    assert out[-1] == "done 0 failures", out[-20:]
    half = STEPS // 2
    for name, reference in expected.items():
        run = table(out, f"{name}:run")
        assert run.shape == reference.shape, name
        assert worst_disagreement(run, reference) <= AGREE, name
        assert np.array_equal(table(out, f"{name}:restored"), run[half + 1 :]), name
        for label in ("reset", "twin_b", "twin_c"):
            assert np.array_equal(table(out, f"{name}:{label}"), run[1:]), (name, label)
        # the refused step says why, although the host left debug logging off
        assert f"{name}:zero step status 3" in out, name
        assert any(ln.startswith(f"log Error {name}_a:") and "refused" in ln for ln in out), name
        # fmi2Error for an unknown value reference, and the instance is in FMI's error state
        assert f"{name}:after an unknown value reference 3, then 3" in out, name
        said = [ln for ln in out if ln.startswith("log ") and f" {name}_d:" in ln]
        assert said == [
            f"log Error {name}_d: fmi2GetReal: no variable has value reference 999999",
            f"log Error {name}_d: fmi2DoStep: not allowed in state error (FMI 2.0 allows it in: "
            "step complete)",
        ], said


#: FMI 2.0 resource locations (2.1.6) that name the unpacked FMU's resources/ directory
RESOURCE_FORMS = {
    "file:/": "file:{dir}/resources",
    "file://localhost/": "file://localhost{dir}/resources",
    "percent-escaped": "file://{escaped}/%72esources",  # %72 is "r"
}


@pytest.fixture(scope="module")
def fmpy_alone(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple]:
    """Each of our FMUs unpacked, and its first 3 steps in FMPy (at "file:///")."""
    scratch = tmp_path_factory.mktemp("alone")
    runs = {}
    for name in FMU_RECORDS:
        path = build_fmu(name)
        outs = outputs(path)
        values = ALONE.get(name, {})
        step = float(read_model_description(str(path)).defaultExperiment.stepSize)
        reference = fmpy_run(path, values, outs, step, scratch / f"{name}-fmpy", steps=3)
        unpacked = unpack(path, scratch / name).resolve()
        lines = fmu_lines(name, path, unpacked, values, outs)
        runs[name] = (unpacked, lines + [f"step {step!r}"], reference)
    return runs


@pytest.mark.parametrize("form", RESOURCE_FORMS)
def test_every_fmu_runs_at_every_form_of_resource_location(
    host: Path, tmp_path: Path, fmpy_alone: dict, form: str
) -> None:
    """Each of our FMUs in one C process, instantiated at a resource location written as
    FMI 2.0 allows (pythonfmu's runtime alone takes only "file://": the others crashed it),
    stepped as FMPy steps it with "file:///", value for value."""
    job = ["plain 0 3"]
    for unpacked, lines, _ in fmpy_alone.values():
        escaped = "".join(f"%{ord(c):02X}" if c == "_" else c for c in str(unpacked))
        job += [*lines, f"uri {RESOURCE_FORMS[form].format(dir=unpacked, escaped=escaped)}"]
    (tmp_path / "job.txt").write_text("\n".join(job) + "\n")
    out = run_host(host, tmp_path / "job.txt")
    assert out[-1] == "done 0 failures", out[-20:]
    for name, (_, _, reference) in fmpy_alone.items():
        assert np.array_equal(table(out, f"{name}:run"), reference), name


def test_input_derivatives_in_a_c_host(host: Path, tmp_path: Path) -> None:
    """The brake load slipping under a torque ramped by fmi2SetRealInputDerivatives (its
    loader serves them, with no Python in the host): speed v0 + ((T0 - T_b) t + dT t^2/2)/j,
    the closed form of a shaft under a ramped torque against constant friction."""
    j, t_b, v0, t0, dt, h, n = 0.05, 18.0, 5.0, 20.0, 3000.0, 1e-3, 20
    path = build_fmu("BrakeLoad")
    md = read_model_description(str(path))
    speed = next(v for v in md.modelVariables if v.name == "speed")
    torque = next(v for v in md.modelVariables if v.name == "torque")
    values = {"j": j, "brake_torque": t_b, "speed0": v0, "torque": t0}
    job = [f"plain 0 {n}", *fmu_lines("brake", path, unpack(path, tmp_path / "b"), values, [])]
    job += [f"out r {speed.valueReference}", f"derivative {torque.valueReference} {dt!r}"]
    (tmp_path / "job.txt").write_text("\n".join(job + [f"step {h!r}"]) + "\n")
    out = run_host(host, tmp_path / "job.txt")
    assert out[-1] == "done 0 failures", out[-20:]
    t, v = table(out, "brake:run").T
    assert len(t) == n + 1
    exact = v0 + ((t0 - t_b) * t + 0.5 * dt * t * t) / j
    assert np.abs(v - exact).max() <= 1e-13 * np.abs(exact).max()


def test_a_resource_location_that_is_no_local_file_is_refused_by_name(
    host: Path, tmp_path: Path
) -> None:
    path = build_fmu("Inertia")
    unpacked = unpack(path, tmp_path / "x")
    job = ["plain 0 1", *fmu_lines("i", path, unpacked, {}, []), "uri http://host/resources"]
    (tmp_path / "job.txt").write_text("\n".join(job + ["step 1e-3"]) + "\n")
    out = run_host(host, tmp_path / "job.txt")
    assert "instantiate i returned NULL" in out
    assert any(
        ln.startswith("log Error i:") and '"http://host/resources" is no file URI' in ln
        for ln in out
    ), out
    job[-1] = f"uri file://{tmp_path}/resources"  # an existing directory, not the FMU's
    (tmp_path / "job.txt").write_text("\n".join(job + ["step 1e-3"]) + "\n")
    out = run_host(host, tmp_path / "job.txt")
    assert "instantiate i returned NULL" in out
    assert any("no slavemodule.txt in" in ln for ln in out), out


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_m739_train_and_verge_coupled_in_a_c_host_match_our_jacobi_master(
    host: Path, tmp_path: Path
) -> None:
    """The first 2 ms of M739 at 1 us, fixed-step Jacobi in C (two different FMUs, an
    Integer connection among the Real ones, each FMU stepped on a thread of its own)
    against ``mechcosim`` Jacobi at that step."""
    scene = load_scene(
        SCENARIOS / "m739.toml",
        {"master.algorithm": "jacobi", "master.step": 1e-6, "scene.stop": 2e-3},
    )
    steps = round((scene.stop - scene.start) / scene.master.step)
    ours = run_scene(
        scene, output_dir=tmp_path / "ours", show_progress=False, compare_reference=False
    )
    assert ours.status == "completed", ours.message

    # each FMU steps on a thread of its own, both at once, as a parallel host does
    job = [f"jacobi {scene.start!r} {scene.stop!r} {scene.master.step!r} {steps} threads"]
    header = ["time"]
    order = list(scene.master.order)
    variables = {}
    for name in order:
        spec = scene.fmus[name]
        md = read_model_description(str(spec.path))
        variables[name] = {v.name: v for v in md.modelVariables}
        recorded = [var for inst, var in scene.record if inst == name]
        header += [f"{name}.{var}" for var in recorded]
        values = {**spec.parameters, **spec.inputs}
        outs = [variables[name][var] for var in recorded]
        job += fmu_lines(name, spec.path, unpack(spec.path, tmp_path / name), values, outs)
    for c in scene.connections:
        source, target = variables[c.source[0]][c.source[1]], variables[c.target[0]][c.target[1]]
        kind = "r" if source.type == "Real" else "i"
        job.append(
            f"connect {kind} {c.source[0]} {source.valueReference} "
            f"{c.target[0]} {target.valueReference}"
        )
    assert len(order) == 2 and any(ln.startswith("connect i") for ln in job)
    (tmp_path / "job.txt").write_text("\n".join(job) + "\n")
    out = run_host(host, tmp_path / "job.txt")
    assert out[-1] == "done 0 failures", out[-20:]

    parts = [table(out, name) for name in order]
    assert all(len(p) == steps for p in parts)
    assert np.array_equal(parts[0][:, 0], parts[1][:, 0])
    data = np.column_stack([parts[0]] + [p[:, 1:] for p in parts[1:]])
    theirs = ToolRun("C host", "job file", header, data, 0.0)
    result = agreement(ours, theirs, scene)
    assert result.points >= 100
    assert set(result.per_signal) == {f"{i}.{v}" for i, v in scene.record}
    name, worst = result.worst
    assert worst <= AGREE, (name, worst)
    # past the first impact: the Integer connection carried something
    impacts = data[:, header.index("verge.impact_count")]
    assert impacts[0] == 0 and impacts[-1] >= 1


def test_a_python_named_by_the_variable_is_started_and_its_environment_used(
    host: Path, tmp_path: Path
) -> None:
    """$MECHCOSIM_PYTHON names a virtual environment without numpy (the Python it is made
    from has numpy): DetachedLever cannot load its code there, and the C host hears why at
    default logging; fmi2Instantiate returns NULL, nothing crashes.  A Python that is not
    there, or of another version, is named in the log the same way."""
    bare = tmp_path / "bare"
    venv.create(bare, with_pip=False, symlinks=True)
    path = build_fmu("DetachedLever")
    job = ["sequence 0 2", *fmu_lines("lever", path, unpack(path, tmp_path / "x"), {}, [])]
    job.append("step 1e-3")
    (tmp_path / "job.txt").write_text("\n".join(job) + "\n")

    out = run_host(host, tmp_path / "job.txt", {"MECHCOSIM_PYTHON": str(bare / "bin" / "python")})
    assert "instantiate lever_a returned NULL" in out
    assert any("log Fatal lever_a:" in ln and "No module named 'numpy'" in ln for ln in out), out
    assert out[-1] == "done 1 failures"

    missing = tmp_path / "nowhere" / "python"
    out = run_host(host, tmp_path / "job.txt", {"MECHCOSIM_PYTHON": str(missing)})
    assert "instantiate lever_a returned NULL" in out
    logged = [ln for ln in out if ln.startswith("log Error lever_a:")]
    assert logged and str(missing) in logged[0] and "MECHCOSIM_PYTHON" in logged[0], out

    # A Python of another version is refused before anything of it is loaded.
    cfg = bare / "pyvenv.cfg"
    cfg.write_text(re.sub(r"(?m)^version.*$", "version = 3.99.0", cfg.read_text()))
    out = run_host(host, tmp_path / "job.txt", {"MECHCOSIM_PYTHON": str(bare / "bin" / "python")})
    assert "instantiate lever_a returned NULL" in out
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    assert any(
        ln.startswith("log Error lever_a:")
        and f"the FMU was built for Python {version}" in ln
        and "is Python 3.99" in ln
        for ln in out
    ), out


@pytest.mark.parametrize("what", ["ls", "a text file"])
def test_a_variable_naming_no_python_is_refused_at_instantiation(
    host: Path, tmp_path: Path, what: str
) -> None:
    """Something that is not a Python executable is not started as one: fmi2Instantiate
    returns NULL with the reason (/bin/ls beside /usr/lib/python3.X would start, badly)."""
    path = build_fmu("Inertia")
    job = ["plain 0 1", *fmu_lines("i", path, unpack(path, tmp_path / "x"), {}, []), "step 1e-3"]
    (tmp_path / "job.txt").write_text("\n".join(job) + "\n")
    named = shutil.which("ls") if what == "ls" else str(tmp_path / "job.txt")
    out = run_host(host, tmp_path / "job.txt", {"MECHCOSIM_PYTHON": named})
    assert "instantiate i returned NULL" in out
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    expected = "is not a Python" if what == "ls" else "is not there or not executable"
    logged = [ln for ln in out if ln.startswith("log Error i:")]
    assert logged and named in logged[0] and expected in logged[0], out
    assert f"set MECHCOSIM_PYTHON to a Python {version} executable" in logged[0], out


def test_without_a_c_compiler_the_build_says_so_and_the_fmu_runs_in_python_hosts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    from fmpy import simulate_fmu

    monkeypatch.setattr(host_loader, "c_compiler", lambda: None)
    host_loader.loader_plan.cache_clear()
    try:
        path = build_fmu("Inertia", tmp_path)
    finally:
        monkeypatch.undo()
        host_loader.loader_plan.cache_clear()
    said = capsys.readouterr().err.strip().splitlines()
    assert said == [
        "Inertia: no C compiler (cc, gcc or $CC) on PATH: the FMU's Linux binary is "
        "pythonfmu's runtime alone, which loads in hosts that run Python only"
    ]
    with zipfile.ZipFile(path) as z:
        names = z.namelist()
    assert "binaries/linux64/Inertia.so" in names
    assert host_loader.RUNTIME_FILE not in " ".join(names) and host_loader.PYTHON_FILE not in names
    assert path != build_fmu("Inertia", tmp_path)  # with the compiler: another build
    assert len(simulate_fmu(str(path), stop_time=0.01, output_interval=1e-3)) == 11


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
def test_the_c_host_exits_without_touching_freed_memory(host: Path, tmp_path: Path) -> None:
    """pythonfmu's runtime resets freed interpreter state from its library destructor when a
    process exits with it loaded; the loader releases that state first (without it valgrind
    sees invalid reads at exit in this very run)."""
    path = build_fmu("GearTrain")
    job = ["sequence 0 2", *fmu_lines("train", path, unpack(path, tmp_path / "x"), {}, [])]
    job.append("step 1e-5")
    (tmp_path / "job.txt").write_text("\n".join(job) + "\n")
    run = subprocess.run(
        ["valgrind", "--error-exitcode=99", str(host), str(tmp_path / "job.txt")],
        env={},
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert run.stdout.splitlines()[-1] == "done 0 failures"
    assert "ERROR SUMMARY: 0 errors" in run.stderr
