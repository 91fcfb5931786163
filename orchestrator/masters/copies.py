"""Copies of a sampled input that a receiver reports (an output with the role own_copy_of
the input: the verge's copy of the escape wheel), and how the single pass judges them."""

from __future__ import annotations

from typing import Any

Slot = tuple[int, int]  # (instance, index of a Real output)
Copy = tuple[Slot, Slot]  # (source slot, receiver's copy slot)


def angles_with_speeds(
    copies: list[Copy], units: list[tuple[tuple[tuple[str, int], ...], float] | None]
) -> list[tuple[Slot, Slot, Copy | None]]:
    """The copies as the error estimate judges them: (source, copy, its speed's copy or
    None).  A copy whose unit is another's (same receiver, same source FMU) per second is
    that one's speed: its mismatch counts as the angle it moves the copy by in the step.
    Units: each copy's base unit (exponents, factor) as ``ModelInfo.base_unit`` gives it."""

    def per_second(unit):
        if unit is None:
            return None
        exponents = dict(unit[0])
        exponents["s"] = exponents.get("s", 0) - 1
        return tuple(sorted((k, v) for k, v in exponents.items() if v)), unit[1]

    speeds: dict[int, int] = {}  # index of an angle copy -> index of its speed copy
    for a, (ca, ua) in enumerate(zip(copies, units, strict=True)):
        rate = per_second(ua)
        for v, (cv, uv) in enumerate(zip(copies, units, strict=True)):
            same_pair = cv[0][0] == ca[0][0] and cv[1][0] == ca[1][0]
            if v != a and same_pair and rate is not None and uv == rate:
                speeds[a] = v
    judged_as_speed = set(speeds.values())
    return [
        (c[0], c[1], copies[speeds[a]] if a in speeds else None)
        for a, c in enumerate(copies)
        if a not in judged_as_speed
    ]


def copied_inputs(system: Any) -> list[tuple[Slot, int, str, str]]:
    """The sampled Real inputs whose receiver reports its own copy at the step end (an
    output with the role own_copy_of the input): (source slot, receiver, input name, name
    of the copy)."""
    found = []
    for c, src in zip(system.connections, system.connection_sources, strict=True):
        j = system.index[c.target[0]]
        model = system.models[j]
        if src is not None and c.target[1] in model.sampled:
            own = model.with_role("own_copy_of", c.target[1])
            if own is not None:
                found.append((src, j, c.target[1], own.name))
    return found


def judged_by_copies(system: Any) -> bool:
    """Whether some FMU of the system reports its own copy of a sampled input (the error
    measure the single pass needs to take long steps; ``input_hold = "auto"``)."""
    return bool(copied_inputs(system))
