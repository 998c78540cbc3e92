"""Numeric sphere geometry with pinocchio: sphere centres and signed clearances (metres).

A clearance is ≥ 0 when free: centre distance minus radii for sphere pairs, the exact signed distance of the
centre to an obstacle box or cylinder (`ocpkit.geometry.distance`) minus the radius, distance to the workspace face
minus radius. This module is the single numeric reference used by scenario checks,
`verify` and the baselines' validity checker.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ocpkit.geometry.distance import box_distance, cylinder_distance
from ocpkit.geometry.scene import Scene
from ocpkit.robots import Robot


def sphere_centers(robot: Robot, q: np.ndarray, data: pin.Data | None = None) -> np.ndarray:
    """World positions of the robot's spheres at configurations q (n,) or (K, n): shape (M, 3) or (K, M, 3).

    Pass a `data` (robot.model.createData()) when calling often: creating one costs more than the kinematics."""
    data = data or robot.model.createData()
    qs = np.atleast_2d(q)
    poses = np.empty((len(qs), robot.model.njoints, 4, 4))  # homogeneous world pose of every joint
    for k, qk in enumerate(qs):
        pin.forwardKinematics(robot.model, data, qk)
        poses[k] = [placement.homogeneous for placement in data.oMi]
    sphere_poses = poses[:, robot.sphere_joint]
    out = np.einsum("kmij,mj->kmi", sphere_poses[..., :3, :3], robot.sphere_offset) + sphere_poses[..., :3, 3]
    return out[0] if np.ndim(q) == 1 else out


AXES = {"X": 0, "Y": 1, "Z": 2}
"""The joint axis of pinocchio's aligned 1-DoF joints (JointModelRX ... JointModelPZ), by the name's last letter."""


@dataclass(frozen=True)
class ChainJoint:
    """One 1-DoF joint of a robot's model as `sphere_centers_batch` (and the hand-written C kernels,
    ocpkit.solvers.chain) composes it: its parent joint, its q index, its placement in the parent (rotation
    (3, 3), translation (3,)); revolute: the cross-product matrix [a]x of its axis and [a]x² (Rodrigues),
    prismatic: the axis in the parent's frame."""

    parent: int
    index: int
    rotation: np.ndarray
    translation: np.ndarray
    revolute: bool
    cross: np.ndarray
    cross_squared: np.ndarray
    slide: np.ndarray


@functools.lru_cache(maxsize=32)
def joint_chain(robot: Robot) -> tuple[ChainJoint, ...]:
    """The joints 1, 2, ... of `robot`'s model (robots hash by identity)."""
    out = []
    for j in range(1, robot.model.njoints):
        joint, placement = robot.model.joints[j], robot.model.jointPlacements[j]
        kind = joint.shortname()
        axis = joint.extract().axis if kind.endswith("Unaligned") else np.eye(3)[AXES[kind[-1]]]
        cross = np.cross(np.eye(3), axis)
        out.append(ChainJoint(robot.model.parents[j], joint.idx_q, placement.rotation.copy(),
                          placement.translation.copy(), kind.startswith("JointModelR"), cross, cross @ cross,
                          placement.rotation @ axis))
    return tuple(out)


def sphere_centers_batch(robot: Robot, qs: np.ndarray) -> np.ndarray:
    """`sphere_centers` of many configurations qs (K, n) at once, shape (K, M, 3): the joint poses composed in
    numpy over all K together (revolute and prismatic 1-DoF joints, the ones ocpkit models), instead of one
    pinocchio forward-kinematics call per configuration; the same numbers (tests/geometry/test_clearances.py)."""
    return points_on_joints(robot, qs, robot.sphere_joint, robot.sphere_offset)


