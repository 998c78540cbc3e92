"""The scenario and robot-spec file formats as one declarative schema, checked recursively before any use.

A schema is a tree of nodes: `Mapping` (required and optional keys; any other key is an error), `Sequence`
(element node, optional exact or minimum length), `Number` (finite, not a boolean, optional sign, optionally integer),
`String`, `Choice` (one of some values), `Tagged` (a one-key mapping `{kind: body}`, e.g. an obstacle
`{sphere: {...}}`; new kinds are new entries) and `OneOf` (the first option whose type fits the value).
`check(data, node, error)` walks it and raises `error` naming the full path of the offending field
(`scene.obstacles[0].sphere.radius`) and its value, truncated to about 80 characters. Checks that need the robot
or the URDF (vector lengths n, limits, links) are the loaders' and `ocpkit.validation`'s.
"""

from __future__ import annotations

import math
import numbers
import operator
import re
import reprlib
from abc import ABC, abstractmethod
from collections.abc import Sequence as SequenceABC
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import yaml

from ocpkit.errors import OcpkitError

SHOWN_CHARS = 80
"""Longest echo of a user's value in an error message, characters."""
_REPR = reprlib.Repr()
_REPR.maxstring = _REPR.maxother = SHOWN_CHARS
_FLOAT = "tag:yaml.org,2002:float"


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # libyaml's parser where PyYAML was built with it
    """PyYAML's safe loader reading floats by YAML 1.2's core schema: `1.0e6`, `1e-3`, `2e-1` and `.inf` are
    numbers (PyYAML follows YAML 1.1, where an exponent needs a dot and a sign, so `1.0e6` is a string)."""


_Loader.yaml_implicit_resolvers = {first: [(tag, rx) for tag, rx in resolvers if tag != _FLOAT]
                                   for first, resolvers in _Loader.yaml_implicit_resolvers.items()}
