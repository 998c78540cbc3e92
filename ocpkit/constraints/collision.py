"""Sphere collision constraints, eqs. (7)–(8) of the paper: self, obstacle and workspace clearance.

Distances are compared squared (smooth everywhere): ‖c_a − c_b‖² ≥ (r_a + r_b + margin)².

Terms that can never be active are left out, which keeps the NLP (and IPOPT's KKT system) small: every
robot sphere stays within its *reach* ρ of a fixed anchor (the origin of the first joint of its chain,
which never moves), so a sphere whose reach ball cannot touch an obstacle or a workspace face gets no
constraint for it. On the paper cases this drops a third of the obstacle terms and 30 % of the solve
time. The kept terms are part of the NLP shape: moving an obstacle keeps the build unless it crosses a
sphere's reach boundary. Spheres on the fixed base never move at all; they are checked once, when the
scenario is loaded (ocpkit.scenario.validate). The clearance margin is an NLP parameter (a refinement round
may raise it), so terms are kept up to MAX_MARGIN.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.constraints.base import PointValues
from ocpkit.dynamics.base import Dynamics
from ocpkit.problem import Problem
from ocpkit.robots import Robot

MAX_MARGIN = 0.1  # m: the largest clearance margin the kept collision terms stay valid for


def sphere_reach(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """(anchors (M, 3), reach (M,)): sphere j's centre stays within reach[j] metres of anchors[j]."""
    model = robot.model
    anchors, reach = [], []
    for joint, offset in zip(robot.sphere_joint.tolist(), robot.sphere_offset):
        distance = np.linalg.norm(offset)
        while joint > 0 and model.parents[joint] > 0:
            distance += np.linalg.norm(model.jointPlacements[joint].translation)
            if model.joints[joint].shortname().startswith("JointModelP"):  # prismatic: add its stroke
                i = model.joints[joint].idx_q
                distance += max(abs(robot.q_lower[i]), abs(robot.q_upper[i]))
            joint = model.parents[joint]
        anchors.append(model.jointPlacements[joint].translation if joint > 0 else offset)
        reach.append(distance if joint > 0 else 0.0)
    return np.asarray(anchors).reshape(-1, 3), np.asarray(reach)


def active_terms(problem: Problem) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the collision terms that can become active with a margin up to MAX_MARGIN: obstacles
    (M, S), workspace faces [x, y, z min, x, y, z max] (M, 6), or (M, 0) without a workspace."""
    robot, scene = problem.robot, problem.scene
    anchors, reach = sphere_reach(robot)
    moving = (robot.sphere_joint > 0)[:, None]
    span = (reach + robot.sphere_radius + MAX_MARGIN)[:, None]
    gaps = np.linalg.norm(anchors[:, None, :] - scene.obstacle_centers[None], axis=-1)
    obstacles = (gaps <= span + scene.obstacle_radii[None, :]) & moving
    if scene.workspace is None:
        return obstacles, np.zeros((len(reach), 0), dtype=bool)
    faces = np.hstack([anchors - scene.workspace.lower, scene.workspace.upper - anchors])
    return obstacles, (faces <= span) & moving


class SphereCollision:
    """Clearance ≥ `margin` (m, a CasADi expression, ≤ MAX_MARGIN) between robot spheres, to S obstacle
    spheres and to the workspace box."""

    name = "collision"
    enforced_by_knot_bounds = False

    def __init__(self, dynamics: Dynamics, problem: Problem, margin: ca.SX) -> None:
        robot = dynamics.robot
        self.dynamics, self.margin = dynamics, margin
        self.obstacle_mask, self.face_mask = active_terms(problem)
        pairs = robot.self_collision
        self.pairs = pairs[(robot.sphere_joint[pairs] > 0).any(axis=1)] if len(pairs) else pairs
        self.obstacle_centers = ca.SX.sym("obstacle_center", problem.scene.n_obstacles, 3)
        self.obstacle_radii = ca.SX.sym("obstacle_radius", problem.scene.n_obstacles)
        self.box = ca.SX.sym("workspace", self.face_mask.shape[1])  # [lower (3), upper (3)]

    @property
    def parameters(self) -> ca.SX:
        return ca.vertcat(ca.vec(self.obstacle_centers), self.obstacle_radii, self.box)

    def parameter_values(self, problem: Problem) -> np.ndarray:
        scene = problem.scene
        box = [] if self.box.numel() == 0 else [scene.workspace.lower, scene.workspace.upper]
        return np.concatenate([scene.obstacle_centers.ravel(order="F"), scene.obstacle_radii, *box])

    def evaluate(self, point: PointValues) -> tuple[ca.SX, np.ndarray, np.ndarray]:
        radius = self.dynamics.robot.sphere_radius
        centers = self.dynamics.sphere_centers(point.q)
        g, upper = [], []
        for a, b in self.pairs:
            gap = centers[a, :] - centers[b, :]
            g.append(ca.dot(gap, gap) - (radius[a] + radius[b] + self.margin) ** 2)
        for m, s in zip(*np.nonzero(self.obstacle_mask)):
            gap = centers[m, :] - self.obstacle_centers[s, :]
            g.append(ca.dot(gap, gap) - (radius[m] + self.obstacle_radii[s] + self.margin) ** 2)
        upper = [np.inf] * len(g)
        for m, axis in zip(*np.nonzero(self.face_mask[:, :3] | self.face_mask[:, 3:])):
            g.append(self._workspace_row(centers[m, axis], radius[m] + self.margin, axis, self.face_mask[m]))
            upper.append(1.0 if self.face_mask[m, axis] and self.face_mask[m, axis + 3] else np.inf)
        g = ca.vertcat(*g) if g else ca.SX(0, 1)
        return g, np.zeros(g.numel()), np.asarray(upper, dtype=float)

    def _workspace_row(self, c: ca.SX, inset: float, axis: int, faces: np.ndarray) -> ca.SX:
        """One row per axis, ≥ 0 when inside: both faces reachable → the position scaled to [0, 1] between
        them (a single two-sided row, half the rows of two one-sided ones); else the one reachable face."""
        low, high = self.box[axis] + inset, self.box[axis + 3] - inset
        if faces[axis] and faces[axis + 3]:
            return (c - low) / (high - low)
        return c - low if faces[axis] else high - c