def points_on_joints(robot: Robot, qs: np.ndarray, joints: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """World positions (K, P, 3) of P points, point p fixed at offsets[p] (m) in the frame of joint joints[p], at
    configurations qs (K, n): `sphere_centers_batch` for any points on the robot."""
    qs = np.atleast_2d(np.asarray(qs, dtype=float))
    rotation = np.empty((robot.model.njoints, len(qs), 3, 3))
    translation = np.empty((robot.model.njoints, len(qs), 3))
    rotation[0], translation[0] = np.eye(3), 0.0
    for j, joint in enumerate(joint_chain(robot), start=1):
        q = qs[:, joint.index]
        if joint.revolute:  # Rodrigues: R(q) = I + sin q [a]x + (1 − cos q) [a]x²
            turn = np.sin(q)[:, None, None] * joint.cross + (1 - np.cos(q))[:, None, None] * joint.cross_squared
            rotation[j] = rotation[joint.parent] @ (joint.rotation + joint.rotation @ turn)
            local_t = joint.translation
        else:
            rotation[j] = rotation[joint.parent] @ joint.rotation
            local_t = joint.translation + joint.slide * q[:, None]
        translation[j] = translation[joint.parent] + (rotation[joint.parent] @ local_t[..., None])[..., 0]
    r, t = rotation[joints], translation[joints]  # (P, K, 3, 3), (P, K, 3)
    return np.einsum("pkij,pj->kpi", r, offsets) + t.transpose(1, 0, 2)


@dataclass(frozen=True)
class Clearances:
    """Signed clearances (m) for K configurations: self (K, P), obstacle (K, M, S + B + C: spheres, boxes,
    cylinders as in `Scene.obstacle_labels`), workspace (K, M, 6)."""

    self_pairs: np.ndarray
    obstacles: np.ndarray
    workspace: np.ndarray

    def smallest(self) -> float:
        """The smallest clearance of any kind (m); inf when there is nothing to check."""
        return min([np.inf] + [float(v.min()) for v in (self.self_pairs, self.obstacles, self.workspace) if v.size])


def buried(robot: Robot, scene: Scene, centers: np.ndarray) -> np.ndarray:
    """Per configuration (K,): whether some sphere centre of `centers` (K, M, 3) lies inside an obstacle box or
    cylinder, where its collision row has no gradient (ocpkit.constraints.collision; a sphere obstacle's row has
    one everywhere but at its centre)."""
    solids = clearances(robot, scene, centers).obstacles[..., len(scene.obstacle_radii):]
    return (solids + robot.sphere_radius[None, :, None] <= 0).any(axis=(1, 2))


def clearances(robot: Robot, scene: Scene, centers: np.ndarray) -> Clearances:
    """Clearances of sphere centres (K, M, 3) against each other, the obstacles and the workspace box."""
    r = robot.sphere_radius
    a, b = robot.self_collision.T if len(robot.self_collision) else (np.zeros(0, int), np.zeros(0, int))
    gaps = centers[:, a] - centers[:, b]
    self_pairs = np.sqrt(np.einsum("kpi,kpi->kp", gaps, gaps)) - (r[a] + r[b])
    offsets = centers[:, :, None, :] - scene.obstacle_centers[None, None]
    distances = [np.sqrt(np.einsum("kmsi,kmsi->kms", offsets, offsets)) - scene.obstacle_radii[None, :]]
    shapes = ((box_distance, scene.boxes), (cylinder_distance, scene.cylinders))
    distances += [distance(centers, group) for distance, group in shapes if len(group)]  # skipped when empty: the
    obstacles = np.concatenate(distances, axis=-1) - r[:, None]  # OMPL validity checker calls this thousands of times
    return Clearances(self_pairs, obstacles, workspace_clearances(robot, scene, centers))


def workspace_clearances(robot: Robot, scene: Scene, centers: np.ndarray) -> np.ndarray:
    """Clearances (K, M, 6) of sphere centres (K, M, 3) from the workspace's faces, lower x, y, z then upper; (K, M, 0)
    without a workspace."""
    r = robot.sphere_radius
    if scene.workspace is None:
        return np.zeros((len(centers), len(r), 0))
    below = centers - scene.workspace.lower - r[:, None]
    above = scene.workspace.upper - centers - r[:, None]
    return np.concatenate([below, above], axis=-1)


def collision_report(robot: Robot, scene: Scene, q: np.ndarray) -> list[str]:
    """Human-readable list of every sphere contact at configuration q (n,); empty when collision-free."""
    c = clearances(robot, scene, sphere_centers(robot, q)[None])
    link = robot.sphere_link
    lines = [f"self-collision: sphere {i} ({link[i]}) and sphere {j} ({link[j]}) overlap by {-d:.3f} m"
             for (i, j), d in zip(robot.self_collision, c.self_pairs[0]) if d < 0]
    names = scene.obstacle_labels()
    lines += [f"sphere {m} ({link[m]}) overlaps {names[s]} by {-c.obstacles[0, m, s]:.3f} m"
              for m, s in zip(*np.nonzero(c.obstacles[0] < 0))]
    faces = ["x min", "y min", "z min", "x max", "y max", "z max"]
    lines += [f"sphere {m} ({link[m]}) leaves the workspace at {faces[f]} by {-c.workspace[0, m, f]:.3f} m"
              for m, f in zip(*np.nonzero(c.workspace[0] < 0))]
    return lines
