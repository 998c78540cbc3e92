"""An outside checker that knows nothing of ocpkit: it reads a trajectory JSON, the robot's spec.yaml +
URDF and the scenario YAML (for the scene), and re-checks the samples with pinocchio.

Usage: python tests/outside_check.py TRAJECTORY.json SPEC.yaml ROBOT.urdf SCENARIO.yaml
(ROBOT.urdf `-`: the URDF the spec names in `urdf:`, relative to the spec or `example-robot-data:<path>`).
The spec's `base` pose places the URDF root; joints not in `joints` are held at `locked` values (default 0).
Prints one line per check and exits 1 if any fails: limits within 1 %, tau within 1 % of the torque range
of rnea(q, qd, qdd) + friction, torque rate (finite differences of tau) within 1 %, no contact of a robot sphere
with an obstacle (sphere, box or cylinder; exact distances), with another sphere or the workspace faces, and
self-consistent samples: over each sample step the difference quotient of q (of qd) lies between qd (qdd) at
the step's ends (mean value theorem), within 1 % of the velocity limit (5 % of the peak acceleration).
"""

from __future__ import annotations

import importlib.metadata
import json
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import yaml

TOLERANCE = {"position": 1e-4, "self_collision": 0.0, "obstacle": 0.0, "workspace": 0.0,
             "qdd_consistency": 0.05}  # others: 0.01


def outside_range(t: np.ndarray, x: np.ndarray, derivative: np.ndarray) -> np.ndarray:
    """Distance of each step's difference quotient of x from the range of `derivative` at the step's ends."""
    quotient = np.diff(x, axis=0) / np.diff(t)[:, None]
    low, high = np.minimum(derivative[:-1], derivative[1:]), np.maximum(derivative[:-1], derivative[1:])
    return np.maximum(low - quotient, quotient - high)


def consistency(s: dict[str, np.ndarray], velocity_limit: np.ndarray) -> dict[str, float]:
    """Worst self-consistency of the samples: q against qd (relative to the velocity limit), qd against qdd
    (relative to the peak of |qdd| and of the difference quotients of qd)."""
    peak = max(np.abs(s["qdd"]).max(), np.abs(np.diff(s["qd"], axis=0) / np.diff(s["t"])[:, None]).max(), 1e-300)
    return {"qd_consistency": np.max(outside_range(s["t"], s["q"], s["qd"]) / velocity_limit),
            "qdd_consistency": np.max(outside_range(s["t"], s["qd"], s["qdd"]) / peak)}


def spec_urdf(spec: dict, spec_file: str) -> str:
    """The URDF file a spec names: relative to the spec, or example-robot-data:<path> in that package."""
    name = spec["urdf"]
    if name.startswith("example-robot-data:"):
        package = importlib.metadata.distribution("example-robot-data")
        share = package.locate_file("cmeel.prefix/share/example-robot-data")
        return str(Path(share) / name.removeprefix("example-robot-data:"))
    return str(Path(spec_file).parent / name)


def robot_model(spec: dict, urdf: str) -> pin.Model:
    """The planned model: the URDF with its root at the spec's `base` (xyz m, rpy rad) and every joint not in
    `joints` locked at its `locked` value (default 0)."""
    full = pin.buildModelFromUrdf(urdf)
    base = spec.get("base", {})
    pose = pin.SE3(pin.rpy.rpyToMatrix(*base.get("rpy", [0, 0, 0])), np.array(base.get("xyz", [0, 0, 0]), float))
    for j in range(1, full.njoints):
        if full.parents[j] == 0:
            full.jointPlacements[j] = pose * full.jointPlacements[j]
    for k in range(1, len(full.frames)):
        frame = full.frames[k]
        if frame.parentJoint == 0:
            frame.placement = pose * frame.placement
            full.frames[k] = frame
    q = pin.neutral(full)
    for name, value in spec.get("locked", {}).items():
        q[full.joints[full.getJointId(name)].idx_q] = value
    fixed = [j for j in range(1, full.njoints) if full.names[j] not in spec["joints"]]
    return pin.buildReducedModel(full, fixed, q) if fixed else full


def rotation(quaternion: list[float]) -> np.ndarray:
    """Rotation matrix of [x, y, z, w] through pinocchio (normalised)."""
    x, y, z, w = np.asarray(quaternion, dtype=float) / np.linalg.norm(quaternion)
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


