"""The port rule: how two ports of our FMUs join, variable by variable.

A port groups the variables of one shaft or joint by role (``angle``, ``speed``,
``torque``, and extra roles some joints need).  The scene loader (read from the FMU
file's annotation) and the FMU documentation (read from the component's PORTS) both
expand a port connection by this one rule.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

PORT_RULE = (
    "Connecting two ports joins each role present on both sides, from the side where it is "
    "an output to the side where it is an input. A role present on one side only is not "
    "connected."
)


class PortError(ValueError):
    """Two ports that cannot be joined (no shared role, or a role not output on one side)."""


@dataclass(frozen=True)
class PortSide:
    instance: str
    port: str
    roles: Mapping[str, str]  # role -> variable name
    causality: Callable[[str], str]  # variable name -> its causality


@dataclass(frozen=True)
class RoleLink:
    role: str
    source: tuple[str, str]  # (instance, output variable)
    target: tuple[str, str]  # (instance, input variable)


def join_ports(a: PortSide, b: PortSide) -> list[RoleLink]:
    """The variable-level connections of a port connection, one per shared role (sorted)."""
    roles = sorted(set(a.roles) & set(b.roles))
    if not roles:
        raise PortError(
            f"ports {a.instance}.{a.port} and {b.instance}.{b.port} share no role "
            "(angle, speed, torque, ...)"
        )
    links = []
    for role in roles:
        va, vb = a.roles[role], b.roles[role]
        ca, cb = a.causality(va), b.causality(vb)
        if ca == "output" and cb == "input":
            links.append(RoleLink(role, (a.instance, va), (b.instance, vb)))
        elif cb == "output" and ca == "input":
            links.append(RoleLink(role, (b.instance, vb), (a.instance, va)))
        else:
            raise PortError(
                f"role {role!r}: one side must output it and the other take it as input"
            )
    return links
