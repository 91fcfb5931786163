"""Every FMU runs in a fresh virtual environment that has fmpy, pythonfmu and numpy (plus
what the FMU's requirements.txt names) but not this project, as a user of another tool
would have it; two of them in one process.  A missing requirement is named on standard
error, and the process exits without touching freed memory.  In a Python whose executable
has the interpreter built in (Debian's), the FMUs use that interpreter and load no
libpython.  Slow: it installs packages into a new environment.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import venv
import zipfile
from pathlib import Path

import pytest

from fmus.build import build_fmu
from fmus.registry import FMU_RECORDS

pytestmark = pytest.mark.slow

# Runs inside the plain environment: simulate each FMU named on the command line in this
# one process and report what happened.
PROBE = """
import json, re, sys
from fmpy import simulate_fmu
report = {}
try:
    import components  # noqa: F401
    report["project importable"] = True
except ImportError:
    report["project importable"] = False
for path in sys.argv[1:]:
    try:
        result = simulate_fmu(path, stop_time=1e-3, output_interval=1e-4)
        report[path] = ["ok", len(result)]
    except Exception as exc:
        report[path] = ["failed", str(exc)]
with open("/proc/self/maps") as maps:  # interpreters mapped (not pythonfmu's runtime)
    report["libpython mapped"] = sorted(set(re.findall(r"/libpython3[^/\\s]*", maps.read())))
print(json.dumps(report))
"""


def requirements(path: Path) -> list[str]:
    with zipfile.ZipFile(path) as z:
        return z.read("resources/requirements.txt").decode().split()


def pip(python: Path, *packages: str) -> None:
    subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", *packages],
        check=True,
    )


def probe(python: Path, paths: list[Path], cwd: Path) -> tuple[dict, str]:
    run = subprocess.run(
        [str(python), "-c", PROBE, *map(str, paths)],
        capture_output=True,
        text=True,
        cwd=cwd,  # not the project: nothing of it on the path
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    return json.loads(run.stdout.strip().splitlines()[-1]), run.stderr


@pytest.fixture(scope="module")
def plain_python(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh virtual environment with fmpy, pythonfmu and numpy only."""
    env = tmp_path_factory.mktemp("plain") / "venv"
    venv.create(env, with_pip=True)
    python = env / "bin" / "python"
    pip(python, "fmpy", "pythonfmu", "numpy")
    return python


def test_every_fmu_runs_in_a_plain_python(plain_python: Path, tmp_path: Path) -> None:
    fmus = {name: build_fmu(name) for name in sorted(FMU_RECORDS)}
    python = plain_python
    numpy_only = [p for p in fmus.values() if all("scipy" not in r for r in requirements(p))]
    needs_scipy = [p for p in fmus.values() if p not in numpy_only]
    assert numpy_only and needs_scipy

    report, stderr = probe(python, [*numpy_only, *needs_scipy], tmp_path)
    assert report.pop("project importable") is False
    assert len(report.pop("libpython mapped")) == 1  # the one its executable links
    for path in numpy_only:
        assert report[str(path)] == ["ok", 11], path
    # Those that import scipy when loaded are refused, and the reason is named (some import
    # it only for a computation the short run does not reach).
    assert report[str(fmus["GearMesh"])][0] == "failed"
    assert report[str(fmus["ClockGearTrain"])][0] == "failed"
    assert "cannot load its Python code: No module named 'scipy'" in stderr

    pip(python, *sorted({r for p in needs_scipy for r in requirements(p)}))
    report, _ = probe(python, needs_scipy, tmp_path)
    for path in needs_scipy:
        assert report[str(path)] == ["ok", 11], path
    assert sys.executable not in str(python)


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
def test_the_process_exits_without_touching_freed_memory(
    plain_python: Path, tmp_path: Path
) -> None:
    # pythonfmu's runtime resets a freed pointer at exit unless the FMU releases it first;
    # the heap corruption aborts only now and then, valgrind sees it every time.
    run = subprocess.run(
        ["valgrind", "--error-limit=no", str(plain_python), "-c", PROBE, str(build_fmu("Inertia"))],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONMALLOC": "malloc"},  # valgrind sees each object
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert json.loads(run.stdout.strip().splitlines()[-1])[str(build_fmu("Inertia"))][0] == "ok"
    # An error report is a blank-line-separated block; those naming the FMU's library count.
    blocks = re.split(r"\n==\d+== \n", run.stderr)
    in_fmu = [b for b in blocks if "Invalid" in b and "binaries/linux64" in b]
    assert not in_fmu, in_fmu[0]


def static_python() -> Path | None:
    """A Python 3.11+ whose executable has the interpreter built in (links no libpython),
    if this machine has one: Debian's /usr/bin/python3 is such a Python."""
    if shutil.which("ldd") is None:
        return None
    for candidate in sorted(Path("/usr/bin").glob("python3.[0-9]*")):
        if not re.fullmatch(r"python3\.\d+", candidate.name) or int(candidate.name[8:]) < 11:
            continue
        linked = subprocess.run(["ldd", str(candidate)], capture_output=True, text=True)
        if linked.returncode == 0 and "libpython" not in linked.stdout:
            return candidate
    return None


STATIC_PYTHON = static_python()


@pytest.mark.skipif(
    STATIC_PYTHON is None,
    reason="no Python 3.11+ here whose executable links no libpython (Debian's python3 is one)",
)
def test_fmus_run_in_fmpy_in_a_python_with_the_interpreter_built_in(
    tmp_path_factory: pytest.TempPathFactory, tmp_path: Path
) -> None:
    """The FMU's binary finds the interpreter the executable has built in and loads no
    libpython beside it (a second interpreter in one process would crash)."""
    env = tmp_path_factory.mktemp("static") / "venv"
    made = subprocess.run(
        [str(STATIC_PYTHON), "-m", "venv", str(env)], capture_output=True, text=True
    )
    if made.returncode != 0:
        pytest.skip(f"{STATIC_PYTHON} cannot make a virtual environment: {made.stderr.strip()}")
    python = env / "bin" / "python"
    pip(python, "fmpy", "numpy")
    fmus = [build_fmu("Inertia"), build_fmu("DetachedLever")]  # the second imports numpy
    report, stderr = probe(python, fmus, tmp_path)
    assert report.pop("project importable") is False
    assert report.pop("libpython mapped") == [], "a libpython was loaded beside the built-in one"
    for path in fmus:
        assert report[str(path)] == ["ok", 11], (path, stderr)
