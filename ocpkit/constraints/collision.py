"""Sphere collision constraints, eqs. (7)–(8) of the paper: self, obstacle and workspace clearance.

Distances are compared squared (smooth everywhere): ‖c_a − c_b‖² ≥ (r_a + r_b + margin)².

Terms that can never be active are left out, which keeps the NLP (and IPOPT's KKT system) small: every
robot sphere stays within its reach ρ of a fixed anchor (`ocpkit.robots.sphere_reach`), so a sphere whose
reach ball cannot touch an obstacle or a workspace face gets no constraint for it. The kept terms are the
constraint's shape: moving an obstacle keeps the build unless it crosses a sphere's reach boundary. Spheres
on the fixed base never move at all; they are checked once, when the problem is validated. The clearance
margin is an NLP parameter (a refinement round may raise it), so terms are kept up to MAX_MARGIN.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.constraints.base import Constraint, Context, PointValues, Rows
from ocpkit.problem import Problem
from ocpkit.robots import sphere_reach

MAX_MARGIN = 0.1  # m: the largest clearance margin the kept collision terms stay valid for


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


class SphereCollision(Constraint):
    """Clearance ≥ margin (m) between robot spheres, to the S obstacle spheres and to the workspace box."""

    name = "collision"

    def __init__(self, problem: Problem) -> None:
        super().__init__(problem)
        self.obstacle_mask, self.face_mask = active_terms(problem)
        pairs = self.robot.self_collision
        self.pairs = pairs[(self.robot.sphere_joint[pairs] > 0).any(axis=1)] if len(pairs) else pairs

    def shape(self) -> tuple:
        return self.obstacle_mask.shape, self.obstacle_mask.tobytes(), self.face_mask.shape, self.face_mask.tobytes()

    def parameter_shapes(self) -> dict[str, tuple[int, int]]:
        obstacles = self.obstacle_mask.shape[1]
        return {"obstacle_center": (obstacles, 3), "obstacle_radius": (obstacles, 1),
                "workspace": (self.face_mask.shape[1], 1)}  # [lower (3), upper (3)] or nothing

    def parameter_values(self, problem: Problem) -> dict[str, np.ndarray]:
        scene = problem.scene
        box = [] if self.face_mask.shape[1] == 0 else [scene.workspace.lower, scene.workspace.upper]
        return {"obstacle_center": scene.obstacle_centers, "obstacle_radius": scene.obstacle_radii,
                "workspace": np.concatenate([np.zeros(0), *box])}

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        radius, margin = self.robot.sphere_radius, context.margin
        centers = context.dynamics.sphere_centers(point.q)
        obstacle_centers, obstacle_radii = context.parameters["obstacle_center"], context.parameters["obstacle_radius"]
        g = []
        for a, b in self.pairs:
            gap = centers[a, :] - centers[b, :]
            g.append(ca.dot(gap, gap) - (radius[a] + radius[b] + margin) ** 2)
        for m, s in zip(*np.nonzero(self.obstacle_mask)):
            gap = centers[m, :] - obstacle_centers[s, :]
            g.append(ca.dot(gap, gap) - (radius[m] + obstacle_radii[s] + margin) ** 2)
        upper = [np.inf] * len(g)
        box = context.parameters["workspace"]
        for m, axis in zip(*np.nonzero(self.face_mask[:, :3] | self.face_mask[:, 3:])):
            g.append(_workspace_row(box, centers[m, axis], radius[m] + margin, axis, self.face_mask[m]))
            upper.append(1.0 if self.face_mask[m, axis] and self.face_mask[m, axis + 3] else np.inf)
        g = ca.vertcat(*g) if g else ca.SX(0, 1)
        return Rows(g, np.zeros(g.numel()), np.asarray(upper, dtype=float))


def _workspace_row(box: ca.SX, c: ca.SX, inset: ca.SX, axis: int, faces: np.ndarray) -> ca.SX:
    """One row per axis, ≥ 0 when inside the box [lower (3), upper (3)]: both faces reachable → the position
    scaled to [0, 1] between them (one two-sided row, half the rows of two one-sided ones); else the one
    reachable face."""
    low, high = box[axis] + inset, box[axis + 3] - inset
    if faces[axis] and faces[axis + 3]:
        return (c - low) / (high - low)
    return c - low if faces[axis] else high - c
