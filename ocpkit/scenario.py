"""Load and validate scenario YAML files (format in README, section 'Scenario files') into a Problem."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ocpkit.errors import OcpkitError, ScenarioError
from ocpkit.problem import Problem, TimeBounds
from ocpkit.robots import load_robot
from ocpkit.scene import Scene, Workspace
from ocpkit.validation import validate

_KEYS = {"robot", "unit", "start", "goal", "scene", "time", "cost", "name"}


def load_scenario(path: str | Path) -> Problem:
    """Read a scenario file and return its validated Problem; raises ScenarioError naming what is wrong."""
    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise ScenarioError(f"cannot read scenario {path}: {exc.strerror}") from exc
    except yaml.YAMLError as exc:
        raise ScenarioError(f"{path}: malformed YAML: {exc}") from exc
    try:
        return problem_from_dict(data, base_dir=path.parent, name=path.stem)
    except OcpkitError as exc:
        raise type(exc)(f"{path}: {exc}") from exc


def problem_from_dict(data: Any, base_dir: Path | None = None, name: str = "problem") -> Problem:
    """Build and validate a Problem from a parsed scenario mapping."""
    if not isinstance(data, dict):
        raise ScenarioError("a scenario must be a mapping with keys robot, unit, start, goal, ...")
    unknown = set(data) - _KEYS
    if unknown:
        raise ScenarioError(f"unknown keys {sorted(unknown)}; allowed: {sorted(_KEYS)}")
    for key in ("robot", "unit", "start", "goal"):
        if key not in data:
            raise ScenarioError(f"missing '{key}'")
    robot = load_robot(data["robot"], base_dir)
    unit = data["unit"]
    if unit not in ("deg", "rad"):
        raise ScenarioError(f"unit must be 'deg' or 'rad', got {unit!r}")
    scale = np.pi / 180.0 if unit == "deg" else 1.0
    start = _numbers(data["start"], "start", (robot.n,)) * scale
    goal = _numbers(data["goal"], "goal", (robot.n,)) * scale
    scene = _scene(data.get("scene") or {})
    time = _time(data.get("time") or {})
    mu = float(_mapping(data.get("cost") or {}, "cost").get("mu", 0.3))
    if mu < 0:
        raise ScenarioError(f"cost.mu must be ≥ 0, got {mu}")
    problem = Problem(robot, start, goal, scene, time, mu, str(data.get("name", name)))
    validate(problem)
    return problem


def _mapping(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise ScenarioError(f"'{where}' must be a mapping, got {value!r}")
    return value


def _numbers(value: Any, where: str, shape: tuple[int, ...]) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"'{where}' must be numbers, got {value!r}") from exc
    if array.shape != shape:
        raise ScenarioError(f"'{where}' needs shape {shape}, got {array.shape}: {value!r}")
    if not np.all(np.isfinite(array)):
        raise ScenarioError(f"'{where}' must be finite, got {value!r}")
    return array


def _scene(data: Any) -> Scene:
    data = _mapping(data, "scene")
    centers, radii = [], []
    for k, item in enumerate(data.get("obstacles") or []):
        sphere = _mapping(_mapping(item, f"scene.obstacles[{k}]").get("sphere"), f"scene.obstacles[{k}].sphere")
        centers.append(_numbers(sphere.get("center"), f"scene.obstacles[{k}].sphere.center", (3,)))
        radius = float(_numbers(sphere.get("radius"), f"scene.obstacles[{k}].sphere.radius", ()))
        if radius <= 0:
            raise ScenarioError(f"scene.obstacles[{k}].sphere.radius must be > 0, got {radius}")
        radii.append(radius)
    workspace = None
    if data.get("workspace") is not None:
        box = _mapping(data["workspace"], "scene.workspace")
        lower = _numbers(box.get("min"), "scene.workspace.min", (3,))
        upper = _numbers(box.get("max"), "scene.workspace.max", (3,))
        if np.any(lower >= upper):
            raise ScenarioError(f"scene.workspace: min {lower} must be below max {upper}")
        workspace = Workspace(lower, upper)
    return Scene(np.asarray(centers, dtype=float).reshape(-1, 3), np.asarray(radii, dtype=float), workspace)


def _time(data: Any) -> TimeBounds:
    data = _mapping(data, "time")
    default = TimeBounds()
    values = {key: float(_numbers(data.get(key, getattr(default, key)), f"time.{key}", ())) for key in
              ("min", "max", "guess")}
    bounds = TimeBounds(**values)
    if not 0 < bounds.min <= bounds.max:
        raise ScenarioError(f"time bounds need 0 < min ≤ max, got min={bounds.min}, max={bounds.max}")
    if not bounds.min <= bounds.guess <= bounds.max:
        raise ScenarioError(f"time.guess = {bounds.guess} must lie in [{bounds.min}, {bounds.max}]")
    return bounds
