"""The exported system run by another tool, in a child process: what comes back is the
header and one row of numbers per communication point k = 1..n.

This module imports nothing of the project, so a child process starts quickly.  ``job``:
``source`` (the unpacked SSP directory or the OSP-IS file for libcosim, the .ssp archive
for FMPy), ``record`` ([instance, variable] pairs), ``steps``, ``start``, ``step``, ``stop``.
"""

from __future__ import annotations

from pathlib import Path


def libcosim_run(job: dict) -> tuple[list[str], list[list[float]]]:
    import json

    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    source = job["source"]
    events: list[float] = []  # instants of input-signal jumps (a libcosim scenario)
    if source.endswith(".xml"):
        execution = CosimExecution.from_osp_config_file(source)
        scenario = Path(source).parent / "scenario.json"  # input signals (osp_export)
        if scenario.is_file():
            events = [job["start"] + e["time"] for e in json.loads(scenario.read_text())["events"]]
            manager = CosimManipulator.create_scenario_manager()
            if not (
                execution.add_manipulator(manager)
                and execution.load_scenario(manager, str(scenario))
            ):
                raise RuntimeError(f"libcosim did not load the scenario {scenario}")
    else:
        execution = CosimExecution.from_ssp_file(source)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = {s.name.decode(): s.index for s in execution.slave_infos()}
    variables = {
        name: {v.name.decode(): v for v in execution.slave_variables(i)}
        for name, i in index.items()
    }
    readers = []
    for instance, var in job["record"]:
        v = variables[instance][var]
        # libcosim's variable types: 0 Real, 1 Integer, 2 Boolean, 3 String
        read = {0: observer.last_real_values, 1: observer.last_integer_values}.get(v.type)
        if read is None:
            read = observer.last_boolean_values
        readers.append((read, index[instance], v.reference))
    header = ["time", *(f"{i}.{v}" for i, v in job["record"])]
    rows = []
    for k in range(1, job["steps"] + 1):  # the observer holds values only after a step
        if not execution.step(1):
            raise RuntimeError(f"libcosim step {k} failed")
        row = [job["start"] + k * job["step"]]
        row.extend(float(read(slave, [ref])[0]) for read, slave, ref in readers)
        if any(abs(row[0] - t) <= 1e-9 * job["step"] for t in events):
            # libcosim takes a scenario event at the step that starts there: the values it
            # shows at that instant are those before the event, not compared
            row = [float("nan")] * len(row)
        rows.append(row)
    return header, rows


def fmpy_run(job: dict) -> tuple[list[str], list[list[float]]]:
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from fmpy.ssp.ssd import read_ssd

    archive = job["source"]
    ssd = read_ssd(archive, validate=True)
    unpacked = Path(extract(archive))
    start, step = job["start"], job["step"]
    slaves, variables = {}, {}
    for component in ssd.system.elements:
        fmu_file = str(unpacked / component.source)
        md = read_model_description(fmu_file, validate=False)
        slave = FMU2Slave(
            guid=md.guid,
            unzipDirectory=extract(fmu_file),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=component.name,
        )
        slave.instantiate()
        slave.setupExperiment(startTime=start, stopTime=job["stop"])
        slave.enterInitializationMode()
        variables[component.name] = {v.name: v for v in md.modelVariables}
        slaves[component.name] = slave
        for binding in component.parameterBindings:
            for parameter_set in binding.parameterValues:
                for p in parameter_set.parameters:
                    var = variables[component.name][p.name]
                    if p.type == "Real" and p.unit and var.unit and p.unit != var.unit:
                        raise RuntimeError(
                            f"{component.name}.{p.name} is bound in {p.unit}, the FMU "
                            f"declares {var.unit}: this loop does not convert units"
                        )
                    _set(slave, var, p.value)
        slave.exitInitializationMode()
    wires = [
        (c.startElement, c.startConnector, c.endElement, c.endConnector)
        for c in ssd.system.connections
    ]
    held: dict[tuple[str, str], object] = {}

    def read_sources() -> None:
        for src, out, _, _ in wires:
            held[(src, out)] = _get(slaves[src], variables[src][out])

    def feed(instance: str) -> None:
        for src, out, dst, inp in wires:
            if dst == instance:
                _set(slaves[dst], variables[dst][inp], held[(src, out)])

    # Outputs with direct feedthrough depend on inputs: settle the initial exchange.
    for _ in range(len(slaves) + 1):
        read_sources()
        for name in slaves:
            feed(name)
    read_sources()
    record = [(slaves[i], variables[i][v]) for i, v in job["record"]]
    header = ["time", *(f"{i}.{v}" for i, v in job["record"])]
    rows = []
    for k in range(1, job["steps"] + 1):
        t = start + (k - 1) * step
        for name, slave in slaves.items():  # Jacobi: all see the last point's outputs
            feed(name)
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=step)
        read_sources()
        rows.append([start + k * step, *(float(_get(s, v)) for s, v in record)])
    return header, rows


def _get(slave, variable):  # noqa: ANN001, ANN202 - FMPy objects
    ref = [variable.valueReference]
    if variable.type == "Real":
        return slave.getReal(ref)[0]
    if variable.type in ("Integer", "Enumeration"):
        return slave.getInteger(ref)[0]
    return slave.getBoolean(ref)[0]


def _set(slave, variable, value) -> None:  # noqa: ANN001 - FMPy objects
    ref = [variable.valueReference]
    if variable.type == "Real":
        slave.setReal(ref, [float(value)])
    elif variable.type in ("Integer", "Enumeration"):
        slave.setInteger(ref, [int(value)])
    elif variable.type == "Boolean":
        truth = value if isinstance(value, bool) else str(value).strip().lower() in ("true", "1")
        slave.setBoolean(ref, [truth])
    else:
        raise RuntimeError(f"cannot set {variable.name}: type {variable.type}")


def fmpy_simulate_run(job: dict) -> tuple[list[str], list[list[float]]]:
    """One FMU through FMPy's own ``simulate_fmu``, given its input signals as FMPy's input
    table (``job["inputs"]``: the input names, then rows [time, value, ...], a jump as
    two rows at one time).  Rows at the communication points k = 1..n; one FMPy did not
    record, or recorded at an input jump, is all NaN."""
    import numpy as np
    from fmpy import simulate_fmu

    names, table = job["inputs"]
    signals = np.array(
        [tuple(row) for row in table], dtype=[("time", float), *((n, float) for n in names)]
    )
    result = simulate_fmu(
        job["fmu"],
        start_time=job["start"],
        stop_time=job["stop"],
        output_interval=job["step"],
        input=signals,
        start_values=job["start_values"],
        output=[v for _, v in job["record"]],
    )
    header = ["time", *(f"{i}.{v}" for i, v in job["record"])]
    # At a jump FMPy records the outputs before it applies the input after the jump (or no
    # row at all): those rows are not compared.
    jumps = np.array([a[0] for a, b in zip(table, table[1:], strict=False) if a[0] == b[0]])
    rows = []
    for k in range(1, job["steps"] + 1):
        t = job["start"] + k * job["step"]
        hit = np.flatnonzero(np.abs(result["time"] - t) <= 1e-9 * job["step"])
        if len(hit) == 0 or np.any(np.abs(jumps - t) <= 1e-9 * job["step"]):
            rows.append([float("nan")] * len(header))
        else:
            rows.append([t, *(float(result[v][hit[-1]]) for _, v in job["record"])])
    return header, rows
