"""The exported system run by another tool, in a child process: what comes back is the
header and one row of numbers per communication point k = 1..n.

This module imports nothing of the project, so a child process starts quickly.  ``job``:
``source`` (the unpacked SSP directory or the OSP-IS file for libcosim, the .ssp archive
for FMPy), ``record`` ([instance, variable] pairs), ``steps``, ``start``, ``step``, ``stop``.
"""

from __future__ import annotations

from pathlib import Path


def libcosim_run(job: dict) -> tuple[list[str], list[list[float]]]:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    source = job["source"]
    if source.endswith(".xml"):
        execution = CosimExecution.from_osp_config_file(source)
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
