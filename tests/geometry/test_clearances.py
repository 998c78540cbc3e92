"""Sphere centres against pinocchio frame placements, clearances against closed forms, collision reports."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
import yaml

import ocpkit
import ocpkit.geometry.clearances
from ocpkit.geometry.clearances import Clearances, buried, clearances, collision_report, sphere_centers
from ocpkit.geometry.scene import Boxes, Scene, Workspace
from ocpkit.robots.robot import DATA_DIR

ROBOT = ocpkit.load_robot("industrial6")
M = len(ROBOT.sphere_radius)
RADIUS = ROBOT.sphere_radius
RNG = np.random.default_rng(5)
HOME = np.array([0.0, 0.0, 0.0, 0.0, -np.pi / 2, 0.0])


def reference_centers(q: np.ndarray) -> np.ndarray:
    """Sphere centres from spec.yaml (link frame) through pinocchio's frame placements."""
    spheres = yaml.safe_load((DATA_DIR / "industrial6/spec.yaml").read_text())["spheres"]
    model, data = ROBOT.model, ROBOT.model.createData()
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    return np.array([data.oMf[model.getFrameId(s["link"])].act(np.asarray(s["center"], float)) for s in spheres])


def test_sphere_centers_match_pinocchio_frame_placements():
    for q in RNG.uniform(ROBOT.q_lower, ROBOT.q_upper, (4, ROBOT.n)):
        np.testing.assert_allclose(sphere_centers(ROBOT, q), reference_centers(q), atol=1e-12)


def test_sphere_centers_match_joint_placements_acting_on_the_offsets():
    q = RNG.uniform(ROBOT.q_lower, ROBOT.q_upper)
    data = ROBOT.model.createData()
    pin.forwardKinematics(ROBOT.model, data, q)
    expected = [data.oMi[int(j)].act(offset) for j, offset in zip(ROBOT.sphere_joint, ROBOT.sphere_offset)]
    np.testing.assert_allclose(sphere_centers(ROBOT, q, data), expected, atol=1e-12)


def test_base_sphere_does_not_move_and_flange_sphere_does():
    a, b = sphere_centers(ROBOT, np.zeros(ROBOT.n)), sphere_centers(ROBOT, HOME + 0.5)
    np.testing.assert_allclose(a[0], b[0])
    assert np.linalg.norm(a[14] - b[14]) > 0.1


def test_batched_and_single_calls_agree():
    qs = RNG.uniform(ROBOT.q_lower, ROBOT.q_upper, (5, ROBOT.n))
    batched = sphere_centers(ROBOT, qs)
    assert batched.shape == (5, M, 3) and sphere_centers(ROBOT, qs[0]).shape == (M, 3)
    for q, centers in zip(qs, batched):
        np.testing.assert_array_equal(sphere_centers(ROBOT, q), centers)


def test_a_single_row_batch_keeps_its_batch_axis():
    assert sphere_centers(ROBOT, HOME[None]).shape == (1, M, 3)


def line_of_spheres() -> np.ndarray:
    """Hand-made centres (1, M, 3): sphere j at (10 j, 0, 0)."""
    return np.stack([10.0 * np.arange(M), np.zeros(M), np.zeros(M)], axis=1)[None]


def test_self_clearances_are_distance_minus_radii():
    c = clearances(ROBOT, Scene(), line_of_spheres())
    a, b = ROBOT.self_collision.T
    np.testing.assert_allclose(c.self_pairs[0], 10.0 * np.abs(a - b) - RADIUS[a] - RADIUS[b])
    assert c.self_pairs.shape == (1, len(a))


def test_obstacle_clearances_are_distance_minus_radii():
    scene = Scene(np.array([[0.0, 3.0, 0.0], [20.0, 0.0, 4.0]]), np.array([0.5, 1.0]))
    c = clearances(ROBOT, scene, line_of_spheres())
    x = 10.0 * np.arange(M)
    np.testing.assert_allclose(c.obstacles[0, :, 0], np.hypot(x, 3.0) - RADIUS - 0.5)
    np.testing.assert_allclose(c.obstacles[0, :, 1], np.hypot(x - 20.0, 4.0) - RADIUS - 1.0)


def test_workspace_clearances_are_face_distance_minus_radius():
    box = Workspace(np.array([-1.0, -2.0, -3.0]), np.array([200.0, 4.0, 5.0]))
    c = clearances(ROBOT, Scene(workspace=box), line_of_spheres())
    x = 10.0 * np.arange(M)
    expected = np.stack([x + 1, np.full(M, 2.0), np.full(M, 3.0), 200 - x, np.full(M, 4.0), np.full(M, 5.0)], axis=1)
    np.testing.assert_allclose(c.workspace[0], expected - RADIUS[:, None])
    assert c.smallest() == pytest.approx(1.0 - RADIUS[0])  # sphere 0, 1 m from x min


