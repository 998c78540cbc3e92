"""The sphere model's yes/no collision test in C++: pinocchio's kinematics and coal's narrow phase.

`CoalCheck(robot, scene, margin)` answers what `clearances(...) >= margin` answers (ocpkit.geometry.clearances,
the verifier's model), for many configurations in one call: the robot's spheres become coal spheres on their
joints, the obstacles coal spheres, boxes and cylinders fixed in the world, the workspace's six faces half-spaces
(the region outside each face), and every checked pair (the robot's self-collision pairs, each sphere against each
obstacle and face) carries `margin` as coal's security margin, so a pair counts as colliding when its clearance is
below the margin. It is the path search's test (ocpkit.planner.ompl_seed); `verify` keeps the NumPy reference.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from ocpkit.geometry.scene import Scene
from ocpkit.robots import Robot


class CoalCheck:
    """Collision tests of `robot` in `scene` keeping `margin` (m) of clearance."""

    def __init__(self, robot: Robot, scene: Scene, margin: float) -> None:
        model = pin.GeometryModel()
        spheres = [model.addGeometryObject(pin.GeometryObject(
            f"sphere {m}", int(joint), pin.SE3(np.eye(3), offset), coal.Sphere(float(radius))))
            for m, (joint, offset, radius) in enumerate(zip(robot.sphere_joint, robot.sphere_offset,
                                                             robot.sphere_radius))]
        fixed = [model.addGeometryObject(pin.GeometryObject(name, 0, pose, shape))
                 for name, pose, shape in _world_shapes(scene)]
        for a, b in robot.self_collision:
            model.addCollisionPair(pin.CollisionPair(spheres[a], spheres[b]))
        for sphere in spheres:
            for body in fixed:
                model.addCollisionPair(pin.CollisionPair(sphere, body))
        self.pool = pin.GeometryPool(robot.model, model, 1)
        for data in self.pool.getGeometryDatas():
            for request in data.collisionRequests:
                request.security_margin = margin
                request.enable_contact = False

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
        columns = np.asfortranarray(np.atleast_2d(q).T)  # pinocchio takes configurations as columns
        return np.asarray(pin.computeCollisionsInParallel(1, self.pool, columns, True, stop_at_first), dtype=bool)


def _world_shapes(scene: Scene) -> list[tuple[str, pin.SE3, coal.CollisionGeometry]]:
    """(name, pose in the world, coal shape) of every obstacle and, with a workspace, of the half-space beyond each
    of its faces."""
    shapes = [("sphere", pin.SE3(np.eye(3), c), coal.Sphere(float(r)))
              for c, r in zip(scene.obstacle_centers, scene.obstacle_radii)]
    shapes += [("box", pin.SE3(rotation, c), coal.Box(*map(float, size)))
               for c, size, rotation in zip(scene.boxes.centers, scene.boxes.sizes, scene.boxes.rotations)]
    cylinders = scene.cylinders
    shapes += [("cylinder", pin.SE3(rotation, c), coal.Cylinder(float(r), float(length)))
               for c, r, length, rotation in zip(cylinders.centers, cylinders.radii, cylinders.lengths,
                                                 cylinders.rotations)]
    if scene.workspace is not None:
        for axis, normal in enumerate(np.eye(3)):  # coal's Halfspace(n, d) is the solid n·x ≤ d
            shapes.append(("below", pin.SE3.Identity(), coal.Halfspace(normal, float(scene.workspace.lower[axis]))))
            shapes.append(("above", pin.SE3.Identity(), coal.Halfspace(-normal, -float(scene.workspace.upper[axis]))))
    return shapes
