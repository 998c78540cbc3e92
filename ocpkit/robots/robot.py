"""The robot model: kinematic tree (pinocchio), actuator limits, friction and collision spheres."""

from __future__ import annotations

import functools
import hashlib
import itertools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from ocpkit.errors import RobotError, within
from ocpkit.formats.schema import ROBOT, SPEC, check, read_yaml, show
from ocpkit.robots.friction import friction_slope, friction_torque
from ocpkit.robots.urdf import model_from_urdf, resolve_urdf

DATA_DIR = Path(__file__).parent / "data"


@dataclass(frozen=True, eq=False)
class Robot:
    """A serial robot with n joints and M collision spheres (SI units, radians).

    `model` holds only the listed joints (the others are locked at the spec's `locked` values, default 0; the
    URDF root sits at the spec's `base` pose). Sphere j is rigidly attached to
    pinocchio joint `sphere_joint[j]` (0 = universe) at `sphere_offset[j]` (metres, in that joint's frame).
    `key` identifies the content it was built from (sha256 hex of the URDF and spec files' bytes); Robots
    compare and hash by identity, and `robot_from_files` returns one object per key.
    """

    name: str
    key: str
    model: pin.Model
    joint_names: tuple[str, ...]
    q_lower: np.ndarray  # (n,) rad
    q_upper: np.ndarray  # (n,) rad
    qd_max: np.ndarray  # (n,) rad/s
    tau_max: np.ndarray  # (n,) N m
    taud_max: np.ndarray  # (n,) N m / s
    gear_ratios: np.ndarray  # (n,)
    viscous: np.ndarray  # (n,) N m s / rad
    coulomb: np.ndarray  # (n,) N m
    friction_smoothing: float  # rad/s
    sphere_joint: np.ndarray  # (M,) int
    sphere_offset: np.ndarray  # (M, 3) m
    sphere_radius: np.ndarray  # (M,) m
    sphere_link: tuple[str, ...]  # (M,) URDF link names, for messages
    self_collision: np.ndarray  # (P, 2) int, indices into the spheres

    @property
    def n(self) -> int:
        """Number of actuated joints."""
        return len(self.joint_names)

    def friction(self, qd: np.ndarray) -> np.ndarray:
        """Joint friction torque (N m) at velocity qd (rad/s), shape of qd (..., n) (ocpkit.robots.friction)."""
        return friction_torque(qd, self.viscous, self.coulomb, self.friction_smoothing, np.tanh)

    def friction_slope(self, qd: np.ndarray) -> np.ndarray:
        """d friction / d qd (N m s / rad) at velocity qd (rad/s), shape of qd (..., n)."""
        return friction_slope(qd, self.viscous, self.coulomb, self.friction_smoothing, np.tanh)


def builtin_robots() -> list[str]:
    """Names of the robots shipped with ocpkit."""
    return sorted(p.name for p in DATA_DIR.iterdir() if (p / "spec.yaml").exists())


def load_robot(robot: str | dict[str, Any], base_dir: Path | None = None) -> Robot:
    """Load a built-in robot by name, `{urdf: path, spec: path}` or `{spec: path}` when the spec names its URDF
    (relative paths start at base_dir)."""
    check(robot, ROBOT, RobotError, "robot")
    if isinstance(robot, dict):
        base = base_dir or Path.cwd()
        if "urdf" in robot:
            return robot_from_files(base / robot["urdf"], base / robot["spec"])
        return robot_from_spec(base / robot["spec"])
    if robot not in builtin_robots():
        raise RobotError(f"unknown robot {show(robot)}; built-in robots: {', '.join(builtin_robots())}; "
                         "a robot of your own is {urdf: path, spec: path} or {spec: path}")
    folder = DATA_DIR / robot
    if (folder / "robot.urdf").exists():
        return robot_from_files(folder / "robot.urdf", folder / "spec.yaml")
    return robot_from_spec(folder / "spec.yaml")


def robot_from_spec(spec_file: Path) -> Robot:
    """Build a Robot from a spec.yaml whose `urdf:` names its URDF (ocpkit.robots.urdf.resolve_urdf)."""
    spec_file = Path(spec_file)
    return robot_from_files(resolve_urdf(_urdf_entry(spec_file, _read(spec_file)), spec_file.parent), spec_file)


