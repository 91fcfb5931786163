"""Run a scene in libcosim (libcosimpy) at a fixed step: proof that our FMUs are standard.

libcosim unloads FMU binaries when it is done, which pythonfmu's runtime does not survive
within one process, so the run happens in a child process and only numbers come back.
"""

from __future__ import annotations

import multiprocessing as mp
from pathlib import Path

import numpy as np

from orchestrator.errors import RunError
from orchestrator.run import fmu_files
from orchestrator.scenario import Scene


def run_with_libcosim(scene: Scene, cache_dir: Path | None = None) -> tuple[list[str], np.ndarray]:
    """Recorded Real signals after each of libcosim's fixed steps (the start row is absent)."""
    paths = fmu_files(scene, cache_dir)
    job = {
        "fmus": [
            (name, str(paths[name]), spec.parameters, spec.inputs)
            for name, spec in scene.fmus.items()
        ],
        "connections": [(c.source, c.target) for c in scene.connections],
        "record": list(scene.record),
        "step_ns": round(scene.master.step * 1e9),
        "duration_ns": round((scene.stop - scene.start) * 1e9),
    }
    if abs(job["step_ns"] * 1e-9 - scene.master.step) > 1e-15 * max(1.0, scene.master.step):
        raise RunError(f"libcosim steps in whole nanoseconds; {scene.master.step} s is not one")
    with mp.get_context("spawn").Pool(1) as pool:
        header, rows = pool.apply(_libcosim_child, (job,))
    return header, np.array(rows)


def _libcosim_child(job: dict) -> tuple[list[str], list[list[float]]]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_step_size(job["step_ns"])
    index, refs = {}, {}
    for name, path, parameters, inputs in job["fmus"]:
        index[name] = execution.add_local_slave(CosimLocalSlave(fmu_path=path, instance_name=name))
        refs[name] = {v.name.decode(): v.reference for v in execution.slave_variables(index[name])}
        for var, value in {**parameters, **inputs}.items():
            execution.real_initial_value(index[name], refs[name][var], value)
    for (src, out), (dst, inp) in job["connections"]:
        execution.connect_real_variables(index[src], refs[src][out], index[dst], refs[dst][inp])
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    record = [(inst, var) for inst, var in job["record"]]
    header = ["time", *(f"{i}.{v}" for i, v in record)]
    rows = []
    n_steps = job["duration_ns"] // job["step_ns"]
    for k in range(1, n_steps + 1):  # the observer holds values only after a step
        if not execution.step(1):
            raise RuntimeError(f"libcosim step {k} failed")
        row = [k * job["step_ns"] * 1e-9]
        for inst, var in record:
            row.append(observer.last_real_values(index[inst], [refs[inst][var]])[0])
        rows.append(row)
    return header, rows
