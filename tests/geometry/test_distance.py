"""Exact signed distances to boxes and cylinders against coal (an independent collision library) and closed forms."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from ocpkit.geometry.distance import box_distance, cylinder_distance
from ocpkit.geometry.scene import Boxes, Cylinders

RNG = np.random.default_rng(12)


def random_rotation(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """(quaternion [x, y, z, w], its rotation matrix from pinocchio)."""
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return q, pin.Quaternion(q[3], q[0], q[1], q[2]).toRotationMatrix()


def coal_clearance(shape: coal.CollisionGeometry, rotation: np.ndarray, center: np.ndarray, point: np.ndarray,
                   radius: float) -> float:
    """coal's signed distance between `shape` at (rotation, center) and a sphere of `radius` at `point`. The sphere
    is a capsule of length 1e-9 m: coal's GJK/EPA then answers; its specialised sphere–cylinder routine (coal 3.0)
    reports the radial depth for a centre inside a cylinder even when an end cap is nearer."""
    request = coal.DistanceRequest()
    request.gjk_tolerance = 1e-10  # a tighter EPA tolerance makes coal 3.0 stop early with worse depths
    return coal.distance(shape, coal.Transform3s(rotation, center), coal.Capsule(radius, 1e-9),
                         coal.Transform3s(np.eye(3), point), request, coal.DistanceResult())


def assert_close_to_coal(ours: np.ndarray, theirs: np.ndarray) -> None:
    """Equal within 1e-6 m where free (GJK) and 1e-4 m where overlapping (coal's EPA is iterative on curved
    shapes)."""
    free = theirs > 0
    np.testing.assert_allclose(ours[free], theirs[free], atol=1e-6)
    np.testing.assert_allclose(ours[~free], theirs[~free], atol=1e-4)


def points_around(center: np.ndarray, extent: float, rng: np.random.Generator, count: int) -> np.ndarray:
    """Points (count, 3): half within `extent` of the centre (many inside), half up to 3 × extent away."""
    near = center + rng.uniform(-extent, extent, (count // 2, 3))
    far = center + rng.uniform(-3 * extent, 3 * extent, (count - count // 2, 3))
    return np.vstack([near, far])


@pytest.mark.parametrize("seed", range(5))
def test_box_clearance_matches_coal_inside_and_outside(seed):
    rng = np.random.default_rng(seed)
    _, rotation = random_rotation(rng)
    center, size, radius = rng.uniform(-1, 1, 3), rng.uniform(0.05, 0.8, 3), 0.04
    boxes = Boxes(center[None], size[None], rotation[None])
    points = points_around(center, 0.5 * size.min(), rng, 200)
    ours = box_distance(points, boxes)[:, 0] - radius
    theirs = [coal_clearance(coal.Box(*size), rotation, center, p, radius) for p in points]
    assert (ours < -radius).sum() > 20 and (ours > 0).sum() > 20  # deep inside and free both sampled
    assert_close_to_coal(ours, np.asarray(theirs))


@pytest.mark.parametrize("seed", range(5))
def test_cylinder_clearance_matches_coal_inside_and_outside(seed):
    rng = np.random.default_rng(seed)
    _, rotation = random_rotation(rng)
    center, cyl_radius, length, radius = rng.uniform(-1, 1, 3), rng.uniform(0.03, 0.4), rng.uniform(0.05, 1.0), 0.03
    cylinders = Cylinders(center[None], np.array([cyl_radius]), np.array([length]), rotation[None])
    points = points_around(center, min(cyl_radius, 0.5 * length), rng, 200)
    ours = cylinder_distance(points, cylinders)[:, 0] - radius
    theirs = [coal_clearance(coal.Cylinder(cyl_radius, length), rotation, center, p, radius) for p in points]
    assert (ours < -radius).sum() > 20 and (ours > 0).sum() > 20
    assert_close_to_coal(ours, np.asarray(theirs))


def test_closed_forms_at_faces_edges_and_corners():
    boxes = Boxes(np.zeros((1, 3)), np.array([[2.0, 4.0, 6.0]]), np.eye(3)[None])
    points = np.array([[0, 0, 0], [0.5, 0, 0], [2, 0, 0], [2, 3, 0], [2, 3, 4], [0, 0, 2.9]])
    expected = [-1.0, -0.5, 1.0, np.hypot(1, 1), np.sqrt(3), -0.1]
    np.testing.assert_allclose(box_distance(points, boxes)[:, 0], expected)
    cylinders = Cylinders(np.zeros((1, 3)), np.array([1.0]), np.array([2.0]), np.eye(3)[None])
    points = np.array([[0, 0, 0], [0, 0, 3], [2, 0, 0], [0, 3, 4], [0.9, 0, 0.5]])
    np.testing.assert_allclose(cylinder_distance(points, cylinders)[:, 0], [-1, 2, 1, np.hypot(2, 3), -0.1])


def test_shapes_broadcast_over_leading_axes():
    boxes = Boxes(np.zeros((2, 3)), np.ones((2, 3)), np.stack([np.eye(3)] * 2))
    assert box_distance(np.zeros((4, 5, 3)), boxes).shape == (4, 5, 2)
    assert cylinder_distance(np.zeros((4, 5, 3)), Cylinders()).shape == (4, 5, 0)
