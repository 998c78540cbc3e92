"""The robot model: kinematic tree (pinocchio), actuator limits, friction and collision spheres."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import yaml

from ocpkit.errors import RobotError
from ocpkit.robots.friction import friction_slope, friction_torque

DATA_DIR = Path(__file__).parent / "data"


@dataclass(frozen=True, eq=False)
class Robot:
    """A serial robot with n joints and M collision spheres (SI units, radians).

    `model` holds only the listed joints (others are locked at zero). Sphere j is rigidly attached to
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
    """Load a built-in robot by name, or `{urdf: path, spec: path}` (relative paths start at base_dir)."""
    if isinstance(robot, str):
        folder = DATA_DIR / robot
        if not (folder / "spec.yaml").exists():
            raise RobotError(f"unknown robot {robot!r}; built-in robots: {', '.join(builtin_robots())}")
        return robot_from_files(folder / "robot.urdf", folder / "spec.yaml")
    if isinstance(robot, dict) and set(robot) == {"urdf", "spec"}:
        base = base_dir or Path.cwd()
        return robot_from_files(base / robot["urdf"], base / robot["spec"])
    raise RobotError(f"robot must be a built-in name or {{urdf: ..., spec: ...}}, got {robot!r}")


CACHE_SIZE = 16
"""How many Robots `robot_from_files` keeps by content key."""
_BY_KEY: dict[str, Robot] = {}


def robot_from_files(urdf: Path, spec_file: Path) -> Robot:
    """Build a Robot from a URDF and a spec.yaml (schema in README, section 'Robot files').

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
    return path.read_bytes()


def _remember(robot: Robot) -> None:
    """Cache `robot` by its key, dropping the oldest entries beyond CACHE_SIZE."""
    _BY_KEY[robot.key] = robot
    while len(_BY_KEY) > CACHE_SIZE:
        del _BY_KEY[next(iter(_BY_KEY))]


def _build(urdf_bytes: bytes, spec_bytes: bytes, key: str, urdf: Path, spec_file: Path) -> Robot:
    """The Robot of these file contents; the paths only name the files in error messages."""
    try:
        spec = yaml.safe_load(spec_bytes)
        full = pin.buildModelFromXML(urdf_bytes.decode())
    except (yaml.YAMLError, UnicodeDecodeError, ValueError, RuntimeError) as exc:
        raise RobotError(f"cannot read robot files {urdf}, {spec_file}: {exc}") from exc
    return _robot_from_spec(full, spec, key, spec_file)


def _vector(spec: dict, path: str, n: int, spec_file: Path) -> np.ndarray:
    value: Any = spec
    for key in path.split("."):
        if not isinstance(value, dict) or key not in value:
            raise RobotError(f"{spec_file}: missing '{path}'")
        value = value[key]
    array = np.asarray(value, dtype=float)
    if array.shape != (n,):
        raise RobotError(f"{spec_file}: '{path}' needs {n} values, got {np.shape(array)}")
    return array


def _robot_from_spec(full: pin.Model, spec: dict, key: str, spec_file: Path) -> Robot:
    if not isinstance(spec, dict) or "joints" not in spec or "name" not in spec:
        raise RobotError(f"{spec_file}: needs at least 'name' and 'joints'")
    joints = tuple(spec["joints"])
    missing = [j for j in joints if not full.existJointName(j)]
    if missing:
        raise RobotError(f"{spec_file}: joints not in the URDF: {missing}")
    keep = [full.getJointId(j) for j in joints]
    if keep != sorted(keep):
        raise RobotError(f"{spec_file}: 'joints' must follow the URDF tree order {list(full.names[1:])}")
    locked = [j for j in range(1, full.njoints) if j not in keep]
    model = pin.buildReducedModel(full, locked, pin.neutral(full)) if locked else full
    n = len(joints)
    if model.nq != n or model.nv != n:
        raise RobotError(f"{spec_file}: only 1-DoF joints are supported (nq={model.nq}, nv={model.nv})")
    vec = lambda path: _vector(spec, path, n, spec_file)  # noqa: E731
    joint_of, offset, radius, link = _spheres(model, spec.get("spheres", []), spec_file)
    pairs = np.asarray(spec.get("self_collision", []), dtype=int).reshape(-1, 2)
    if pairs.size and (pairs.min() < 0 or pairs.max() >= len(radius)):
        raise RobotError(f"{spec_file}: self_collision index outside 0..{len(radius) - 1}")
    smoothing = float(spec.get("friction", {}).get("smoothing", 0.0))
    if smoothing <= 0:
        raise RobotError(f"{spec_file}: friction.smoothing must be > 0 rad/s")
    robot = Robot(
        name=str(spec["name"]), key=key, model=model, joint_names=joints,
        q_lower=vec("limits.position.lower"), q_upper=vec("limits.position.upper"),
        qd_max=vec("limits.velocity"), tau_max=vec("limits.torque"), taud_max=vec("limits.torque_rate"),
        gear_ratios=vec("gear_ratios"), viscous=vec("friction.viscous"), coulomb=vec("friction.coulomb"),
        friction_smoothing=smoothing, sphere_joint=joint_of, sphere_offset=offset, sphere_radius=radius,
        sphere_link=link, self_collision=pairs,
    )
    for field in ("qd_max", "tau_max", "taud_max", "gear_ratios"):
        if np.any(getattr(robot, field) <= 0):
            raise RobotError(f"{spec_file}: {field} must be positive")
    if np.any(robot.q_lower >= robot.q_upper):
        raise RobotError(f"{spec_file}: position lower limits must be below upper limits")
    return robot


def _spheres(model: pin.Model, spheres: list, spec_file: Path):
    joint_of, offset, radius, link = [], [], [], []
    for k, sphere in enumerate(spheres):
        name = sphere.get("link")
        if not model.existFrame(name):
            raise RobotError(f"{spec_file}: sphere {k} is on unknown link {name!r}")
        frame = model.frames[model.getFrameId(name)]
        joint_of.append(frame.parentJoint)
        offset.append(frame.placement.act(np.asarray(sphere["center"], dtype=float)))
        radius.append(float(sphere["radius"]))
        link.append(name)
    return (np.asarray(joint_of, dtype=int), np.asarray(offset, dtype=float).reshape(-1, 3),
            np.asarray(radius, dtype=float), tuple(link))
