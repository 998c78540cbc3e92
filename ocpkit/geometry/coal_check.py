"""The sphere model's yes/no collision test in C++: pinocchio's kinematics, coal's broad and narrow phases.

`CoalCheck(robot, scene, margin)` answers what `clearances(...) >= margin` answers (ocpkit.geometry.clearances,
the verifier's model), for many configurations in one call: the robot's spheres become coal spheres on their
joints, the obstacles coal spheres, boxes and cylinders fixed in the world, the region beyond each of the
workspace's six faces a large box (`_world_shapes`). The checked pairs are the robot's self-collision pairs and
each sphere against each obstacle and face. It is the path search's test (ocpkit.planner.ompl_seed); `verify`
keeps the NumPy reference.

A broad phase (through pinocchio's broad-phase manager) hands the narrow phase only the pairs whose bounding boxes
overlap. It is coal's naive manager, which tests every two boxes of a configuration: for the hundred-odd spheres
and few obstacles of a robot in a scene that is faster than refitting and walking coal's dynamic AABB tree
(docs/design-notes.md, 2026-12-04). For the broad phase to be exact, every robot sphere is grown by
i = max(margin, 0) and each pair's security margin (coal counts a pair as colliding when its distance is below it)
takes the rest: margin − i for a sphere against an obstacle, margin − 2i for two spheres. Both are ≤ 0, so a pair
that counts as colliding overlaps its grown boxes, and its clearance is below `margin` exactly when coal says it
collides.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from ocpkit.geometry.scene import Scene
from ocpkit.robots import Robot


SLAB = 1e3  # m: the edge of the cube standing in for the half-space beyond a workspace face (`_world_shapes`)


class CoalCheck:
    """Collision tests of `robot` in `scene` keeping `margin` (m) of clearance."""

    def __init__(self, robot: Robot, scene: Scene, margin: float) -> None:
        grown = max(margin, 0.0)
        model = pin.GeometryModel()
        spheres = [model.addGeometryObject(pin.GeometryObject(
            f"sphere {m}", int(joint), pin.SE3(np.eye(3), offset), coal.Sphere(float(radius) + grown)))
            for m, (joint, offset, radius) in enumerate(zip(robot.sphere_joint, robot.sphere_offset,
                                                             robot.sphere_radius))]
        fixed = [model.addGeometryObject(pin.GeometryObject(name, 0, pose, shape))
                 for name, pose, shape in _world_shapes(scene)]
        for a, b in robot.self_collision:
            model.addCollisionPair(pin.CollisionPair(spheres[a], spheres[b]))
        for sphere in spheres:
            for body in fixed:
                model.addCollisionPair(pin.CollisionPair(sphere, body))
        self.geometry, self.geometry_data = model, pin.GeometryData(model)  # kept: the manager points to them
        grown_pair = [2 * grown if pair.second < len(spheres) else grown for pair in model.collisionPairs]
        for request, taken in zip(self.geometry_data.collisionRequests, grown_pair):
            request.security_margin = margin - taken
            request.enable_contact = False
        self.model, self.data = robot.model, robot.model.createData()
        self.manager = pin.BroadPhaseManager_NaiveCollisionManager(self.model, self.geometry, self.geometry_data)

    def free(self, q: np.ndarray) -> np.ndarray:
        """Whether each configuration of q (K, n) keeps the margin everywhere: shape (K,), bool."""
        return ~self._collides(q, stop_at_first=False)

    def first_collision(self, q: np.ndarray) -> int | None:
        """The index of the first configuration of q (K, n) that does not keep the margin, None if all do; the
        ones after it are not checked."""
        hits = np.flatnonzero(self._collides(q, stop_at_first=True))
        return int(hits[0]) if len(hits) else None

    def _collides(self, q: np.ndarray, stop_at_first: bool) -> np.ndarray:
        """Per configuration of q (K, n), whether some pair is within the margin (bool (K,)); with `stop_at_first`
        the configurations after the first such one are left False."""
        q = np.atleast_2d(np.asarray(q, dtype=float))
        hits = np.zeros(len(q), dtype=bool)
        for k, configuration in enumerate(q):  # each call stops at its first colliding pair
            hits[k] = pin.computeCollisions(self.model, self.data, self.manager, configuration, True)
            if hits[k] and stop_at_first:
                break
        return hits


def _world_shapes(scene: Scene) -> list[tuple[str, pin.SE3, coal.CollisionGeometry]]:
    """(name, pose in the world, coal shape) of every obstacle and, with a workspace, of the region beyond each of
    its faces: a cube of edge SLAB against the face, centred on the workspace's centre across it, the same as the
    half-space for every sphere within SLAB / 2 of that centre, which is every sphere a robot can reach. (coal's
    Halfspace has an unbounded bounding box, which coal's dynamic AABB tree missed; a cube is safe in any broad
    phase.)"""
    shapes = [("sphere", pin.SE3(np.eye(3), c), coal.Sphere(float(r)))
              for c, r in zip(scene.obstacle_centers, scene.obstacle_radii)]
    shapes += [("box", pin.SE3(rotation, c), coal.Box(*map(float, size)))
               for c, size, rotation in zip(scene.boxes.centers, scene.boxes.sizes, scene.boxes.rotations)]
    cylinders = scene.cylinders
    shapes += [("cylinder", pin.SE3(rotation, c), coal.Cylinder(float(r), float(length)))
               for c, r, length, rotation in zip(cylinders.centers, cylinders.radii, cylinders.lengths,
                                                 cylinders.rotations)]
    if scene.workspace is not None:
        lower, upper = scene.workspace.lower, scene.workspace.upper
        for axis in range(3):
            for name, face, side in (("below", lower[axis], -1.0), ("above", upper[axis], 1.0)):
                center = (lower + upper) / 2
                center[axis] = face + side * SLAB / 2
                shapes.append((name, pin.SE3(np.eye(3), center), coal.Box(SLAB, SLAB, SLAB)))
    return shapes
