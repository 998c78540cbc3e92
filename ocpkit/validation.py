"""Checks every Problem gets before planning, however it was made (a scenario file or Python).

First the numbers alone (shapes, finiteness, signs, order; the same messages as for a scenario file), then what
needs the robot: joint limits, collisions, the torque that holds start and goal against gravity, and t_f against
the velocity limits."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pinocchio as pin

from ocpkit.errors import ScenarioError
from ocpkit.formats.schema import COST, OBSTACLE, TIME, WORKSPACE, check, show
from ocpkit.geometry.clearances import collision_report
from ocpkit.geometry.scene import Scene
from ocpkit.problem import Problem, TimeBounds
from ocpkit.robots import Robot

LIMIT_SLACK = 1e-9  # rad: a start or goal exactly at a limit, given in degrees, must not fail on round-off
SHOWN_CONTACTS = 3  # contacts named in a start/goal collision error; the rest are counted
ROTATION_TOLERANCE = 1e-6  # an obstacle's rotation matrix must be orthonormal to this
GRAVITY_SLACK = 1e-6  # relative: holding torque may exceed tau_max by round-off only


def validate(problem: Problem) -> None:
    """Raise ScenarioError naming the field if a number is malformed, start or goal is outside the joint limits,
    in collision or cannot be held against gravity, or t_f is impossible."""
    robot = problem.robot
    points = {label: _joint_values(getattr(problem, label), label, robot.n) for label in ("start", "goal")}
    check({"mu": problem.mu}, COST, ScenarioError, "cost")
    _check_time(problem.time)
    _check_scene(problem.scene)
    for label, q in points.items():
        _check_limits(robot, q, label)
        contacts = collision_report(robot, problem.scene, q)
        if contacts:
            more = f"; and {len(contacts) - SHOWN_CONTACTS} more" if len(contacts) > SHOWN_CONTACTS else ""
            raise ScenarioError(f"{label} configuration is in collision: " + "; ".join(contacts[:SHOWN_CONTACTS])
                                + more)
        _check_gravity(robot, q, label)
    lower_bound = problem.velocity_lower_bound()
    if problem.time.max < lower_bound:
        raise ScenarioError(f"time.max = {problem.time.max} s is below the velocity-limited minimum "
                            f"{lower_bound:.3f} s (max_i |goal_i - start_i| / qd_max_i)")


def _float_array(value: Any, label: str) -> np.ndarray:
    """`value` itself if it is a numpy array of numbers; ScenarioError naming `label` otherwise."""
    if not (isinstance(value, np.ndarray) and value.dtype.kind in "fiu"):
        raise ScenarioError(f"{label} must be a numpy array of numbers, got {show(value)}")
    return value


def _joint_values(value: Any, label: str, n: int) -> np.ndarray:
    """Start or goal (rad): n finite values."""
    q = _float_array(value, label)
    if q.shape != (n,) or not np.all(np.isfinite(q)):
        raise ScenarioError(f"{label} needs {n} finite joint values, got {show(q.tolist())}")
    return q


def _check_time(t: TimeBounds) -> None:
    """Each bound finite and > 0 (seconds), min ≤ max and min ≤ guess ≤ max."""
    check(dataclasses.asdict(t), TIME, ScenarioError, "time")
    if not t.min <= t.max:
        raise ScenarioError(f"time bounds need 0 < min ≤ max, got min={t.min}, max={t.max}")
    if not t.min <= t.guess <= t.max:
        raise ScenarioError(f"time.guess = {t.guess} must lie in [{t.min}, {t.max}]")


def _check_scene(scene: Scene) -> None:
    """Obstacle centres (S, 3) finite, radii (S,) finite and > 0; workspace corners (3,) finite, min < max (m)."""
    centers = _float_array(scene.obstacle_centers, "scene.obstacle_centers")
    radii = _float_array(scene.obstacle_radii, "scene.obstacle_radii")
    if centers.ndim != 2 or centers.shape[1] != 3 or radii.shape != centers.shape[:1]:
        raise ScenarioError(f"scene: obstacle centres need shape (S, 3) and radii (S,), got {centers.shape} and "
                            f"{radii.shape}")
    for k, (center, radius) in enumerate(zip(centers.tolist(), radii.tolist())):
        check({"sphere": {"center": center, "radius": radius}}, OBSTACLE, ScenarioError, f"scene.obstacles[{k}]")
    _check_primitives(scene)
    if scene.workspace is not None:
        lower = _float_array(scene.workspace.lower, "scene.workspace.min")
        upper = _float_array(scene.workspace.upper, "scene.workspace.max")
        check({"min": lower.tolist(), "max": upper.tolist()}, WORKSPACE, ScenarioError, "scene.workspace")
        if np.any(lower >= upper):
            raise ScenarioError(f"scene.workspace: min {lower} must be below max {upper}")


def _check_primitives(scene: Scene) -> None:
    """Boxes and cylinders: centres (N, 3) finite, sizes, radii and lengths finite and > 0 (m), rotations (N, 3, 3)
    proper (orthonormal, det +1, within ROTATION_TOLERANCE); `names` one per obstacle if given."""
    parts = {"boxes": {"centers": 3, "sizes": 3}, "cylinders": {"centers": 3, "radii": 0, "lengths": 0}}
    for kind, fields in parts.items():
        group = getattr(scene, kind)
        count = len(_float_array(group.centers, f"scene.{kind}.centers"))
        for name, width in fields.items():
            values = _float_array(getattr(group, name), f"scene.{kind}.{name}")
            if values.shape != ((count, width) if width else (count,)) or not np.all(np.isfinite(values)):
                raise ScenarioError(f"scene.{kind}.{name} needs {count} finite values of width {width or 1}, got "
                                    f"shape {values.shape}: {show(values.tolist())}")
            if name != "centers" and np.any(values <= 0):
                raise ScenarioError(f"scene.{kind}.{name} must be > 0, got {show(values.tolist())}")
        rotations = _float_array(group.rotations, f"scene.{kind}.rotations")
        if rotations.shape != (count, 3, 3) or not np.all(np.isfinite(rotations)):
            raise ScenarioError(f"scene.{kind}.rotations needs shape ({count}, 3, 3), got {rotations.shape}")
        for k, rotation in enumerate(rotations):
            if (np.abs(rotation.T @ rotation - np.eye(3)).max() > ROTATION_TOLERANCE
                    or abs(np.linalg.det(rotation) - 1) > ROTATION_TOLERANCE):
                raise ScenarioError(f"scene.{kind}.rotations[{k}] is not a rotation matrix: {show(rotation.tolist())}")
    if scene.names and len(scene.names) != scene.n_obstacles:
        raise ScenarioError(f"scene.names needs one name per obstacle ({scene.n_obstacles}), got {len(scene.names)} "
                            "(replace the names with the obstacles, or set names=())")


def _check_limits(robot: Robot, q: np.ndarray, label: str) -> None:
    outside = (q < robot.q_lower - LIMIT_SLACK) | (q > robot.q_upper + LIMIT_SLACK)
    for i in np.nonzero(outside)[0]:
        raise ScenarioError(
            f"{label}: joint {i + 1} ({robot.joint_names[i]}) = {np.degrees(q[i]):.2f} deg is outside "
            f"[{np.degrees(robot.q_lower[i]):.2f}, {np.degrees(robot.q_upper[i]):.2f}] deg")


def _check_gravity(robot: Robot, q: np.ndarray, label: str) -> None:
    """The torque holding q at rest, rnea(q, 0, 0) + friction(0) (N m), must lie within tau_max."""
    zero = np.zeros(robot.n)
    hold = pin.rnea(robot.model, robot.model.createData(), q, zero, zero) + robot.friction(zero)
    for i in np.nonzero(np.abs(hold) > robot.tau_max * (1 + GRAVITY_SLACK))[0]:
        raise ScenarioError(f"{label}: joint {i + 1} ({robot.joint_names[i]}) needs {abs(hold[i]):.1f} N m to hold "
                            f"it against gravity, above its torque limit {robot.tau_max[i]:.1f} N m")
