"""`ocpkit robot import`: a spec.yaml for any URDF (docs/robots-and-data.md, 'Robots from any URDF').

Limits come from the URDF's `<limit>` (position, velocity, effort). Where the URDF knows nothing, a documented
rule fills in, and `overrides` replace any value:

- torque rate (N m/s) = TORQUE_RATE_PER_SECOND × torque limit: full torque in 0.1 s (Panda: 1000 N m/s for
  87 N m, 11.5/s; industrial6: 15/s);
- gear ratio = max(1, floor(MOTOR_SPEED / velocity limit)): the joint reaches its speed limit at the top speed
  of a 4000 rpm servo motor (the industrial6 rule); for a prismatic joint the velocity is in m/s;
- friction zero;
- a position limit within PI_ROUNDING of ±π or ±2π is read as exactly that (URDFs often write 3.14159 for π, and
  the problems of benchmarks such as MotionBenchMaker then sit a few µrad outside it).
"""

from __future__ import annotations

import math
import os
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml

from ocpkit.errors import RobotError
from ocpkit.robots.robot import place_base, reduced_model
from ocpkit.robots.self_collision import Pairs, self_collision_pairs
from ocpkit.robots.spheres import Sphere, urdf_root
from ocpkit.robots.urdf import EXAMPLE_ROBOT_DATA, example_robot_data_dir, model_from_urdf

TORQUE_RATE_PER_SECOND = 10.0
"""Torque-rate limit per N m of torque limit, 1/s, when the URDF gives none (it never does)."""
MOTOR_SPEED = 4000 * 2 * math.pi / 60
"""Assumed servo motor top speed, rad/s (4000 rpm), for the gear-ratio rule."""
FRICTION_SMOOTHING = 0.05
"""rad/s (or m/s), as industrial6."""
PI_ROUNDING = 1e-5
"""rad: how close to ±π or ±2π a URDF position limit must be to be read as it."""
OVERRIDABLE = ("lower", "upper", "velocity", "torque", "torque_rate", "gear_ratio", "viscous", "coulomb")
"""Fields `--set FIELD.JOINT=VALUE` may replace."""


@dataclass(frozen=True)
class Imported:
    """A spec (mapping, ready for YAML) and what the import decided: the self-collision pair report."""

    spec: dict
    pairs: Pairs


def urdf_reference(urdf: Path, out_dir: Path) -> str:
    """How the spec in `out_dir` names `urdf`: example-robot-data:<path> inside that package, else a relative path."""
    urdf = urdf.resolve()
    try:
        return EXAMPLE_ROBOT_DATA + urdf.relative_to(example_robot_data_dir().resolve()).as_posix()
    except (ValueError, RobotError):
        return Path(os.path.relpath(urdf, out_dir.resolve())).as_posix()


def movable_joints(model: pin.Model) -> list[str]:
    """Every 1-DoF joint of the URDF model (revolute and prismatic), in tree order."""
    return [model.names[j] for j in range(1, model.njoints) if model.joints[j].nq == 1]


def planned_model(full: pin.Model, joints: list[str], locked: dict[str, float], base: dict) -> pin.Model:
    """`full` placed at `base` with every joint but `joints` locked (at `locked` values, default 0)."""
    model = full.copy()
    place_base(model, base)
    return reduced_model(model, tuple(joints), locked)


def import_urdf(urdf: Path, spheres: list[Sphere], out_dir: Path, *, name: str | None = None,
                joints: list[str] | None = None, srdf: Path | None = None, locked: dict[str, float] | None = None,
                base: dict | None = None, overrides: dict[str, dict[str, float]] | None = None) -> Imported:
    """The spec of a robot from `urdf` with collision `spheres` (on its links), to be written in `out_dir`.

    `joints`: the planned joints (default: every revolute and prismatic joint); `locked`: values of the other
    joints (default 0); `overrides`: {field: {joint: value}} for the fields of OVERRIDABLE."""
    full = model_from_urdf(Path(urdf).read_bytes(), urdf)
    joints = joints or movable_joints(full)
    locked, base, overrides = locked or {}, base or {}, overrides or {}
    for joint in joints:
        if not full.existJointName(joint):
            raise RobotError(f"--joints: {joint!r} is not a joint of {urdf}; its joints: {list(full.names[1:])}")
        if full.joints[full.getJointId(joint)].nq != 1:
            raise RobotError(f"--joints: {joint!r} is not a 1-DoF revolute or prismatic joint (a continuous joint "
                             "is not supported: lock it or leave it out)")
    model = planned_model(full, joints, locked, base)
    values = _joint_values(model, joints, overrides)
    pairs = self_collision_pairs(model, spheres, srdf)
    spec = {
        "name": name or _robot_name(urdf),
        "urdf": urdf_reference(Path(urdf), Path(out_dir)),
        "joints": list(joints),
        **({"locked": dict(locked)} if locked else {}),
        **({"base": dict(base)} if base else {}),
        "limits": {"position": {"lower": values["lower"], "upper": values["upper"]}, "velocity": values["velocity"],
                   "torque": values["torque"], "torque_rate": values["torque_rate"]},
        "gear_ratios": values["gear_ratio"],
        "friction": {"viscous": values["viscous"], "coulomb": values["coulomb"], "smoothing": FRICTION_SMOOTHING},
        "spheres": [s.as_spec() for s in spheres],
        "self_collision": [list(p) for p in pairs.kept],
    }
    return Imported(spec, pairs)


