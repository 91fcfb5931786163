"""What one FMU instance logs, kept within bounds, and its warnings counted by kind.

An FMU may log a line at every step for the whole run, or one line of megabytes: the
instance keeps its last ``KEPT_LINES`` lines, each cut at ``MAX_CHARS`` characters (its
length said), so memory per instance is bounded.  Warnings (a message logged with status
fmi2Warning or in a category that names a warning, and calls that return fmi2Warning) are
counted by kind, a kind being the message with its numbers taken out; the first message of
each of the first ``KEPT_KINDS`` kinds is kept, with its count and the time it came first.
"""

from __future__ import annotations

import re
from collections import deque
from dataclasses import dataclass
from typing import Any

KEPT_LINES = 100  # last lines of an instance's log kept
MAX_CHARS = 1000  # characters of one line kept
KEPT_KINDS = 20  # kinds of warning told apart per instance; the others are counted together
SAID_LINES = 10  # lines of what an FMU said during a failed call, in its error message
SHOWN_KINDS = 5  # kinds of warning per FMU written as notes and into the summary
WARNING = 1  # fmi2Warning
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def cut(text: str, limit: int = MAX_CHARS) -> str:
    """``text`` at most ``limit`` characters long, its length said where it was cut."""
    if len(text) <= limit:
        return text
    return f"{text[:limit]}... [cut: {len(text)} characters]"


def kind_of(message: str) -> str:
    """A warning's kind: its text with the numbers taken out."""
    return _NUMBER.sub("#", message.strip())[:200]


@dataclass
class WarningKind:
    first: str  # the first message of this kind (cut)
    first_time: float  # simulated time it came [s]
    count: int = 1


class FmuLog:
    """One instance's log: its last lines and its warnings."""

    def __init__(self) -> None:
        self.lines: deque[str] = deque(maxlen=KEPT_LINES)
        self.count = 0  # lines logged so far (kept or not)
        self.kinds: dict[str, WarningKind] = {}
        self.warnings = 0
        self.other_warnings = 0  # of kinds past KEPT_KINDS
        self.warned_at = -1  # self.count when the last logged warning came

    def add(self, status: int, category: str, message: str, time: float) -> None:
        text = cut(message.strip())
        self.lines.append(text)
        self.count += 1
        if status == WARNING or "warning" in category.lower():
            self.warn(text, time)
            self.warned_at = self.count

    def returned_warning(self, function: str, time: float) -> None:
        """``function`` returned fmi2Warning: a warning, unless the FMU's last line logged
        was one (the same warning, logged as the call returned it)."""
        if self.warned_at != self.count:
            self.warn(f"{function} returned fmi2Warning", time)

    def warn(self, text: str, time: float) -> None:
        self.warnings += 1
        kind = kind_of(text)
        if kind in self.kinds:
            self.kinds[kind].count += 1
        elif len(self.kinds) < KEPT_KINDS:
            self.kinds[kind] = WarningKind(text, time)
        else:
            self.other_warnings += 1

    def since(self, index: int) -> list[str]:
        """The lines logged since the ``index``-th (those still kept)."""
        new = self.count - index
        if new <= 0:
            return []
        return list(self.lines)[-new:]

    def said_since(self, index: int) -> str:
        """What was logged since line ``index``, one string: its last SAID_LINES lines."""
        lines = [line for line in self.since(index) if line]
        earlier = self.count - index - len(lines)
        if len(lines) > SAID_LINES:
            earlier += len(lines) - SAID_LINES
            lines = lines[-SAID_LINES:]
        said = cut("; ".join(lines), 2 * MAX_CHARS)
        return f"({earlier} earlier lines not shown) {said}" if earlier > 0 and said else said

    def last(self, n: int) -> str:
        return "; ".join(line for line in list(self.lines)[-n:] if line)

    def summary(self) -> dict[str, Any]:
        """Its warnings, for summary.json: the total and the first SHOWN_KINDS kinds."""
        kinds = list(self.kinds.values())
        return {
            "count": self.warnings,
            "kinds": len(kinds) + (1 if self.other_warnings else 0),
            "first": [
                {"message": k.first, "count": k.count, "first_time": k.first_time}
                for k in kinds[:SHOWN_KINDS]
            ],
        }

    def notes(self, fmu: str) -> list[str]:
        """One line per kind of warning (the first SHOWN_KINDS), with its count."""
        lines = []
        for k in list(self.kinds.values())[:SHOWN_KINDS]:
            times = f"{k.count} times" if k.count > 1 else "once"
            lines.append(
                f"FMU {fmu!r} warned {times} (first at t = {k.first_time:.9g} s): {k.first}"
            )
        rest = self.warnings - sum(k.count for k in list(self.kinds.values())[:SHOWN_KINDS])
        if rest:
            lines.append(f"FMU {fmu!r}: {rest} more warnings of other kinds (summary.json)")
        return lines
