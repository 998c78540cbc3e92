"""The path search's collision test in compiled C: the sphere model's yes/no answer, one configuration after another.

`SphereCheck(robot, scene, margin)` answers what `clearances(...) >= margin` answers (ocpkit.geometry.clearances,
the verifier's model) for many configurations in one call, in C (sphere_check.c after ocpkit/solvers/chain.c,
compiled once per machine: ocpkit.solvers.chain): the joints' poses by Rodrigues' formula from the model's
placements (the joints `sphere_centers_batch` composes), the sphere centres, then every sphere against every
obstacle and workspace face and every self-collision pair, stopping at the first clearance below the margin. The
signed distances are ocpkit.geometry.distance's. What makes it fast is what it does not test: the spheres on one
joint (a link) have a bounding sphere, and a link whose bound keeps clear of an obstacle, or of another link, skips
all its spheres' tests against it; so does a sphere whose own distance to an obstacle's centre exceeds the
obstacle's reach. Both skips are exact (a skipped pair's clearance is above the margin). `collision_check` returns
it, or coal's test (ocpkit.geometry.coal_check: the same answers, slower) when there is no C compiler.
"""

from __future__ import annotations

import ctypes
import functools

import numpy as np

from ocpkit.geometry.coal_check import CoalCheck
from ocpkit.geometry.scene import Scene
from ocpkit.robots import Robot
from ocpkit.solvers.chain import INT, REAL, Chain, CArrays, chain, chain_work, kernel


class _Model(ctypes.Structure):
    """sphere_check.c's Model, field for field."""

    _fields_ = [("chain", Chain), ("spheres", ctypes.c_int), ("sphere_joint", INT), ("offset", REAL),
                ("radius", REAL), ("links", ctypes.c_int), ("link_joint", INT), ("link_first", INT),
                ("link_end", INT), ("link_center", REAL), ("link_reach", REAL), ("link_pairs", ctypes.c_int),
                ("pair_link_a", INT), ("pair_link_b", INT), ("pair_first", INT), ("pair_end", INT), ("pair_a", INT),
                ("pair_b", INT), ("obstacles", ctypes.c_int), ("kind", INT), ("center", REAL), ("axes", REAL),
                ("half", REAL), ("bound", REAL), ("workspace", ctypes.c_int), ("lower", REAL), ("upper", REAL),
                ("margin", ctypes.c_double)]


@functools.cache
def _kernel() -> ctypes.CDLL | None:
    """sphere_check.c's library (after chain.c), loaded once per process; None (with a warning) when it cannot be
    compiled or loaded."""
    library = kernel((("ocpkit.solvers", "chain.c"), ("ocpkit.planner", "sphere_check.c")), "the path search asks coal")
    if library is not None:
        library.sphere_check.restype = ctypes.c_int
        library.sphere_check.argtypes = [ctypes.POINTER(_Model), ctypes.c_void_p, ctypes.c_int, ctypes.c_int,
                                         ctypes.c_void_p, ctypes.c_void_p]
    return library


def collision_check(robot: Robot, scene: Scene, margin: float) -> SphereCheck | CoalCheck:
    """The fastest yes/no collision test of `robot` in `scene` keeping `margin` (m) this machine can run."""
    return CoalCheck(robot, scene, margin) if _kernel() is None else SphereCheck(robot, scene, margin)


