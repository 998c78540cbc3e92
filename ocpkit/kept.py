"""A few values kept for reuse, the most recently used: what every build of a robot shares (the dynamics rows'
Function, its derivatives and compiled code, the shapes' layouts), made once and kept apart from the builds."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, TypeVar

V = TypeVar("V")


class Kept(Generic[V]):
    """At most `size` values by key; the least recently used goes first."""

    def __init__(self, size: int) -> None:
        self.size = size
        self._values: OrderedDict[Hashable, V] = OrderedDict()

    def get(self, key: Hashable, make: Callable[[], V]) -> V:
        """The value kept for `key`, made by make() and kept if there is none."""
        if key not in self._values:
            self.put(key, make())
        return self[key]

    def put(self, key: Hashable, value: V) -> None:
        """Keep `value` for `key`, dropping the least recently used values beyond `size`."""
        self._values[key] = value
        self._values.move_to_end(key)
        while len(self._values) > self.size:
            self._values.popitem(last=False)

    def __getitem__(self, key: Hashable) -> V:
        self._values.move_to_end(key)
        return self._values[key]

    def __contains__(self, key: Hashable) -> bool:
        return key in self._values

    def __len__(self) -> int:
        return len(self._values)

    def clear(self) -> None:
        self._values.clear()