@functools.lru_cache(maxsize=16)  # a spherized spec is long to parse: once per content, not once per scenario
def _urdf_entry(spec_file: Path, text: bytes) -> str:
    """The `urdf:` entry of a spec file's text, schema-checked (RobotError naming the file otherwise)."""
    with within(spec_file):
        spec = read_yaml(text, RobotError)
        check(spec, SPEC, RobotError)
        if "urdf" not in spec:
            raise RobotError("missing 'urdf' (the spec names no URDF; give the robot as {urdf: path, spec: path})")
    return spec["urdf"]


CACHE_SIZE = 16
"""How many Robots `robot_from_files` keeps by content key."""
_BY_KEY: dict[str, Robot] = {}


def robot_from_files(urdf: Path, spec_file: Path) -> Robot:
    """Build a Robot from a URDF and a spec.yaml (docs/formats.md, 'Robot files'; ocpkit.formats.schema.SPEC).

    Both files are read anew on every call; identical content gives the same Robot object (a bounded cache by
    content key), so problems on one robot share one Robot and its builds, and an edited file a new Robot."""
    urdf_bytes, spec_bytes = _read(Path(urdf)), _read(Path(spec_file))
    key = _content_key(urdf_bytes, spec_bytes)
    if key not in _BY_KEY:
        _remember(_build(urdf_bytes, spec_bytes, key, Path(urdf), Path(spec_file)))
    return _BY_KEY[key]


def _content_key(urdf: bytes, spec: bytes) -> str:
    """sha256 hex digest of a URDF's and a spec file's bytes (each length-prefixed, so no two pairs collide)."""
    digest = hashlib.sha256()
    for data in (urdf, spec):
        digest.update(len(data).to_bytes(8, "little"))
        digest.update(data)
    return digest.hexdigest()


def _read(path: Path) -> bytes:
    if not path.is_file():
        raise RobotError(f"robot file not found: {path}")
    try:
        return path.read_bytes()
    except OSError as exc:
        raise RobotError(f"cannot read robot file {path}: {exc.strerror}") from exc


def _remember(robot: Robot) -> None:
    """Cache `robot` by its key, dropping the oldest entries beyond CACHE_SIZE."""
    _BY_KEY[robot.key] = robot
    while len(_BY_KEY) > CACHE_SIZE:
        del _BY_KEY[next(iter(_BY_KEY))]


def _build(urdf_bytes: bytes, spec_bytes: bytes, key: str, urdf: Path, spec_file: Path) -> Robot:
    """The Robot of these file contents; the paths only name the files in error messages."""
    full = model_from_urdf(urdf_bytes, urdf)
    with within(spec_file):
        spec = read_yaml(spec_bytes, RobotError)
        check(spec, SPEC, RobotError)
        return _robot_from_spec(full, spec, key)


def _vector(spec: dict, path: str, n: int) -> np.ndarray:
    """The (n,) array at dotted `path` of a schema-checked spec."""
    value: Any = spec
    for key in path.split("."):
        value = value[key]
    if len(value) != n:
        raise RobotError(f"'{path}' needs {n} values, one per joint, got {len(value)}: {show(value)}")
    return np.asarray(value, dtype=float)


def _robot_from_spec(full: pin.Model, spec: dict, key: str) -> Robot:
    """The Robot of a schema-checked spec on the URDF's model `full`."""
    joints = tuple(spec["joints"])
    place_base(full, spec.get("base", {}))
    model = reduced_model(full, joints, spec.get("locked", {}))
    n = len(joints)
    vec = functools.partial(_vector, spec, n=n)
    joint_of, offset, radius, link = _spheres(model, spec.get("spheres", []))
    robot = Robot(
        name=spec["name"], key=key, model=model, joint_names=joints,
        q_lower=vec("limits.position.lower"), q_upper=vec("limits.position.upper"),
        qd_max=vec("limits.velocity"), tau_max=vec("limits.torque"), taud_max=vec("limits.torque_rate"),
        gear_ratios=vec("gear_ratios"), viscous=vec("friction.viscous"), coulomb=vec("friction.coulomb"),
        friction_smoothing=float(spec["friction"]["smoothing"]), sphere_joint=joint_of, sphere_offset=offset,
        sphere_radius=radius, sphere_link=link, self_collision=_pairs(spec.get("self_collision", []), len(radius)),
    )
    _check_position_limits(robot)
    return robot