def _robot_name(urdf: Path) -> str:
    return urdf_root(urdf).get("name") or Path(urdf).stem


def _joint_values(model: pin.Model, joints: list[str], overrides: dict[str, dict[str, float]]) -> dict[str, list]:
    """Per-field lists of joint values: the URDF's, the rule's (module docstring), then `overrides`."""
    index = [model.joints[model.getJointId(j)].idx_v for j in joints]
    values = {"lower": model.lowerPositionLimit[index], "upper": model.upperPositionLimit[index],
              "velocity": model.velocityLimit[index], "torque": model.effortLimit[index]}
    values = {key: np.array(v, dtype=float) for key, v in values.items()}
    for key in ("lower", "upper"):
        for whole in (np.pi, 2 * np.pi):
            near = np.abs(np.abs(values[key]) - whole) < PI_ROUNDING
            values[key][near] = np.sign(values[key][near]) * whole
    for key, value in overrides.items():
        if key not in OVERRIDABLE:
            raise RobotError(f"--set {key}.…: unknown field; allowed: {', '.join(OVERRIDABLE)}")
        for joint in value:
            if joint not in joints:
                raise RobotError(f"--set {key}.{joint}: not a planned joint; planned: {', '.join(joints)}")
    for key in ("lower", "upper", "velocity", "torque"):
        _apply(values[key], key, joints, overrides)
    values["torque_rate"] = TORQUE_RATE_PER_SECOND * values["torque"]
    values["gear_ratio"] = np.maximum(1.0, np.floor(MOTOR_SPEED / np.maximum(values["velocity"], 1e-9)))
    values["viscous"], values["coulomb"] = np.zeros(len(joints)), np.zeros(len(joints))
    for key in ("torque_rate", "gear_ratio", "viscous", "coulomb"):
        _apply(values[key], key, joints, overrides)
    for key, what in (("velocity", "velocity"), ("torque", "effort")):
        for joint, v in zip(joints, values[key]):
            if not v > 0 or not np.isfinite(v):
                raise RobotError(f"joint {joint}: the URDF gives no {what} limit ({v}); set one with "
                                 f"--set {key}.{joint}=VALUE")
    for joint, lo, hi in zip(joints, values["lower"], values["upper"]):
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise RobotError(f"joint {joint}: position limits [{lo}, {hi}] are not a finite range; set them with "
                             f"--set lower.{joint}=VALUE --set upper.{joint}=VALUE")
    return {key: [float(x) if key in ("lower", "upper") else round(float(x), 6) for x in v]
            for key, v in values.items()}


def _apply(values: np.ndarray, key: str, joints: list[str], overrides: dict[str, dict[str, float]]) -> None:
    for joint, value in overrides.get(key, {}).items():
        values[joints.index(joint)] = value


def spec_header(imported: Imported, urdf: Path, spheres: str, by: str) -> str:
    """The comment above an imported spec.yaml: what made it (`by`), from which URDF and `spheres` source, the
    rules its values follow, and the self-collision pairs dropped."""
    return (f"{imported.spec['name']}: imported by {by} from {Path(urdf).name} (spheres: {spheres}).\n"
            "Limits from the URDF; torque rate = 10/s x torque limit, gear ratio = floor(418.9 rad/s / velocity "
            "limit),\nfriction zero, unless overridden (ocpkit.robots.importer). Self-collision:\n"
            + pair_report(imported.pairs))


def write_spec(imported: Imported, out_dir: Path, header: str) -> Path:
    """Write `imported.spec` to out_dir/spec.yaml under the comment `header`; the path written."""
    comment = "".join(f"# {line}\n".replace("# \n", "#\n") for line in header.splitlines())
    body = yaml.safe_dump(imported.spec, sort_keys=False, default_flow_style=None, width=120)
    path = out_dir / "spec.yaml"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        path.write_text(comment + body)
    except OSError as exc:
        raise RobotError(f"--out: cannot write {path}: {exc.strerror}") from None
    return path


def pair_report(pairs: Pairs) -> str:
    """Lines naming the link pairs dropped from self-collision, and why."""
    def names(links: set[frozenset[str]]) -> str:
        text = ", ".join(sorted("/".join(sorted(p)) for p in links)) or "none"
        return textwrap.fill(text, width=110, subsequent_indent="  ")

    return (f"self-collision: {len(pairs.kept)} sphere pairs kept\n"
            f"dropped, disabled in the SRDF: {names(pairs.disabled)}\n"
            f"dropped, touching at {pairs.home}: {names(pairs.touching)}")
