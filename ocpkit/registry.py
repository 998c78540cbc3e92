"""Name → component registries, filled from Python entry points (one group per family).

Design: pyproject.toml's `[project.entry-points."ocpkit.<family>"]` tables are the one list of built-in
components (name = "module:object"), and third-party packages add theirs to the same groups in their own
metadata. A registry resolves a name through the entry points and loads (imports) only what is asked for.

Where ocpkit's own entry points come from:
- Running from a source checkout (pyproject.toml naming project `ocpkit` next to the package, as in the
  repository with `PYTHONPATH=.` or an editable install), they are read from that pyproject.toml, so a
  component declared there is found without (re)installing, and stale ocpkit metadata (an old
  `ocpkit.egg-info`, an outdated install) is ignored. Needs `tomllib` (Python ≥ 3.11); on 3.10 the
  installed metadata is used instead.
- Otherwise (a wheel install) from the installed distribution's metadata, as for any package.

Entry points are scanned anew whenever a name is not yet loaded (importlib.metadata notices new
distributions on sys.path), so components installed after the first lookup are found; loaded components are
cached. `register` adds a component at run time without packaging (a notebook, a test).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path
from typing import Any, Generic, TypeVar

from ocpkit.errors import OptionError, RegistryError

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: no TOML reader in the standard library
    tomllib = None

T = TypeVar("T")

_PYPROJECT = Path(__file__).resolve().parent.parent / "pyproject.toml"


@functools.cache
def _source_entry_points() -> tuple[EntryPoint, ...] | None:
    """ocpkit's own entry points from the source checkout's pyproject.toml; None when not in a checkout."""
    if tomllib is None or not _PYPROJECT.is_file():
        return None
    project = tomllib.loads(_PYPROJECT.read_text(encoding="utf-8")).get("project", {})
    if project.get("name") != "ocpkit":
        return None
    return tuple(EntryPoint(name, value, group)
                 for group, points in project.get("entry-points", {}).items() for name, value in points.items())


def _entry_points(group: str) -> list[EntryPoint]:
    """Every entry point of `group`: ocpkit's own (see the module docstring), then other packages'."""
    installed = entry_points(group=group)
    own = _source_entry_points()
    if own is None:
        return list(installed)
    return [p for p in own if p.group == group] + [p for p in installed if p.dist.name != "ocpkit"]


class Registry(Generic[T]):
    """Components of one family (e.g. transcriptions) keyed by a short name, from entry-point group `group`."""

    def __init__(self, family: str, group: str) -> None:
        self.family, self.group = family, group
        self._items: dict[str, T] = {}

    def register(self, name: str, item: T) -> T:
        """Add `item` under `name` at run time; returns it, so it can decorate a class."""
        self._items[name] = item
        return item

    def get(self, name: str) -> T:
        """The component called `name`; RegistryError lists the known names if there is none."""
        if name not in self._items:
            values = {p.value: p for p in _entry_points(self.group) if p.name == name}
            if not values:
                raise RegistryError(f"unknown {self.family} {name!r}; known: {', '.join(self.names())}")
            if len(values) > 1:
                raise RegistryError(f"{self.family} {name!r} is declared more than once: {', '.join(values)}")
            self._items[name] = next(iter(values.values())).load()
        return self._items[name]

    def names(self) -> list[str]:
        """Every known name: from entry points and registered at run time."""
        return sorted(set(self._items) | {p.name for p in _entry_points(self.group)})

    def description(self, name: str, width: int | None = None) -> str:
        """One line about the component `name`: the first sentence of its docstring, cut to `width` characters
        (ending in "…") when it is longer (loads the component)."""
        return summary(inspect.getdoc(self.get(name)) or "", width)


def summary(doc: str, width: int | None = None) -> str:
    """The first sentence of `doc` on one line: up to the first full stop outside brackets and backticks that
    ends the first paragraph or is followed by a space and no lower-case letter (so "e.g. x" and "(et al.)" do
    not end it); cut at a word boundary to at most `width` characters, ending in "…", if it is longer."""
    text = " ".join(doc.split("\n\n")[0].split())
    depth, quoted = 0, False
    for i, char in enumerate(text):
        if char == "`":
            quoted = not quoted
        elif not quoted and char in "([{":
            depth += 1
        elif not quoted and char in ")]}":
            depth = max(depth - 1, 0)
        elif char == "." and depth == 0 and not quoted and (i + 1 == len(text) or text[i + 1] == " " and
                                                            not text[i + 2:i + 3].islower()):
            text = text[:i + 1]
            break
    if width is None or len(text) <= width:
        return text
    cut = text[:width - 1]
    if " " in cut and text[width - 1] != " ":
        cut = cut[:cut.rindex(" ")]
    return cut.rstrip(" ,;:") + "…"


def construct(component: Callable, name: str, options: dict) -> Any:
    """`component(**options)`; an option it does not take is the user's mistake, reported as an OptionError."""
    try:
        return component(**options)
    except TypeError as exc:
        raise OptionError(f"{name}: {exc} (options given: {sorted(options)})") from exc