def place_base(model: pin.Model, base: dict) -> None:
    """Move the URDF root of `model` (in place) to the schema-checked `base` pose: xyz (m), rpy (rad), default 0."""
    pose = pin.SE3(pin.rpy.rpyToMatrix(*base.get("rpy", [0.0, 0.0, 0.0])), np.asarray(base.get("xyz", [0.0] * 3)))
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            model.jointPlacements[j] = pose * model.jointPlacements[j]
    for k, frame in enumerate(model.frames):
        if frame.parentJoint == 0 and k > 0:
            frame.placement = pose * frame.placement
            model.frames[k] = frame


def reduced_model(full: pin.Model, joints: tuple[str, ...], locked: dict[str, float]) -> pin.Model:
    """`full` with every joint but `joints` (URDF names, in tree order) locked at its `locked` value (default:
    its neutral position, 0)."""
    missing = [j for j in joints if not full.existJointName(j)]
    if missing:
        raise RobotError(f"joints not in the URDF: {missing}")
    keep = [full.getJointId(j) for j in joints]
    if any(a >= b for a, b in itertools.pairwise(keep)):
        raise RobotError(f"'joints' must follow the URDF tree order {list(full.names[1:])}, each joint once")
    reference = pin.neutral(full)
    for name, value in locked.items():
        if not full.existJointName(name):
            raise RobotError(f"locked.{name}: not a movable joint of the URDF; its movable joints: "
                             f"{list(full.names[1:])}")
        if name in joints:
            raise RobotError(f"locked.{name}: a planned joint (in 'joints') cannot be locked")
        joint = full.joints[full.getJointId(name)]
        if joint.nq != 1:
            raise RobotError(f"locked.{name}: only 1-DoF joints can be locked at a value (nq={joint.nq})")
        reference[joint.idx_q] = value
    fixed = [j for j in range(1, full.njoints) if j not in keep]
    model = pin.buildReducedModel(full, fixed, reference) if fixed else full
    if model.nq != len(joints) or model.nv != len(joints):
        raise RobotError(f"only 1-DoF joints are supported (nq={model.nq}, nv={model.nv})")
    return model


def _check_position_limits(robot: Robot) -> None:
    for i in np.nonzero(robot.q_lower >= robot.q_upper)[0]:
        raise RobotError(f"limits.position.lower[{i}] = {robot.q_lower[i]} must be below limits.position.upper[{i}] "
                         f"= {robot.q_upper[i]} (joint {robot.joint_names[i]})")


def _pairs(pairs: list[list[int]], count: int) -> np.ndarray:
    """The (P, 2) index array of schema-checked self_collision pairs among `count` spheres."""
    for k, (a, b) in enumerate(pairs):
        if max(a, b) >= count or a == b:
            raise RobotError(f"self_collision index outside the {count} spheres or a sphere paired with itself: "
                             f"self_collision[{k}] = {show([a, b])}")
    return np.asarray(pairs, dtype=int).reshape(-1, 2)


def _spheres(model: pin.Model, spheres: list[dict]):
    """Parent joint (M,), offset in that joint's frame (M, 3), radius (M,) and link name of schema-checked spheres."""
    joint_of, offset, radius, link = [], [], [], []
    for k, sphere in enumerate(spheres):
        name = sphere["link"]
        if not model.existFrame(name):
            raise RobotError(f"spheres[{k}] is on unknown link {show(name)}")
        frame = model.frames[model.getFrameId(name)]
        joint_of.append(frame.parentJoint)
        offset.append(frame.placement.act(np.asarray(sphere["center"], dtype=float)))
        radius.append(float(sphere["radius"]))
        link.append(name)
    return (np.asarray(joint_of, dtype=int), np.asarray(offset, dtype=float).reshape(-1, 3),
            np.asarray(radius, dtype=float), tuple(link))
