"""A name -> callable registry whose entries are imported only when used.

Scene families live in their own modules (orchestrator/scenes/); registering one is one
line here-and-there, and loading a scene imports only what it names.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from importlib import import_module
from typing import Any


def resolve(entry: str) -> Callable[..., Any]:
    """The callable an entry "package.module:attribute" names (imports its module)."""
    module, _, attribute = entry.partition(":")
    return getattr(import_module(module), attribute)


class LazyRegistry(Mapping[str, Callable[..., Any]]):
    def __init__(self, entries: dict[str, str]) -> None:
        self._entries = dict(entries)  # name -> "package.module:attribute"

    def __getitem__(self, name: str) -> Callable[..., Any]:
        return resolve(self._entries[name])

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)