class SphereCheck:
    """Collision tests of `robot` in `scene` keeping `margin` (m) of clearance (module docstring)."""

    def __init__(self, robot: Robot, scene: Scene, margin: float) -> None:
        self._kernel = _kernel()
        if self._kernel is None:
            raise RuntimeError("sphere_check.c did not compile: use collision_check, which falls back to coal")
        arrays = self._arrays = CArrays()  # what the Model points to, kept alive with it
        order = np.argsort(robot.sphere_joint, kind="stable")  # the spheres in link order
        place = np.empty_like(order)
        place[order] = np.arange(len(order))
        sphere_joint, offset, radius = robot.sphere_joint[order], robot.sphere_offset[order], robot.sphere_radius[order]
        link_joint, link_first = np.unique(sphere_joint, return_index=True)
        link_end = np.append(link_first[1:], len(order))
        link_center = np.array([offset[a:b].mean(axis=0) for a, b in zip(link_first, link_end)]).reshape(-1, 3)
        link_reach = np.array([(np.linalg.norm(offset[a:b] - c, axis=1) + radius[a:b]).max()
                               for a, b, c in zip(link_first, link_end, link_center)])
        link_of = np.searchsorted(link_joint, sphere_joint)  # each (ordered) sphere's link
        pairs = np.sort(place[robot.self_collision], axis=1) if len(robot.self_collision) else np.zeros((0, 2), int)
        pairs = pairs[np.lexsort(link_of[pairs].T[::-1])]  # grouped by link pair
        groups, pair_first = np.unique(link_of[pairs], axis=0, return_index=True)
        groups = groups.reshape(-1, 2)
        kind, center, axes, half, bound = _obstacles(scene)
        workspace = scene.workspace
        self.model = _Model(
            chain(robot, arrays), len(order), arrays.ints(sphere_joint), arrays.reals(offset), arrays.reals(radius),
            len(link_joint), arrays.ints(link_joint), arrays.ints(link_first), arrays.ints(link_end),
            arrays.reals(link_center), arrays.reals(link_reach),
            len(groups), arrays.ints(groups[:, 0]), arrays.ints(groups[:, 1]), arrays.ints(pair_first),
            arrays.ints(np.append(pair_first[1:], len(pairs))), arrays.ints(pairs[:, 0]), arrays.ints(pairs[:, 1]),
            len(kind), arrays.ints(kind), arrays.reals(center), arrays.reals(axes), arrays.reals(half),
            arrays.reals(bound), int(workspace is not None),
            arrays.reals(np.zeros(3) if workspace is None else workspace.lower),
            arrays.reals(np.zeros(3) if workspace is None else workspace.upper), float(margin))
        self._work = np.empty(chain_work(robot) + 3 * (len(order) + len(link_joint)))
        self._model_pointer = ctypes.byref(self.model)

    def free(self, q: np.ndarray) -> np.ndarray:
        """Whether each configuration of q (K, n) keeps the margin everywhere: shape (K,), bool."""
        return ~self._collides(q, stop_at_first=False)[0]

    def first_collision(self, q: np.ndarray) -> int | None:
        """The index of the first configuration of q (K, n) that does not keep the margin, None if all do; the
        ones after it are not checked."""
        first = self._collides(q, stop_at_first=True)[1]
        return None if first < 0 else first

    def _collides(self, q: np.ndarray, stop_at_first: bool) -> tuple[np.ndarray, int]:
        """Per configuration of q (K, n), whether it collides (bool (K,); with `stop_at_first` those after the
        first that does are left False), and the first one's index (−1: none)."""
        q = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        hits = np.zeros(len(q), dtype=np.uint8)
        first = self._kernel.sphere_check(self._model_pointer, q.ctypes.data, len(q), int(stop_at_first),
                                          hits.ctypes.data, self._work.ctypes.data)
        return hits.astype(bool), first


def _obstacles(scene: Scene) -> tuple[np.ndarray, ...]:
    """Per obstacle (spheres, boxes, cylinders): kind (0, 1, 2), centre (O, 3), rotation (O, 9) row-major, half
    sizes (O, 3) (sphere [radius, 0, 0], box half edges, cylinder [radius, length / 2, 0]), and the distance of
    its farthest point from its centre (O,)."""
    spheres, boxes, cylinders = len(scene.obstacle_radii), scene.boxes, scene.cylinders
    half = np.concatenate([np.column_stack([scene.obstacle_radii, np.zeros((spheres, 2))]), 0.5 * boxes.sizes,
                           np.column_stack([cylinders.radii, 0.5 * cylinders.lengths, np.zeros(len(cylinders))])])
    bound = np.concatenate([scene.obstacle_radii, boxes.bounding_radii(), cylinders.bounding_radii()])
    kind = np.repeat([0, 1, 2], [spheres, len(boxes), len(cylinders)])
    center = np.concatenate([scene.obstacle_centers, boxes.centers, cylinders.centers]).reshape(-1, 3)
    axes = np.concatenate([np.tile(np.eye(3).reshape(1, 9), (spheres, 1)), boxes.rotations.reshape(-1, 9),
                           cylinders.rotations.reshape(-1, 9)])
    return kind, center, axes, half.reshape(-1, 3), bound
