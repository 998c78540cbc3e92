"""Sphere collision constraints, eqs. (7)–(8) of the paper: self, obstacle and workspace clearance.

Distances are compared squared (smooth everywhere): ‖c_a − c_b‖² ≥ (r_a + r_b + margin)².

Boxes and cylinders: one row per (robot sphere, obstacle), the squared outside distance of the sphere centre in
the obstacle's frame, Σ_k max(|p_k| − h_k, 0)² ≥ (r + margin)² for a box of half sizes h (a cylinder: the radial
excess √(p_x² + p_y²) − R and the axial excess |p_z| − L/2). Its feasible set is exactly the true one (no rounding,
no conservatism) and it is continuously differentiable with a Lipschitz gradient (|·| and the norm's kink lie where
max(·, 0) is already 0); only its second derivative jumps across the planes of the faces, which IPOPT tolerates.
Its weakness: inside the obstacle the row is flat (zero gradient), so a guess deep inside a box gives IPOPT no
direction there (the ladder's OMPL guess is the remedy). `ocpkit bench shapes` measures their rows and solve time.

Terms that can never be active are left out, which keeps the NLP (and IPOPT's KKT system) small: every
robot sphere stays within its reach ρ of a fixed anchor (`ocpkit.robots.sphere_reach`), so a sphere whose
reach ball cannot touch an obstacle or a workspace face gets no constraint for it. The kept terms are the
constraint's shape: moving an obstacle keeps the build unless it crosses a sphere's reach boundary. Spheres
on the fixed base never move at all; they are checked once, when the problem is validated. The clearance
margin is an NLP parameter (a refinement round may raise it), so terms are kept up to MAX_MARGIN.
`screened` goes further for robots with many terms: it keeps only the terms near given configurations (the
planner's active set, ocpkit.planner.screening); the pairs and terms kept are then part of the shape too.

Grouped rows. An arm with a spherized model (MotionBenchMaker's Panda and UR5: 700–1 100 terms per point,
against the paper robot's 60–90) would put thousands of rows into IPOPT's KKT system. Beyond GROUP_ABOVE terms per
point (counted before screening), the terms of one group — one joint's spheres against one obstacle, or the sphere
pairs between two joints — become one row, their soft minimum (`soft_minimum`): smooth, never above the smallest
term, so a grouped row ≥ 0 still keeps every sphere clear (conservative by at most log(terms) / SOFTMIN_SHARPNESS
m², under 2 mm of distance at the spheres' sizes), and `verify` checks every sphere as before. Each term keeps its
own margin and cap inside its group.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.constraints.base import Constraint, Context, PointValues, Rows
from ocpkit.geometry.clearances import clearances, sphere_centers_batch
from ocpkit.problem import Problem
from ocpkit.robots import sphere_reach

MAX_MARGIN = 0.1  # m: the largest clearance margin the kept collision terms stay valid for
GROUP_ABOVE = 200  # collision terms per point above which they are grouped into one row per group (docstring)
SOFTMIN_SHARPNESS = 2e4  # 1/m²: β of a group's soft minimum; it lies at most log(terms) / β below the minimum
RADIAL_EPS = 1e-12  # m²: under the cylinder's radial root (shifts it by < 1e-9 m where it counts, radii ≥ 1 mm)


def active_terms(problem: Problem) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the collision terms that can become active with a margin up to MAX_MARGIN: obstacles
    (M, S + B + C: spheres, boxes, cylinders, each bounded by a sphere), workspace faces
    [x, y, z min, x, y, z max] (M, 6), or (M, 0) without a workspace."""
    robot, scene = problem.robot, problem.scene
    anchors, reach = sphere_reach(robot)
    moving = (robot.sphere_joint > 0)[:, None]
    span = (reach + robot.sphere_radius + MAX_MARGIN)[:, None]
    centers = np.concatenate([scene.obstacle_centers, scene.boxes.centers, scene.cylinders.centers])
    radii = np.concatenate([scene.obstacle_radii, scene.boxes.bounding_radii(), scene.cylinders.bounding_radii()])
    gaps = np.linalg.norm(anchors[:, None, :] - centers[None], axis=-1)
    obstacles = (gaps <= span + radii[None, :]) & moving
    if scene.workspace is None:
        return obstacles, np.zeros((len(reach), 0), dtype=bool)
    faces = np.hstack([anchors - scene.workspace.lower, scene.workspace.upper - anchors])
    return obstacles, (faces <= span) & moving