_Loader.add_implicit_resolver(_FLOAT, re.compile(r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                                                  r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"),
                              list("-+0123456789."))
Sign = Literal["positive", "non-negative"]
_SIGNS = {"positive": ("> 0", operator.gt), "non-negative": ("≥ 0", operator.ge)}


class _Invalid(Exception):
    """Raised inside the walk; `check` turns it into the caller's error type."""


def show(value: Any) -> str:
    """repr(value) on one line, at most SHOWN_CHARS characters (long containers and strings are cut)."""
    text = _REPR.repr(value)
    return text if len(text) <= SHOWN_CHARS else text[:SHOWN_CHARS - 3] + "..."


def _child(path: str, key: Any) -> str:
    """The path of mapping entry `key` below `path`: `scene.obstacles`."""
    name = key if isinstance(key, str) and key.isprintable() and len(key) <= SHOWN_CHARS else show(key)
    return f"{path}.{name}" if path else name


def _label(path: str) -> str:
    return path or "the file"


class Node(ABC):
    """A schema node: `fits` says whether the value has the right type, `_check_inside` checks its content."""

    @abstractmethod
    def describe(self) -> str:
        """What a fitting value is, for messages: 'a number'."""

    @abstractmethod
    def fits(self, value: Any) -> bool:
        """Whether `value` has this node's type."""

    def check(self, value: Any, path: str) -> None:
        """Raise _Invalid naming `path` if `value` does not match this node."""
        if not self.fits(value):
            raise _Invalid(f"{_label(path)} must be {self.describe()}, got {show(value)}")
        self._check_inside(value, path)

    def _check_inside(self, value: Any, path: str) -> None:
        """Checks beyond the type; none by default."""


@dataclass(frozen=True)
class Number(Node):
    """A finite real number, or with `integer` an integer (not 1.0); booleans are neither. `sign` 'positive'
    (> 0) or 'non-negative' (≥ 0). With `unbounded`, +inf (YAML `.inf`) fits too: "no limit"."""

    sign: Sign | None = None
    integer: bool = False
    unbounded: bool = False

    def describe(self) -> str:
        return "an integer" if self.integer else "a number"

    def fits(self, value: Any) -> bool:
        kind = numbers.Integral if self.integer else numbers.Real
        return isinstance(value, kind) and not isinstance(value, bool)

    def _check_inside(self, value: Any, path: str) -> None:
        if not _finite(value) and not (self.unbounded and value == math.inf):
            allowed = "finite or .inf (no limit)" if self.unbounded else "finite"
            raise _Invalid(f"{_label(path)} must be {allowed}, got {show(value)}")
        _check_sign(self.sign, value, path)


def _finite(value: numbers.Real) -> bool:
    """math.isfinite, with integers too large for a float counted as infinite."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _check_sign(sign: Sign | None, value: numbers.Real, path: str) -> None:
    if sign is not None and not _SIGNS[sign][1](value, 0):
        raise _Invalid(f"{_label(path)} must be {_SIGNS[sign][0]}, got {show(value)}")


@dataclass(frozen=True)
class String(Node):
    """A string; `what` describes it in messages."""

    what: str = "a string"

    def describe(self) -> str:
        return self.what

    def fits(self, value: Any) -> bool:
        return isinstance(value, str)


@dataclass(frozen=True)
class Choice(Node):
    """One of a few fixed values."""

    values: tuple[Any, ...]

    def describe(self) -> str:
        return " or ".join(map(repr, self.values))

    def fits(self, value: Any) -> bool:
        return any(type(value) is type(v) and value == v for v in self.values)


@dataclass(frozen=True)
class Sequence(Node):
    """A list of `element`s: exactly `length` of them if given, at least `min_length`."""

    element: Node
    length: int | None = None
    min_length: int = 0

    def describe(self) -> str:
        count = f"{self.length} " if self.length is not None else ""
        return f"a list of {count}items, each {self.element.describe()}"

    def fits(self, value: Any) -> bool:
        return isinstance(value, SequenceABC) and not isinstance(value, (str, bytes))

    def _check_inside(self, value: Any, path: str) -> None:
        if self.length is not None and len(value) != self.length:
            raise _Invalid(f"{_label(path)} needs {self.length} values, got {len(value)}: {show(value)}")
        if len(value) < self.min_length:
            raise _Invalid(f"{_label(path)} needs at least {self.min_length} values, got {show(value)}")
        for k, item in enumerate(value):
            self.element.check(item, f"{path}[{k}]")


@dataclass(frozen=True)
class Quaternion(Sequence):
    """A rotation as a unit quaternion [x, y, z, w] (ROS order): four finite numbers of norm 1 within `tolerance`."""

    element: Node = Number()
    length: int | None = 4
    tolerance: float = 1e-3

    def _check_inside(self, value: Any, path: str) -> None:
        super()._check_inside(value, path)
        norm = math.sqrt(sum(float(v) ** 2 for v in value))
        if abs(norm - 1.0) > self.tolerance:
            raise _Invalid(f"{_label(path)} must be a unit quaternion [x, y, z, w] (norm 1 within {self.tolerance}), "
                           f"got norm {norm:.6g}: {show(value)}")


def vector(sign: Sign | None = None, length: int | None = None) -> Sequence:
    """A list of finite numbers (see Number for `sign`)."""
    return Sequence(Number(sign), length)


@dataclass(frozen=True)
class Mapping(Node):
    """A mapping with every key of `required`, any of `optional` and no other key."""

    required: dict[str, Node] = field(default_factory=dict)
    optional: dict[str, Node] = field(default_factory=dict)

    def describe(self) -> str:
        return f"a mapping with keys {', '.join(self._allowed())}"

    def fits(self, value: Any) -> bool:
        return isinstance(value, dict)

    def _allowed(self) -> list[str]:
        return sorted({**self.required, **self.optional})

    def _check_inside(self, value: dict, path: str) -> None:
        unknown = sorted(_child(path, key) for key in value if key not in self.required and key not in self.optional)
        if unknown:
            raise _Invalid(f"unknown keys {unknown}; allowed: {self._allowed()}")
        for key in self.required:
            if key not in value:
                raise _Invalid(f"missing '{_child(path, key)}'")
        for key, node in {**self.required, **self.optional}.items():  # in the schema's order, not the file's
            if key in value:
                node.check(value[key], _child(path, key))


@dataclass(frozen=True)
class Tagged(Node):
    """A one-key mapping `{kind: body}` whose kind names a node in `kinds`: `{sphere: {center, radius}}`."""

    kinds: dict[str, Node]

    def describe(self) -> str:
        return " or ".join(f"{{{kind}: ...}}" for kind in self.kinds)

    def fits(self, value: Any) -> bool:
        return isinstance(value, dict) and len(value) == 1 and next(iter(value)) in self.kinds

    def _check_inside(self, value: dict, path: str) -> None:
        kind, body = next(iter(value.items()))
        self.kinds[kind].check(body, _child(path, kind))


@dataclass(frozen=True)
class OneOf(Node):
    """The first of `options` whose type fits the value checks it (e.g. a name or a mapping of files)."""

    options: tuple[Node, ...]

    def describe(self) -> str:
        return " or ".join(option.describe() for option in self.options)

    def fits(self, value: Any) -> bool:
        return any(option.fits(value) for option in self.options)

    def _check_inside(self, value: Any, path: str) -> None:
        next(option for option in self.options if option.fits(value)).check(value, path)


@dataclass(frozen=True)
class Table(Node):
    """A mapping from string keys (names chosen by the user, e.g. URDF joints) to `value` nodes."""

    value: Node

    def describe(self) -> str:
        return f"a mapping of names to values, each {self.value.describe()}"

    def fits(self, value: Any) -> bool:
        return isinstance(value, dict)

    def _check_inside(self, value: dict, path: str) -> None:
        for key, item in value.items():
            if not isinstance(key, str):
                raise _Invalid(f"{_label(path)} keys must be names, got {show(key)}")
            self.value.check(item, _child(path, key))


def check(data: Any, node: Node, error: type[OcpkitError], path: str = "") -> None:
    """Raise `error` naming the offending field if `data` (parsed YAML) does not match `node`."""
    try:
        node.check(data, path)
    except _Invalid as exc:
        raise error(str(exc)) from None


def read_bytes(path: Path, error: type[OcpkitError], what: str) -> bytes:
    """The content of the file at `path`; `error` naming it ("cannot read <what> <path>: reason") if unreadable."""
    try:
        return path.read_bytes()
    except OSError as exc:
        raise error(f"cannot read {what} {path}: {exc.strerror}") from exc


def read_yaml(text: bytes, error: type[OcpkitError]) -> Any:
    """Parse UTF-8 YAML bytes; raise `error` with a one-line message (line and column for a syntax error)."""
    try:
        return yaml.load(text.decode("utf-8"), Loader=_Loader)
    except UnicodeDecodeError as exc:
        raise error(f"not UTF-8 text: byte {text[exc.start]:#04x} at offset {exc.start}") from None
    except yaml.MarkedYAMLError as exc:
        raise error(f"malformed YAML at {_mark(exc.problem_mark)}: {exc.problem}"
                    + (f" ({exc.context} at {_mark(exc.context_mark)})" if exc.context else "")) from None
    except yaml.YAMLError as exc:
        raise error(f"malformed YAML: {one_line(str(exc))}") from None
    except RecursionError:
        raise error("malformed YAML: nested too deeply") from None


def _mark(mark: yaml.Mark | None) -> str:
    return f"line {mark.line + 1}, column {mark.column + 1}" if mark else "an unknown place"


def one_line(text: str) -> str:
    """`text` with its whitespace runs (newlines too) collapsed to single spaces, cut to 4 × SHOWN_CHARS."""
    text = " ".join(text.split())
    return text if len(text) <= 4 * SHOWN_CHARS else text[:4 * SHOWN_CHARS - 3] + "..."


ROBOT = OneOf((String("a built-in robot name"), Mapping(required={"spec": String()}, optional={"urdf": String()})))
"""`robot:` in a scenario: a built-in name, or the files of a robot of one's own (`urdf` may be left to the spec)."""

OBSTACLE = Tagged({
    "sphere": Mapping(required={"center": vector(length=3), "radius": Number("positive")},
                      optional={"name": String()}),
    "box": Mapping(required={"center": vector(length=3), "size": vector("positive", 3)},
                   optional={"orientation": Quaternion(), "name": String()}),
    "cylinder": Mapping(required={"center": vector(length=3), "radius": Number("positive"),
                                  "length": Number("positive")},
                        optional={"orientation": Quaternion(), "name": String()}),
})
"""One scene obstacle (metres, world frame; `orientation` a unit quaternion [x, y, z, w], default identity):
`{sphere: {center, radius}}`, `{box: {center, size: full edge lengths [lx, ly, lz], orientation}}` or
`{cylinder: {center, radius, length, orientation}}` (axis along local z); each may carry a `name` for messages."""
WORKSPACE = Mapping(required={"min": vector(length=3), "max": vector(length=3)})
TIME = Mapping(optional={key: Number("positive") for key in ("min", "max", "guess")})
COST = Mapping(optional={"mu": Number("non-negative")})

SCENARIO = Mapping(
    required={"robot": ROBOT, "unit": Choice(("deg", "rad")), "start": vector(), "goal": vector()},
    optional={"name": String(), "scene": Mapping(optional={"obstacles": Sequence(OBSTACLE), "workspace": WORKSPACE}),
              "time": TIME, "cost": COST},
)
"""A scenario file (docs/formats.md, 'Scenario files'); start and goal have the robot's n values (checked on
loading)."""

SPEC = Mapping(
    required={
        "name": String(),
        "joints": Sequence(String(), min_length=1),
        "limits": Mapping(required={
            "position": Mapping(required={"lower": vector(), "upper": vector()}),
            "velocity": vector("positive"), "torque": vector("positive"), "torque_rate": vector("positive"),
        }),
        "gear_ratios": vector("positive"),
        "friction": Mapping(required={"viscous": vector("non-negative"), "coulomb": vector("non-negative"),
                                      "smoothing": Number("positive")}),
    },
    optional={
        "spheres": Sequence(Mapping(required={"link": String(), "center": vector(length=3),
                                              "radius": Number("positive")})),
        "self_collision": Sequence(Sequence(Number("non-negative", integer=True), length=2)),
        "urdf": String("a URDF path (relative to the spec) or example-robot-data:<path>"),
        "locked": Table(Number()),
        "base": Mapping(optional={"xyz": vector(length=3), "rpy": vector(length=3)}),
    },
)
"""A robot spec.yaml (docs/formats.md, 'Robot files'); every vector has one value per joint (checked on loading)."""