def test_a_configuration_is_buried_when_some_sphere_centre_lies_inside_an_obstacle_box():
    centers = np.concatenate([line_of_spheres(), line_of_spheres() + [0.0, 9.0, 0.0]])  # (2, M, 3)

    def box(y: float) -> Boxes:  # a 6 m cube at (20, y, 0): around sphere 2 of the first row when |y| < 3
        return Boxes(np.array([[20.0, y, 0.0]]), np.full((1, 3), 6.0), np.eye(3)[None])

    assert buried(ROBOT, Scene(boxes=box(2.0)), centers).tolist() == [True, False]  # the second row is 7 m away
    assert not buried(ROBOT, Scene(boxes=box(3.0 + 1e-3)), centers[:1])[0]  # touching sphere 2, not its centre
    around = Scene(np.array([[20.0, 0.0, 0.0]]), np.array([3.0]))  # a sphere obstacle's row keeps its gradient
    assert not buried(ROBOT, around, centers[:1])[0]


def test_without_a_workspace_there_are_no_face_clearances():
    c = clearances(ROBOT, Scene(), sphere_centers(ROBOT, np.stack([HOME, HOME])))
    assert c.workspace.shape == (2, M, 0) and c.obstacles.shape == (2, M, 0)


def test_smallest_takes_the_minimum_over_all_kinds_and_inf_when_empty():
    empty = Clearances(np.zeros((1, 0)), np.zeros((1, M, 0)), np.zeros((1, M, 0)))
    assert empty.smallest() == np.inf
    mixed = Clearances(np.array([[0.3, 0.2]]), np.full((1, M, 1), 0.5), np.full((1, M, 6), -0.01))
    assert mixed.smallest() == pytest.approx(-0.01)


def test_collision_report_is_empty_when_free():
    assert collision_report(ROBOT, Scene(), HOME) == []


def test_collision_report_names_the_sphere_and_the_obstacle():
    centre = sphere_centers(ROBOT, HOME)[13]
    scene = Scene(np.array([[9.0, 9.0, 9.0], centre]), np.array([0.1, 0.05]))
    lines = collision_report(ROBOT, scene, HOME)
    assert f"sphere 13 (link_5) overlaps obstacle 1 (sphere) by {RADIUS[13] + 0.05:.3f} m" in lines
    assert not any("obstacle 0" in line for line in lines)


def test_collision_report_names_self_contacts_and_workspace_faces():
    folded = np.array([0.0, 0.0, np.radians(225.0), 0.0, 0.0, 0.0])  # forearm folded onto the upper arm
    assert any(line.startswith("self-collision: sphere ") for line in collision_report(ROBOT, Scene(), folded))
    low_ceiling = Workspace(np.array([-3.0, -3.0, -1.0]), np.array([3.0, 3.0, 0.5]))
    lines = collision_report(ROBOT, Scene(workspace=low_ceiling), HOME)
    assert lines and all("leaves the workspace at z max" in line for line in lines)


@pytest.mark.parametrize("name", ["industrial6", "panda"])
def test_batched_sphere_centres_match_pinocchio_per_configuration(name):
    robot = ocpkit.load_robot(name)
    qs = RNG.uniform(robot.q_lower, robot.q_upper, (50, robot.n))
    np.testing.assert_allclose(ocpkit.geometry.clearances.sphere_centers_batch(robot, qs), sphere_centers(robot, qs),
                               atol=1e-12)


def test_batched_sphere_centres_of_prismatic_joints_match_pinocchio():
    model = pin.Model()
    tilted = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.1, 0.2, 0.3]))
    a = model.addJoint(0, pin.JointModelPY(), tilted, "slide")
    b = model.addJoint(a, pin.JointModelPrismaticUnaligned(np.array([0.6, 0.0, 0.8])), tilted, "slide2")
    c = model.addJoint(b, pin.JointModelRevoluteUnaligned(np.array([0.0, 0.6, 0.8])), tilted, "turn")
    robot = dataclasses.replace(ROBOT, model=model, sphere_joint=np.array([a, b, c, c]),
                                 sphere_offset=RNG.normal(size=(4, 3)))
    qs = RNG.uniform(-1, 1, (20, 3))
    np.testing.assert_allclose(ocpkit.geometry.clearances.sphere_centers_batch(robot, qs), sphere_centers(robot, qs),
                               atol=1e-12)