@dataclass(frozen=True)
class Terms:
    """The collision terms at one point in `SphereCollision.evaluate`'s order (the margin caps' order), the rows
    they make and the workspace rows after them."""

    kind: np.ndarray  # (T,): 0 a self-collision pair, 1 a sphere against an obstacle sphere, 2 a box, 3 a cylinder
    first: np.ndarray  # (T,): the robot sphere (a pair's first)
    second: np.ndarray  # (T,): a pair's second sphere, else the obstacle's index among its kind
    groups: tuple[np.ndarray, ...]  # the terms of each row (one each unless `grouped`), in row order
    face_sphere: np.ndarray  # (F,): each workspace row's sphere
    face_axis: np.ndarray  # (F,): its axis (0 x, 1 y, 2 z)
    face_sides: np.ndarray  # (F,): 1 the lower face, 2 the upper, 3 both


class SphereCollision(Constraint):
    """Clearance ≥ margin (m) between robot spheres, to the obstacles and to the workspace box.

    Obstacles are spheres, boxes and cylinders (module docstring)."""

    name = "collision"

    def __init__(self, problem: Problem) -> None:
        super().__init__(problem)
        self.obstacle_mask, self.face_mask = active_terms(problem)
        scene = problem.scene
        self.counts = (len(scene.obstacle_radii), len(scene.boxes), len(scene.cylinders))
        pairs = self.robot.self_collision
        self.pair_mask = (self.robot.sphere_joint[pairs] > 0).any(axis=1) if len(pairs) else np.zeros(0, bool)
        self.grouped = self.term_count > GROUP_ABOVE

    @property
    def pairs(self) -> np.ndarray:
        """The self-collision sphere pairs with rows (P, 2)."""
        return self.robot.self_collision[self.pair_mask]

    @property
    def term_count(self) -> int:
        """Collision rows per point."""
        return int(self.pair_mask.sum() + self.obstacle_mask.sum() + len(self._face_rows()[0]))

    def _face_rows(self) -> tuple[np.ndarray, np.ndarray]:
        """(sphere, axis) of each workspace row: one per axis with a reachable face."""
        return np.nonzero(self.face_mask[:, :3] | self.face_mask[:, 3:])

    def margin_caps(self, problem: Problem) -> np.ndarray:
        """Per row, in `evaluate`'s order: half the row's clearance (m) at the start or the goal, whichever is smaller
        (≥ 0): the largest margin it can take while its own ends keep it."""
        ends = problem.end_clearances
        m, axis = self._face_rows()
        faces = np.minimum(np.where(self.face_mask[m, axis], ends.workspace[:, m, axis], np.inf),
                           np.where(self.face_mask[m, axis + 3], ends.workspace[:, m, axis + 3], np.inf))
        rows = np.concatenate([ends.self_pairs[:, self.pair_mask], ends.obstacles[:, self.obstacle_mask], faces],
                              axis=1)
        return np.maximum(0.5 * rows.min(axis=0, initial=np.inf), 0.0)

    def shape(self) -> tuple:
        return (self.counts, self.obstacle_mask.shape, self.obstacle_mask.tobytes(), self.face_mask.shape,
                self.face_mask.tobytes(), self.pair_mask.tobytes(), self.grouped)

    def screened(self, problem: Problem, near: np.ndarray, distance: float) -> SphereCollision:
        """A copy keeping the terms whose clearance (m) is below `distance` at some configuration of `near`."""
        close = self._close(problem, near, distance)
        kept = copy.copy(self)
        kept.pair_mask, kept.obstacle_mask, kept.face_mask = (mask & near_ for mask, near_ in zip(
            (self.pair_mask, self.obstacle_mask, self.face_mask), close))
        kept.screened_at = distance
        return kept

    def missing(self, problem: Problem, near: np.ndarray, distance: float) -> int:
        """Terms this constraint has no rows for (screened out, not beyond reach) with a clearance below `distance`
        (m) at some configuration of `near`."""
        unscreened = SphereCollision(problem)
        close = self._close(problem, near, distance)
        return int(sum((full & near_ & ~mask).sum() for full, near_, mask in zip(
            (unscreened.pair_mask, unscreened.obstacle_mask, unscreened.face_mask), close,
            (self.pair_mask, self.obstacle_mask, self.face_mask))))

    def _close(self, problem: Problem, near: np.ndarray, distance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Masks shaped like (pair_mask, obstacle_mask, face_mask) of the terms with a clearance (m) below
        `distance` at some configuration of `near` (K, n) in `problem`'s scene."""
        c = clearances(self.robot, problem.scene, sphere_centers_batch(self.robot, near))
        return tuple(values.min(axis=0, initial=np.inf) < distance
                     for values in (c.self_pairs, c.obstacles, c.workspace))

    def parameter_shapes(self) -> dict[str, tuple[int, int]]:
        spheres, boxes, cylinders = self.counts
        return {"obstacle_center": (spheres, 3), "obstacle_radius": (spheres, 1),
                "box_center": (boxes, 3), "box_half_size": (boxes, 3), "box_rotation": (boxes, 9),
                "cylinder_center": (cylinders, 3), "cylinder_half_size": (cylinders, 2),  # [radius, length / 2]
                "cylinder_rotation": (cylinders, 9),  # rotations row-major
                "workspace": (self.face_mask.shape[1], 1),  # [lower (3), upper (3)] or nothing
                "margin_cap": (self.term_count, 1)}  # per term

    def parameter_values(self, problem: Problem) -> dict[str, np.ndarray]:
        scene = problem.scene
        box = [] if self.face_mask.shape[1] == 0 else [scene.workspace.lower, scene.workspace.upper]
        boxes, cylinders = scene.boxes, scene.cylinders
        return {"obstacle_center": scene.obstacle_centers, "obstacle_radius": scene.obstacle_radii,
                "box_center": boxes.centers, "box_half_size": 0.5 * boxes.sizes,
                "box_rotation": boxes.rotations.reshape(-1, 9),
                "cylinder_center": cylinders.centers,
                "cylinder_half_size": np.column_stack([cylinders.radii, 0.5 * cylinders.lengths]),
                "cylinder_rotation": cylinders.rotations.reshape(-1, 9),
                "workspace": np.concatenate([np.zeros(0), *box]), "margin_cap": self.margin_caps(problem)}

    def terms(self) -> Terms:
        """The terms at one point in `evaluate`'s order, the rows they make and the workspace rows (Terms)."""
        spheres, boxes, _ = self.counts
        m, s = np.nonzero(self.obstacle_mask)
        kinds = np.searchsorted([spheres, spheres + boxes], s, side="right")  # 0 sphere, 1 box, 2 cylinder
        first_of_kind = np.array([0, spheres, spheres + boxes])
        kind = np.concatenate([np.zeros(len(self.pairs), int), 1 + kinds])
        first = np.concatenate([self.pairs[:, 0], m]).astype(int)
        second = np.concatenate([self.pairs[:, 1], s - first_of_kind[kinds]]).astype(int)
        joint = self.robot.sphere_joint
        labels = [("self", joint[a], joint[b]) for a, b in self.pairs] + \
            [("obstacle", joint[a], o) for a, o in zip(m, s)]
        members: dict[tuple, list[int]] = {}
        for index, label in enumerate(labels):
            members.setdefault(label if self.grouped else index, []).append(index)
        face_sphere, face_axis = self._face_rows()
        sides = self.face_mask[face_sphere, face_axis] + 2 * self.face_mask[face_sphere, face_axis + 3]
        return Terms(kind, first, second, tuple(np.asarray(v, dtype=int) for v in members.values()), face_sphere,
                     face_axis, sides.astype(int))

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        """Rows ≥ 0 (workspace rows of two faces ≤ 1), each term with the margin min(margin, its cap)
        (`margin_caps`); with `grouped`, one row per group of terms (module docstring)."""
        radius, p = self.robot.sphere_radius, context.parameters
        margins = [ca.fmin(context.margin, p["margin_cap"][k]) for k in range(self.term_count)]
        centers = context.dynamics.sphere_centers(point.q)
        terms = self.terms()
        values = []
        for index, (kind, a, b) in enumerate(zip(terms.kind, terms.first, terms.second)):
            if kind <= 1:
                other, reach = (centers[b, :], radius[b]) if kind == 0 else \
                    (p["obstacle_center"][b, :], p["obstacle_radius"][b])
                gap = centers[a, :] - other
                values.append(ca.dot(gap, gap) - (radius[a] + reach + margins[index]) ** 2)
            else:
                name = "box" if kind == 2 else "cylinder"
                local = _local(centers[a, :], p[f"{name}_center"][b, :], p[f"{name}_rotation"][b, :])
                outside = _outside_squared(local, p[f"{name}_half_size"][b, :], kind == 3)
                values.append(outside - (radius[a] + margins[index]) ** 2)
        g = [soft_minimum([values[k] for k in group]) for group in terms.groups]
        upper = [np.inf] * len(g)
        box = p["workspace"]
        for index, (m, axis, sides) in enumerate(zip(terms.face_sphere, terms.face_axis, terms.face_sides)):
            g.append(_workspace_row(box, centers[m, axis], radius[m] + margins[len(values) + index], axis,
                                    self.face_mask[m]))
            upper.append(1.0 if sides == 3 else np.inf)
        g = ca.vertcat(*g) if g else ca.SX(0, 1)
        return Rows(g, np.zeros(g.numel()), np.asarray(upper, dtype=float))


def soft_minimum(terms: list[ca.SX]) -> ca.SX:
    """A smooth lower bound of min(terms) (m²), within log(len(terms)) / SOFTMIN_SHARPNESS of it:
    m − log Σ exp(−β (t − m)) / β with m = min(terms), exact for one term."""
    if len(terms) == 1:
        return terms[0]
    values = ca.vertcat(*terms)
    low = ca.mmin(values)
    return low - ca.log(ca.sum1(ca.exp(-SOFTMIN_SHARPNESS * (values - low)))) / SOFTMIN_SHARPNESS


def _local(c: ca.SX, center: ca.SX, rotation: ca.SX) -> ca.SX:
    """Point c (1, 3) in the frame of an obstacle at `center` (1, 3) with row-major `rotation` (1, 9): (3, 1)."""
    return ca.reshape(rotation, 3, 3) @ (c - center).T  # reshape is column-major: it gives Rᵀ


def _outside_squared(local: ca.SX, half: ca.SX, cylinder: bool) -> ca.SX:
    """Squared distance (m²) from a point (3, 1) in the obstacle's frame to a box of half sizes `half` (1, 3), or
    to a cylinder of half = [radius, half length] along z; 0 inside. √(x² + y² + RADIAL_EPS) keeps the radial
    term's derivative finite on the axis."""
    if cylinder:
        excess = ca.vertcat(ca.sqrt(local[0] ** 2 + local[1] ** 2 + RADIAL_EPS) - half[0],
                            ca.fabs(local[2]) - half[1])
    else:
        excess = ca.fabs(local) - half.T
    outside = ca.fmax(excess, 0)
    return ca.dot(outside, outside)


def _workspace_row(box: ca.SX, c: ca.SX, inset: ca.SX, axis: int, faces: np.ndarray) -> ca.SX:
    """One row per axis, ≥ 0 when inside the box [lower (3), upper (3)]: both faces reachable → the position
    scaled to [0, 1] between them (one two-sided row, half the rows of two one-sided ones); else the one
    reachable face."""
    low, high = box[axis] + inset, box[axis + 3] - inset
    if faces[axis] and faces[axis + 3]:
        return (c - low) / (high - low)
    return c - low if faces[axis] else high - c
