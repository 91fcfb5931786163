"""Errors a user can act on: each names where the problem is and what was expected."""

from __future__ import annotations

from pathlib import Path


class ScenarioError(ValueError):
    """A scenario file is wrong; raised before anything runs."""

    def __init__(self, path: Path | str, key: str, message: str) -> None:
        self.path, self.key, self.message = str(path), key, message
        super().__init__(f"{path}: [{key}] {message}" if key else f"{path}: {message}")

    def __reduce__(self):
        # rebuilt from its three parts when a study's worker sends it back
        return type(self), (self.path, self.key, self.message)


class RunError(RuntimeError):
    """A run could not go on; what was recorded up to here is kept."""

    def __init__(self, message: str, time: float | None = None, fmu: str | None = None) -> None:
        self.time, self.fmu = time, fmu
        where = []
        if fmu:
            where.append(f"FMU {fmu!r}")
        if time is not None:
            where.append(f"t = {time:.9g} s")
        super().__init__(f"{', '.join(where)}: {message}" if where else message)
