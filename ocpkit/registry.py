"""Name → component registries, extendable by third-party packages through Python entry points."""

from __future__ import annotations

from importlib.metadata import entry_points
from typing import Generic, TypeVar

from ocpkit.errors import RegistryError

T = TypeVar("T")


class Registry(Generic[T]):
    """Components of one family (e.g. transcriptions) keyed by a short name.

    Built-in components register themselves with `register`; others are found in the entry-point
    group `group` (e.g. `ocpkit.transcriptions`), loaded on first lookup of an unknown name.
    """

    def __init__(self, family: str, group: str) -> None:
        self.family, self.group = family, group
        self._items: dict[str, T] = {}

    def register(self, name: str, item: T) -> T:
        """Add `item` under `name`; returns it, so it can decorate a class."""
        self._items[name] = item
        return item

    def get(self, name: str) -> T:
        """The component called `name`; RegistryError lists the known names if there is none."""
        if name not in self._items:
            for point in entry_points(group=self.group):
                if point.name == name:
                    self._items[name] = point.load()
        if name not in self._items:
            raise RegistryError(f"unknown {self.family} {name!r}; known: {', '.join(self.names())}")
        return self._items[name]

    def names(self) -> list[str]:
        """Registered names, built-in and from entry points."""
        return sorted(set(self._items) | {p.name for p in entry_points(group=self.group)})
