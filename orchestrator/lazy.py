"""A name -> callable registry whose entries are imported only when used.

Scene families live in their own modules (orchestrator/scenes/); registering one is one
line here-and-there, and loading a scene imports only what it names.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from importlib import import_module
from typing import Any


class LazyRegistry(Mapping[str, Callable[..., Any]]):
    def __init__(self, entries: dict[str, str]) -> None:
        self._entries = dict(entries)  # name -> "package.module:attribute"

    def __getitem__(self, name: str) -> Callable[..., Any]:
        module, _, attribute = self._entries[name].partition(":")
        return getattr(import_module(module), attribute)

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __len__(self) -> int:
        return len(self._entries)
