"""Load and validate scenario YAML files (format in docs/formats.md, 'Scenario files'; schema in ocpkit.formats.schema)
into a Problem.

Defaults: scene empty, time.min 0.1 s, time.max 10 s, time.guess min(10 s, time.max) but never below time.min,
cost.mu 0.3, name the file's stem.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ocpkit.errors import ScenarioError, within
from ocpkit.formats.schema import SCENARIO, check, read_bytes, read_yaml, show
from ocpkit.geometry.quaternion import IDENTITY, quaternion_matrix
from ocpkit.geometry.scene import Boxes, Cylinders, Scene, Workspace
from ocpkit.problem import Problem, TimeBounds
from ocpkit.robots import load_robot
from ocpkit.validation import validate

DEFAULT_GUESS = 10.0
"""time.guess (s) when the file gives none, clipped into [time.min, time.max]."""


def load_scenario(path: str | Path) -> Problem:
    """Read a scenario file and return its validated Problem; raises ScenarioError naming what is wrong."""
    path = Path(path)
    text = read_bytes(path, ScenarioError, "scenario")
    with within(path):
        return problem_from_dict(read_yaml(text, ScenarioError), base_dir=path.parent, name=path.stem)


def problem_from_dict(data: Any, base_dir: Path | None = None, name: str = "problem") -> Problem:
    """Build and validate a Problem from a parsed scenario mapping (relative robot paths start at base_dir)."""
    check(data, SCENARIO, ScenarioError)
    robot = load_robot(data["robot"], base_dir)
    scale = np.pi / 180.0 if data["unit"] == "deg" else 1.0
    start = _joint_values(data["start"], "start", robot.n) * scale
    goal = _joint_values(data["goal"], "goal", robot.n) * scale
    cost = data.get("cost", {})
    problem = Problem(robot, start, goal, _scene(data.get("scene", {})), _time(data.get("time", {})),
                      float(cost.get("mu", 0.3)), data.get("name", name))
    validate(problem)
    return problem


def _joint_values(values: list, where: str, n: int) -> np.ndarray:
    """The (n,) float array of a schema-checked list of numbers."""
    if len(values) != n:
        raise ScenarioError(f"'{where}' needs shape ({n},), got ({len(values)},): {show(values)}")
    return np.asarray(values, dtype=float)


def _scene(data: dict) -> Scene:
    """The Scene of a schema-checked `scene` mapping; obstacles are named by their place in the file."""
    listed = list(enumerate(data.get("obstacles", [])))
    by_kind = {kind: [(k, item[kind]) for k, item in listed if kind in item] for kind in ("sphere", "box", "cylinder")}
    spheres, boxes, cylinders = (by_kind[kind] for kind in ("sphere", "box", "cylinder"))
    names = tuple(_obstacle_name(k, body, kind) for kind, items in by_kind.items() for k, body in items)
    box = data.get("workspace")
    workspace = None if box is None else Workspace(np.asarray(box["min"], dtype=float),
                                                   np.asarray(box["max"], dtype=float))
    return Scene(_vectors(spheres, "center"), _numbers(spheres, "radius"), workspace,
                 Boxes(_vectors(boxes, "center"), _vectors(boxes, "size"), _rotations(boxes)),
                 Cylinders(_vectors(cylinders, "center"), _numbers(cylinders, "radius"), _numbers(cylinders, "length"),
                           _rotations(cylinders)), names)


def _obstacle_name(k: int, body: dict, kind: str) -> str:
    """'obstacle 3 (box)', or 'obstacle 3 (box 'table')' when the file names it."""
    return f"obstacle {k} ({kind} {body['name']!r})" if "name" in body else f"obstacle {k} ({kind})"


def _vectors(items: list[tuple[int, dict]], key: str) -> np.ndarray:
    """The (N, 3) array of field `key` of each obstacle body."""
    return np.asarray([body[key] for _, body in items], dtype=float).reshape(-1, 3)


def _numbers(items: list[tuple[int, dict]], key: str) -> np.ndarray:
    """The (N,) array of field `key` of each obstacle body."""
    return np.asarray([body[key] for _, body in items], dtype=float)


def _rotations(items: list[tuple[int, dict]]) -> np.ndarray:
    """The (N, 3, 3) rotation matrices of each body's `orientation` quaternion [x, y, z, w] (identity if absent)."""
    return np.asarray([quaternion_matrix(body.get("orientation", IDENTITY)) for _, body in items],
                      dtype=float).reshape(-1, 3, 3)


def _time(data: dict) -> TimeBounds:
    """The TimeBounds of a schema-checked `time` mapping, with the defaults of the module docstring."""
    default = TimeBounds()
    t_min, t_max = float(data.get("min", default.min)), float(data.get("max", default.max))
    return TimeBounds(t_min, t_max, float(data.get("guess", max(t_min, min(DEFAULT_GUESS, t_max)))))
