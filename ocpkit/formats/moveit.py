"""MoveIt → scenario: a PlanningScene YAML (its collision objects) and a MotionPlanRequest YAML (its start state and
joint-space goal) become one scenario mapping for a robot whose planned joints are given in order.

Read: `world.collision_objects` (boxes, spheres and cylinders; each primitive's pose composed with its object's
`pose`), the scene's `robot_state` overlaid by the request's `start_state`, and the first of the request's
`goal_constraints` with its `joint_constraints`. Everything else (meshes, planes, cones, other constraints,
tolerances, other joints, planner settings, the allowed-collision matrix, ...) is listed in `Conversion.ignored`.
Poses are taken in the world frame whatever `header.frame_id` says (noted when it names another frame).
Positions are `[x, y, z]` or `{x, y, z}`, orientations `[x, y, z, w]` or `{x, y, z, w}` (both forms occur).
The scenario gets no workspace box and the loader's own time and cost defaults (docs/robots-and-data.md,
'MoveIt scenes').
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ocpkit.errors import MoveItError, RobotError, within
from ocpkit.formats.schema import read_yaml, show
from ocpkit.geometry.quaternion import IDENTITY, quaternion_matrix, quaternion_product
from ocpkit.problem import Problem, TimeBounds
from ocpkit.robots import Robot, load_robot

PRIMITIVE_TYPES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}
"""shape_msgs/SolidPrimitive type numbers; YAML files also spell them as these names."""
REMOVE = 1
"""moveit_msgs/CollisionObject operation REMOVE (ADD 0, APPEND 2, MOVE 3 are taken as they stand)."""
SCENE_KEYS_READ = ("world", "robot_state")
REQUEST_KEYS_READ = ("start_state", "goal_constraints")
OBJECT_KEYS_READ = ("id", "header", "pose", "primitives", "primitive_poses", "operation", "meshes", "mesh_poses",
                    "planes", "plane_poses")  # meshes and planes are counted as ignored


@dataclass(frozen=True)
class Conversion:
    """A scenario mapping (radians, docs/formats.md 'Scenario files') and one line per MoveIt item left out of it."""

    scenario: dict[str, Any]
    ignored: tuple[str, ...]


def convert_moveit(scene: Any, request: Any, joints: Sequence[str], robot: str | dict[str, str],
                   name: str = "problem") -> Conversion:
    """Convert parsed MoveIt `scene` and `request` mappings for a robot whose planned joints are `joints` (in the
    robot's order); `robot` is the scenario's `robot:` entry. Raises MoveItError naming the field at fault."""
    scene, request = _mapping(scene, "the scene"), _mapping(request, "the request")
    ignored: list[str] = []
    world = _mapping(scene.get("world") or {}, "world")
    obstacles = _obstacles(world, ignored)
    start_positions = {**_joint_state(scene.get("robot_state"), "robot_state", ignored),
                       **_joint_state(request.get("start_state"), "start_state", ignored)}
    start = _planned(start_positions, joints, "start state (scene robot_state and request start_state)", ignored)
    goal = _planned(_joint_goal(request.get("goal_constraints"), ignored), joints, "goal_constraints", ignored)
    for label, data, read in (("scene", scene, SCENE_KEYS_READ), ("world", world, ("collision_objects",)),
                              ("request", request, REQUEST_KEYS_READ)):
        unused = sorted(str(key) for key in data if key not in read)
        if unused:
            ignored.append(f"{label}: {', '.join(unused)} not used")
    defaults = TimeBounds()
    mu = next(f.default for f in dataclasses.fields(Problem) if f.name == "mu")
    scenario = {"name": name, "robot": robot, "unit": "rad", "start": start, "goal": goal,
                "scene": {"obstacles": obstacles},
                "time": {"min": defaults.min, "max": defaults.max, "guess": defaults.guess}, "cost": {"mu": mu}}
    return Conversion(scenario, tuple(ignored))


def resolve_robot(robot: str, relative_to: Path, joints: Sequence[str] | None = None
                  ) -> tuple[str | dict[str, str], list[str], Robot | None]:
    """(the scenario's `robot:` entry, the planned joints in order, the Robot if ocpkit can load it) for `robot`, a
    built-in name or a spec.yaml path (written relative to `relative_to`, the scenario's folder; its URDF is the
    spec's own `urdf` entry, else robot.urdf beside it). `joints` replaces the robot's own list, and lets a robot
    name that is not built in here through (unvalidated)."""
    path = Path(robot)
    if path.suffix not in (".yaml", ".yml") and not path.is_file():
        try:
            loaded = load_robot(robot)
        except RobotError as exc:
            if joints is None:
                raise RobotError(f"{exc}; or give the joint names of a robot not built in here") from exc
            return robot, list(joints), None
        return robot, list(joints or loaded.joint_names), loaded
    try:
        spec = read_yaml(path.read_bytes(), RobotError)
    except OSError as exc:
        raise RobotError(f"cannot read robot spec {path}: {exc.strerror}") from exc
    names = spec.get("joints") if isinstance(spec, dict) else None
    if not (isinstance(names, list) and names and all(isinstance(name, str) for name in names)):
        raise RobotError(f"{path}: 'joints' must be a list of joint names, got {show(names)}")
    spec_path = os.path.relpath(path.resolve(), relative_to.resolve())
    if "urdf" in spec:  # a spec naming its own URDF: {spec: path}
        field: dict[str, str] = {"spec": spec_path}
    else:
        field = {"urdf": os.path.relpath((path.parent / "robot.urdf").resolve(), relative_to.resolve()),
                 "spec": spec_path}
    try:
        loaded = load_robot(field, relative_to)
    except RobotError:
        if "urdf" in field:
            raise
        loaded = None
    return field, list(joints or names), loaded


def read_moveit(scene_file: str | Path, request_file: str | Path, joints: Sequence[str],
                robot: str | dict[str, str], name: str | None = None) -> Conversion:
    """`convert_moveit` of two YAML files; the name defaults to the request file's stem."""
    parsed = []
    for path in (Path(scene_file), Path(request_file)):
        try:
            text = path.read_bytes()
        except OSError as exc:
            raise MoveItError(f"cannot read {path}: {exc.strerror}") from exc
        with within(path):
            parsed.append(read_yaml(text, MoveItError))
    with within(f"{scene_file} + {request_file}"):
        return convert_moveit(*parsed, joints, robot, name or Path(request_file).stem)


def scenario_text(conversion: Conversion, comments: Sequence[str] = ()) -> str:
    """The scenario as YAML in the layout of scenarios/paper (one flow-style line per obstacle), preceded by
    `comments` and the ignored items as `#` lines."""
    s = conversion.scenario
    lines = [f"# {line}" for line in comments]
    lines += [f"# ignored: {line}" for line in conversion.ignored]
    for key in ("name", "robot", "unit", "start", "goal"):
        lines.append(f"{key}: {_flow(s[key])}")
    lines.append("scene:")
    lines.append("  obstacles:" + ("" if s["scene"]["obstacles"] else " []"))
    lines += [f"    - {kind}: {_flow(body)}" for item in s["scene"]["obstacles"] for kind, body in item.items()]
    lines += [f"time: {_flow(s['time'])}", f"cost: {_flow(s['cost'])}"]
    return "\n".join(lines) + "\n"


def _flow(value: Any) -> str:
    """One-line YAML of value (floats in full precision)."""
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml's emitter where PyYAML was built with it
    return yaml.dump(value, Dumper=dumper, default_flow_style=True, width=2**31 - 1, sort_keys=False).strip(
        ).removesuffix("\n...").strip()


def _mapping(value: Any, where: str) -> dict:
    if not isinstance(value, dict):
        raise MoveItError(f"{where} must be a mapping, got {show(value)}")
    return value


def _list(value: Any, where: str) -> list:
    if value is None:
        return []
    if not isinstance(value, list):
        raise MoveItError(f"{where} must be a list, got {show(value)}")
    return value


def _numbers(value: Any, keys: str, where: str) -> np.ndarray:
    """A list of len(keys) finite numbers, or a mapping with those keys ('xyz', 'xyzw')."""
    if isinstance(value, dict):
        missing = [k for k in keys if k not in value]
        if missing:
            raise MoveItError(f"{where} needs keys {list(keys)}, got {show(value)}")
        value = [value[k] for k in keys]
    if (not isinstance(value, list) or len(value) != len(keys)
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)):
        raise MoveItError(f"{where} must be {len(keys)} finite numbers [{', '.join(keys)}], got {show(value)}")
    return np.asarray(value, dtype=float)


def _pose(value: Any, where: str) -> tuple[np.ndarray, np.ndarray]:
    """(position (3,) m, unit quaternion (4,) [x, y, z, w]) of a geometry_msgs/Pose; identity if absent."""
    if value is None:
        return np.zeros(3), np.asarray(IDENTITY)
    pose = _mapping(value, where)
    position = _numbers(pose.get("position", [0.0, 0.0, 0.0]), "xyz", f"{where}.position")
    orientation = _numbers(pose.get("orientation", list(IDENTITY)), "xyzw", f"{where}.orientation")
    norm = np.linalg.norm(orientation)
    if not 0.9 < norm < 1.1:
        raise MoveItError(f"{where}.orientation must be a unit quaternion [x, y, z, w], got norm {norm:.4g}")
    return position, orientation / norm


def _obstacles(world: dict, ignored: list[str]) -> list[dict]:
    """Scenario obstacles of world.collision_objects, in file order."""
    obstacles = []
    for i, item in enumerate(_list(world.get("collision_objects"), "world.collision_objects")):
        where = f"world.collision_objects[{i}]"
        obj = _mapping(item, where)
        label = str(obj.get("id") or f"object {i}")
        if obj.get("operation", 0) in (REMOVE, "remove"):
            ignored.append(f"{label}: operation REMOVE")
            continue
        frame = _mapping(obj.get("header") or {}, f"{where}.header").get("frame_id", "")
        if frame not in ("", "world", "/world"):
            ignored.append(f"{label}: header.frame_id {frame!r} (poses taken in the world frame)")
        origin, rotation = _pose(obj.get("pose"), f"{where}.pose")
        primitives = _list(obj.get("primitives"), f"{where}.primitives")
        poses = _list(obj.get("primitive_poses"), f"{where}.primitive_poses")
        if len(poses) != len(primitives):
            raise MoveItError(f"{where}: {len(primitives)} primitives but {len(poses)} primitive_poses")
        for k, (primitive, pose) in enumerate(zip(primitives, poses)):
            position, orientation = _pose(pose, f"{where}.primitive_poses[{k}]")
            center = origin + quaternion_matrix(rotation) @ position
            name = label if len(primitives) == 1 else f"{label}/{k}"
            body = _primitive(_mapping(primitive, f"{where}.primitives[{k}]"), f"{where}.primitives[{k}]",
                              center, quaternion_product(rotation, orientation), name)
            if body is None:
                ignored.append(f"{name}: a cone")
            else:
                obstacles.append(body)
        for key in ("meshes", "planes"):
            count = len(_list(obj.get(key), f"{where}.{key}"))
            if count:
                ignored.append(f"{label}: {count} {key}")
        unused = sorted(str(key) for key in obj if key not in OBJECT_KEYS_READ)
        if unused:
            ignored.append(f"{label}: {', '.join(unused)} not used")
    return obstacles


def _primitive(primitive: dict, where: str, center: np.ndarray, orientation: np.ndarray, name: str) -> dict | None:
    """The scenario obstacle of one SolidPrimitive at (center, orientation); None for a cone."""
    raw = primitive.get("type")
    kind = PRIMITIVE_TYPES.get(raw, raw) if isinstance(raw, (int, str)) else None
    if kind not in PRIMITIVE_TYPES.values():
        raise MoveItError(f"{where}.type must be box, sphere, cylinder or cone (1-4), got {show(raw)}")
    if kind == "cone":
        return None
    sizes = {"box": "xyz", "sphere": "r", "cylinder": "hr"}[kind]  # MoveIt: cylinder [height, radius]
    dimensions = _numbers(primitive.get("dimensions"), sizes, f"{where}.dimensions ({kind})")
    if np.any(dimensions <= 0):
        raise MoveItError(f"{where}.dimensions ({kind}) must be > 0, got {dimensions.tolist()}")
    body: dict[str, Any] = {"center": center.tolist()}
    if kind == "box":
        body["size"] = dimensions.tolist()
    elif kind == "sphere":
        body["radius"] = float(dimensions[0])
    else:
        body["radius"], body["length"] = float(dimensions[1]), float(dimensions[0])
    if kind != "sphere" and not np.allclose(orientation, IDENTITY, atol=1e-12):
        body["orientation"] = orientation.tolist()
    body["name"] = name
    return {kind: body}


def _joint_state(state: Any, where: str, ignored: list[str]) -> dict[str, float]:
    """Joint name → position of a moveit_msgs/RobotState (empty if absent); other parts noted as ignored."""
    if state is None:
        return {}
    state = _mapping(state, where)
    joint_state = _mapping(state.get("joint_state") or {}, f"{where}.joint_state")
    names = _list(joint_state.get("name"), f"{where}.joint_state.name")
    positions = _list(joint_state.get("position"), f"{where}.joint_state.position")
    if len(names) != len(positions):
        raise MoveItError(f"{where}.joint_state: {len(names)} names but {len(positions)} positions")
    for value, name in zip(positions, names):
        if not (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)):
            raise MoveItError(f"{where}.joint_state.position of {name} must be a finite number, got {show(value)}")
    multi = _mapping(state.get("multi_dof_joint_state") or {}, f"{where}.multi_dof_joint_state")
    for k, transform in enumerate(_list(multi.get("transforms"), f"{where}.multi_dof_joint_state.transforms")):
        transform = _mapping(transform, f"{where}.multi_dof_joint_state.transforms[{k}]")
        moved = _numbers(transform.get("translation", [0, 0, 0]), "xyz", f"{where}.multi_dof_joint_state.translation")
        turned = _numbers(transform.get("rotation", list(IDENTITY)), "xyzw", f"{where}.multi_dof_joint_state.rotation")
        if np.any(moved != 0) or np.any(turned != IDENTITY):
            ignored.append(f"{where}: multi-DOF joint transform {k} (the robot base stays at the world origin)")
    if _list(state.get("attached_collision_objects"), f"{where}.attached_collision_objects"):
        ignored.append(f"{where}: attached collision objects")
    return {str(name): float(value) for name, value in zip(names, positions)}


def _joint_goal(constraints: Any, ignored: list[str]) -> dict[str, float]:
    """Joint name → goal position of the first goal constraint that has joint constraints."""
    goals = _list(constraints, "goal_constraints")
    for k, goal in enumerate(goals):
        goal = _mapping(goal, f"goal_constraints[{k}]")
        joints = _list(goal.get("joint_constraints"), f"goal_constraints[{k}].joint_constraints")
        if not joints:
            continue
        if len(goals) > 1:
            ignored.append(f"goal_constraints: {len(goals) - 1} other goal(s) besides goal_constraints[{k}]")
        others = [key for key in ("position_constraints", "orientation_constraints", "visibility_constraints")
                  if goal.get(key)]
        if others:
            ignored.append(f"goal_constraints[{k}]: {', '.join(others)}")
        positions = {}
        for j, joint in enumerate(joints):
            where = f"goal_constraints[{k}].joint_constraints[{j}]"
            joint = _mapping(joint, where)
            if "joint_name" not in joint or "position" not in joint:
                raise MoveItError(f"{where} needs joint_name and position, got {show(joint)}")
            value = joint["position"]
            if not (isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)):
                raise MoveItError(f"{where}.position must be a finite number, got {show(value)}")
            positions[str(joint["joint_name"])] = float(value)
            if any(joint.get(key) for key in ("tolerance_above", "tolerance_below")):
                ignored.append(f"{where}: tolerances (the plan ends at the position exactly)")
        return positions
    raise MoveItError("the request has no goal_constraints with joint_constraints (a joint-space goal)")


def _planned(positions: dict[str, float], joints: Sequence[str], where: str, ignored: list[str]) -> list[float]:
    """Positions of `joints` in order; MoveItError naming a missing joint, the others noted as ignored."""
    missing = [joint for joint in joints if joint not in positions]
    if missing:
        raise MoveItError(f"{where} gives no position for joint {', '.join(missing)} (planned joints: "
                          f"{', '.join(joints)})")
    extra = [f"{name}={value:g}" for name, value in positions.items() if name not in joints]
    if extra:
        ignored.append(f"{where}: joints not planned: {', '.join(extra)}")
    return [positions[joint] for joint in joints]
