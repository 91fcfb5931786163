"""The last row of a run that an FMU ended (fmi2Terminated after fmi2Discard): as FMPy
does, the FMU's outputs at its last successful time, when it got past the step start
(docs/fmus_in_other_tools.md, "Recording")."""

from __future__ import annotations

from typing import Any

from orchestrator.fmu_instance import FmuTerminated


def record_last_success(system: Any, recorder: Any, ended: FmuTerminated) -> tuple[float, str]:
    """Record the row at the terminating FMU's last successful time; the time reached and
    a note when that row cannot be had.  Only a scene of one FMU: with several, the
    others stand at the step start or its end, not at the FMU's last time."""
    if ended.last_time is None:
        return ended.time, ""
    if len(system.instances) != 1:
        return ended.time, (
            f"FMU {ended.fmu!r} got to t = {ended.last_time:.9g} s within its last step; not "
            "recorded there, as the other FMUs are not at that time"
        )
    system.read_all()
    recorder.row(system.record_row(ended.last_time))
    return ended.last_time, ""
