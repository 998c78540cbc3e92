"""The smallest clearance of each kind per configuration, for many configurations at once: what
`ocpkit.geometry.clearances` gives, reduced to its minimum per configuration, without computing every pair.

The robot's spheres are split, joint by joint, into groups of at most GROUP_SIZE neighbours (`sphere_groups`),
each inside a bounding sphere fixed to the same joint. A distance to a point or to a convex obstacle changes by at
most as much as the point moves, so a pair's clearance is at least its groups' bound: the clearance of the
bounding spheres from each other, or of a bounding sphere from the obstacle. Only the pairs whose bound is at most
`within` are computed, so a configuration's smallest clearance is exact wherever it is at most `within`;
elsewhere the value is a lower bound above `within`. `within` starts at WITHIN and doubles for a kind until its
smallest value over all the configurations is exact. So that minimum, every contact and every clearance up to
`within` are what `clearances` gives (tests/geometry/test_nearest.py); a dense verification of a long motion of a
robot with thousands of sphere pairs computes a small part of them. The workspace clearances are cheap and
computed for every sphere. A small robot among few obstacles has all its clearances computed (FULL_TERMS).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ocpkit.geometry.clearances import clearances, points_on_joints, sphere_centers_batch, workspace_clearances
from ocpkit.geometry.distance import box_distance, box_distance_each, cylinder_distance, cylinder_distance_each
from ocpkit.geometry.scene import Scene
from ocpkit.robots import Robot

GROUP_SIZE = 6  # spheres in a group at most
WITHIN = 0.02  # m: the first threshold below which the smallest clearances are exact
SLICE = 20_000  # candidate groups computed at once (bounds the memory of a long motion)
FULL_TERMS = 100  # pair clearances per configuration up to which computing them all is faster


@dataclass(frozen=True)
class Nearest:
    """The smallest clearance (m) per configuration (K,) of each kind: self pairs, obstacles, workspace faces; inf
    where the kind has nothing to check. Exact as `smallest_clearances` says: every value up to its kind's last
    threshold and each kind's minimum; a larger value is a lower bound of the configuration's smallest clearance."""

    self_pairs: np.ndarray
    obstacles: np.ndarray
    workspace: np.ndarray


@dataclass(frozen=True)
class SphereGroups:
    """A robot's spheres in groups on their joints: group g holds the spheres members[g][member_mask[g]] (G, W),
    inside a sphere of radius radius[g] (m) at offset[g] (m) in the frame of joint joint[g]. The self-collision
    pairs by the groups of their spheres: group_pairs (Q, 2), and per group pair its sphere pairs
    first[q][pair_mask[q]] with second[q][pair_mask[q]] (Q, V)."""

    joint: np.ndarray
    offset: np.ndarray
    radius: np.ndarray
    members: np.ndarray
    member_mask: np.ndarray
    group_pairs: np.ndarray
    first: np.ndarray
    second: np.ndarray
    pair_mask: np.ndarray


@functools.lru_cache(maxsize=32)
def sphere_groups(robot: Robot) -> SphereGroups:
    """The groups of `robot`'s spheres (module docstring; robots hash by identity): each joint's spheres halved
    across their widest extent until at most GROUP_SIZE remain together."""
    members: list[np.ndarray] = []
    for joint in np.unique(robot.sphere_joint):
        _halve(np.flatnonzero(robot.sphere_joint == joint), robot.sphere_offset, members)
    offsets = [robot.sphere_offset[m] for m in members]
    middle = np.array([(o.min(axis=0) + o.max(axis=0)) / 2 for o in offsets]).reshape(-1, 3)
    radius = np.array([np.max(np.linalg.norm(o - c, axis=1) + robot.sphere_radius[m])
                       for o, c, m in zip(offsets, middle, members)])
    group_of = np.zeros(len(robot.sphere_radius), dtype=int)
    for g, m in enumerate(members):
        group_of[m] = g
    by_groups: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for a, b in robot.self_collision.tolist():
        by_groups.setdefault((group_of[a], group_of[b]), []).append((a, b))
    first, pair_mask = _padded([[a for a, _ in pairs] for pairs in by_groups.values()])
    second, _ = _padded([[b for _, b in pairs] for pairs in by_groups.values()])
    grouped, member_mask = _padded(members)
    return SphereGroups(robot.sphere_joint[[m[0] for m in members]], middle, radius, grouped, member_mask,
                        np.array(list(by_groups), dtype=int).reshape(-1, 2), first, second, pair_mask)


def _halve(spheres: np.ndarray, offsets: np.ndarray, groups: list[np.ndarray]) -> None:
    """Append `spheres` (indices into offsets (M, 3)) to `groups`, halved across their widest extent until at most
    GROUP_SIZE remain together."""
    if len(spheres) <= GROUP_SIZE:
        groups.append(spheres)
        return
    own = offsets[spheres]
    ordered = spheres[np.argsort(own[:, np.argmax(np.ptp(own, axis=0))], kind="stable")]
    _halve(ordered[: len(ordered) // 2], offsets, groups)
    _halve(ordered[len(ordered) // 2:], offsets, groups)


def _padded(rows: list) -> tuple[np.ndarray, np.ndarray]:
    """Integer rows of different lengths as one array (R, W), padded with 0, and the mask of real entries."""
    width = max((len(row) for row in rows), default=0)
    out, mask = np.zeros((len(rows), width), dtype=int), np.zeros((len(rows), width), dtype=bool)
    for i, row in enumerate(rows):
        out[i, :len(row)], mask[i, :len(row)] = row, True
    return out, mask


def smallest_clearances(robot: Robot, scene: Scene, qs: np.ndarray) -> Nearest:
    """The smallest clearance of each kind at each configuration of qs (K, n), exact as the module docstring says;
    exact everywhere for a robot and scene with at most FULL_TERMS pair clearances a configuration (a small robot
    among few obstacles), where computing them all (`clearances`) is the faster way."""
    qs = np.atleast_2d(np.asarray(qs, dtype=float))
    centers = sphere_centers_batch(robot, qs)  # (K, M, 3)
    obstacles = len(scene.obstacle_radii) + len(scene.boxes) + len(scene.cylinders)
    if len(robot.self_collision) + len(robot.sphere_radius) * obstacles <= FULL_TERMS:
        full = clearances(robot, scene, centers)
        return Nearest(*map(_per_configuration, (full.self_pairs, full.obstacles, full.workspace)))
    groups = sphere_groups(robot)
    bounds = points_on_joints(robot, qs, groups.joint, groups.offset)  # (K, G, 3)
    near = _Near(robot, scene, groups, centers, bounds)
    return Nearest(_doubled(near.self_pairs), _doubled(near.obstacles),
                   _per_configuration(workspace_clearances(robot, scene, centers)))


def _per_configuration(values: np.ndarray) -> np.ndarray:
    """The smallest of values (K, ...) per configuration (K,), inf where there are none."""
    return values.reshape(len(values), -1).min(axis=1, initial=np.inf)


def _doubled(smallest: Callable[[float], np.ndarray]) -> np.ndarray:
    """`smallest(within)` (K,) for within = WITHIN, 2 WITHIN, ... until its minimum is at most `within` (exact) or
    it is inf everywhere (nothing to check)."""
    within = WITHIN
    while True:
        values = smallest(within)
        if np.isinf(values).all() or values.min() <= within:
            return values
        within *= 2


@dataclass(frozen=True)
class _Near:
    """One call's positions: sphere centres (K, M, 3) and group bounding-sphere centres (K, G, 3)."""

    robot: Robot
    scene: Scene
    groups: SphereGroups
    centers: np.ndarray
    bounds: np.ndarray

    def self_pairs(self, within: float) -> np.ndarray:
        """The smallest self-pair clearance per configuration (K,), exact where at most `within` (m)."""
        groups, r = self.groups, self.robot.sphere_radius
        a, b = groups.group_pairs.T
        gap = self.bounds[:, a] - self.bounds[:, b]
        bound = np.sqrt(np.einsum("kqi,kqi->kq", gap, gap)) - groups.radius[a] - groups.radius[b]  # (K, Q)

        def exact(k: np.ndarray, q: np.ndarray) -> np.ndarray:
            first, second = groups.first[q], groups.second[q]
            gap = self.centers[k[:, None], first] - self.centers[k[:, None], second]
            d = np.sqrt(np.einsum("nvi,nvi->nv", gap, gap)) - r[first] - r[second]
            return np.where(groups.pair_mask[q], d, np.inf).min(axis=1)

        return _refined(bound, within, exact)

    def obstacles(self, within: float) -> np.ndarray:
        """The smallest obstacle clearance per configuration (K,), exact where at most `within` (m)."""
        scene = self.scene
        radius = self.groups.radius[None, :, None]
        kinds = []
        if len(scene.obstacle_radii):
            offsets = self.bounds[:, :, None] - scene.obstacle_centers[None, None]
            distance = np.sqrt(np.einsum("kgsi,kgsi->kgs", offsets, offsets)) - scene.obstacle_radii
            kinds.append((distance - radius, lambda p, o: np.linalg.norm(p - scene.obstacle_centers[o][:, None],
                                                                         axis=-1) - scene.obstacle_radii[o][:, None]))
        if len(scene.boxes):
            kinds.append((box_distance(self.bounds, scene.boxes) - radius,
                          lambda p, o: box_distance_each(p, scene.boxes, o)))
        if len(scene.cylinders):
            kinds.append((cylinder_distance(self.bounds, scene.cylinders) - radius,
                          lambda p, o: cylinder_distance_each(p, scene.cylinders, o)))
        smallest = np.full(len(self.centers), np.inf)
        for bound, distance_each in kinds:  # bound (K, G, O): a group's bounding sphere from each obstacle
            exact = functools.partial(self._obstacle, distance_each, bound.shape[2])
            smallest = np.minimum(smallest, _refined(bound.reshape(len(bound), -1), within, exact))
        return smallest

    def _obstacle(self, distance_each: Callable[[np.ndarray, np.ndarray], np.ndarray], count: int, k: np.ndarray,
                  flat: np.ndarray) -> np.ndarray:
        """The smallest clearance of the spheres of group g from obstacle o (one kind of `count` obstacles) at
        configuration k, for index arrays k and flat = g · count + o; `distance_each(points (n, w, 3), o (n,))`
        gives the obstacles' signed distances (n, w)."""
        g, o = np.divmod(flat, count)
        members = self.groups.members[g]
        d = distance_each(self.centers[k[:, None], members], o) - self.robot.sphere_radius[members]
        return np.where(self.groups.member_mask[g], d, np.inf).min(axis=1)


def _refined(bound: np.ndarray, within: float, exact: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
    """Per configuration (K,), the smallest of the lower bounds `bound` (K, Q) above `within` and of
    `exact(k, q)` (the smallest exact clearance in group pair or group–obstacle q at configuration k, for index
    arrays k, q) where the bound is at most `within`."""
    candidate = bound <= within
    smallest = np.where(candidate, np.inf, bound).min(axis=1, initial=np.inf)
    k, q = np.nonzero(candidate)
    for start in range(0, len(k), SLICE):
        part = slice(start, start + SLICE)
        np.minimum.at(smallest, k[part], exact(k[part], q[part]))
    return smallest
