"""Load and validate scenario YAML files (format in README, section 'Scenario files'; schema in ocpkit.schema)
into a Problem.

Defaults: scene empty, time.min 0.1 s, time.max 10 s, time.guess min(10 s, time.max) but never below time.min,
cost.mu 0.3, name the file's stem.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ocpkit.errors import ScenarioError, within
from ocpkit.problem import Problem, TimeBounds
from ocpkit.robots import load_robot
from ocpkit.scene import Scene, Workspace
from ocpkit.schema import SCENARIO, check, read_yaml, show
from ocpkit.validation import validate

DEFAULT_GUESS = 10.0
"""time.guess (s) when the file gives none, clipped into [time.min, time.max]."""


def load_scenario(path: str | Path) -> Problem:
    """Read a scenario file and return its validated Problem; raises ScenarioError naming what is wrong."""
    path = Path(path)
    try:
        text = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario {path}: {exc.strerror}") from exc
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
    """The Scene of a schema-checked `scene` mapping."""
    spheres = [item["sphere"] for item in data.get("obstacles", [])]
    centers = np.asarray([s["center"] for s in spheres], dtype=float).reshape(-1, 3)
    radii = np.asarray([s["radius"] for s in spheres], dtype=float)
    box = data.get("workspace")
    workspace = None if box is None else Workspace(np.asarray(box["min"], dtype=float),
                                                   np.asarray(box["max"], dtype=float))
    return Scene(centers, radii, workspace)


def _time(data: dict) -> TimeBounds:
    """The TimeBounds of a schema-checked `time` mapping, with the defaults of the module docstring."""
    default = TimeBounds()
    t_min, t_max = float(data.get("min", default.min)), float(data.get("max", default.max))
    return TimeBounds(t_min, t_max, float(data.get("guess", max(t_min, min(DEFAULT_GUESS, t_max)))))