def obstacle_distance(obstacle: dict, points: np.ndarray) -> np.ndarray:
    """Exact signed distance (m) of points (..., 3) to a scenario obstacle {sphere|box|cylinder: {...}}."""
    (kind, o), = obstacle.items()
    offset = points - np.array(o["center"])
    if kind == "sphere":
        return np.linalg.norm(offset, axis=-1) - o["radius"]
    local = offset @ rotation(o.get("orientation", [0, 0, 0, 1]))  # rows: Rᵀ (p - c)
    if kind == "box":
        excess = np.abs(local) - np.array(o["size"]) / 2
    else:  # cylinder along local z
        excess = np.stack([np.hypot(local[..., 0], local[..., 1]) - o["radius"],
                           np.abs(local[..., 2]) - o["length"] / 2], axis=-1)
    outside = np.sqrt(np.sum(np.clip(excess, 0, None) ** 2, axis=-1))
    return np.where(excess.max(axis=-1) > 0, outside, excess.max(axis=-1))


def check(trajectory: dict, spec: dict, urdf: str, scenario: dict) -> dict[str, float]:
    """Worst value of every check: relative excess for limits, metres of penetration for geometry."""
    model = robot_model(spec, urdf)
    data = model.createData()
    s = {k: np.asarray(v, dtype=float) for k, v in trajectory["samples"].items()}
    lim, fr = spec["limits"], spec["friction"]
    lower, upper = np.array(lim["position"]["lower"]), np.array(lim["position"]["upper"])
    tau_max = np.array(lim["torque"])
    rnea = np.array([pin.rnea(model, data, q, qd, qdd).copy() for q, qd, qdd in zip(s["q"], s["qd"], s["qdd"])])
    needed = rnea + np.array(fr["viscous"]) * s["qd"] + np.array(fr["coulomb"]) * np.tanh(s["qd"] / fr["smoothing"])
    rate = np.gradient(s["tau"], s["t"], axis=0)
    worst = {
        "position": np.max(np.maximum(s["q"] - upper, lower - s["q"])),  # rad: a hard stop
        "velocity": np.max(np.abs(s["qd"]) / np.array(lim["velocity"]) - 1),
        "torque": np.max(np.abs(s["tau"]) / tau_max - 1),
        "torque_rate": np.max(np.abs(rate) / np.array(lim["torque_rate"]) - 1),
        "dynamics": np.max(np.abs(s["tau"] - needed) / (2 * tau_max)),
        **consistency(s, np.array(lim["velocity"])),
    }
    centres = []
    for q in s["q"]:
        pin.framesForwardKinematics(model, data, q)
        centres.append([data.oMf[model.getFrameId(sp["link"])].act(np.array(sp["center"])) for sp in spec["spheres"]])
    centres = np.array(centres)
    radii = np.array([sp["radius"] for sp in spec["spheres"]])
    pairs = np.array(spec["self_collision"])
    gaps = np.linalg.norm(centres[:, pairs[:, 0]] - centres[:, pairs[:, 1]], axis=-1) - radii[pairs].sum(axis=1)
    worst["self_collision"] = max(0.0, -gaps.min())
    scene = scenario.get("scene", {})
    for obstacle in scene.get("obstacles", []):
        gap = obstacle_distance(obstacle, centres) - radii
        worst["obstacle"] = max(worst.get("obstacle", 0.0), -gap.min())
    if "workspace" in scene:
        box = scene["workspace"]
        inside = np.minimum(centres - radii[:, None] - box["min"], box["max"] - centres - radii[:, None])
        worst["workspace"] = max(0.0, -inside.min())
    return worst


def main(argv: list[str]) -> int:
    trajectory_file, spec_file, urdf, scenario_file = argv
    with open(trajectory_file) as t, open(spec_file) as sp, open(scenario_file) as sc:
        spec = yaml.safe_load(sp)
        worst = check(json.load(t), spec, spec_urdf(spec, spec_file) if urdf == "-" else urdf, yaml.safe_load(sc))
    failed = False
    for name, value in worst.items():
        ok = value <= TOLERANCE.get(name, 0.01)
        failed |= not ok
        print(f"{name:15s} {value:+.4f} {'ok' if ok else 'FAIL'}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
