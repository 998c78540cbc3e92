"""Built-in `panda` and `ur5`: dynamics against pinocchio on example-robot-data's model, the issue's limits, and
spheres where vamp's spherized MotionBenchMaker URDFs put them (tests/robots/vamp, Apache-2.0)."""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from ocpkit import load_robot
from ocpkit.dynamics import make_dynamics
from ocpkit.geometry.clearances import collision_report, sphere_centers
from ocpkit.geometry.scene import Scene
from ocpkit.robots.spheres import urdf_spheres
from ocpkit.robots.urdf import example_robot_data_dir

VAMP = Path(__file__).parent / "vamp"
RNG = np.random.default_rng(12)
READY = np.array([0, -0.785, 0, -2.356, 0, 1.571, 0.785])  # MBM's Panda start state


def example_robot_data_panda() -> pin.Model:
    """example-robot-data's Panda with the fingers held at 0.065 m each, built here without ocpkit."""
    full = pin.buildModelFromUrdf(str(example_robot_data_dir() / "robots/panda_description/urdf/panda.urdf"))
    q = pin.neutral(full)
    fingers = [full.getJointId(f"panda_finger_joint{k}") for k in (1, 2)]
    for j in fingers:
        q[full.joints[j].idx_q] = 0.065
    return pin.buildReducedModel(full, fingers, q)


@pytest.mark.parametrize("backend", ["casadi", "casadi-rnea"])
def test_panda_dynamics_match_pinocchio_on_the_example_robot_data_model(backend):
    robot, reference = load_robot("panda"), example_robot_data_panda()
    data = reference.createData()
    dynamics = make_dynamics(backend, robot)
    syms = [ca.SX.sym(name, 7) for name in ("q", "qd", "x")]
    inverse = ca.Function("inverse", syms, [dynamics.inverse(*syms)])
    forward = ca.Function("forward", syms, [dynamics.forward(*syms)])
    for _ in range(5):
        q, qd, qdd = RNG.uniform(robot.q_lower, robot.q_upper), RNG.uniform(-2, 2, 7), RNG.uniform(-5, 5, 7)
        tau = pin.rnea(reference, data, q, qd, qdd)  # friction is zero
        np.testing.assert_allclose(np.asarray(inverse(q, qd, qdd)).ravel(), tau, atol=1e-8)
        np.testing.assert_allclose(np.asarray(forward(q, qd, tau)).ravel(), qdd, atol=1e-7)
    assert np.all(robot.viscous == 0) and np.all(robot.coulomb == 0)


def test_panda_limits_are_libfrankas():
    robot = load_robot("panda")
    assert robot.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    np.testing.assert_array_equal(robot.qd_max, [2.175] * 4 + [2.61] * 3)
    np.testing.assert_array_equal(robot.tau_max, [87.0] * 4 + [12.0] * 3)
    np.testing.assert_array_equal(robot.taud_max, [1000.0] * 7)
    np.testing.assert_array_equal(robot.q_lower, [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973])
    np.testing.assert_array_equal(robot.q_upper, [2.8973, 1.7628, 2.8973, 0.0873, 2.8973, 3.7525, 2.8973])


def test_ur5_limits_are_its_urdfs_with_the_torque_rate_rule():
    robot = load_robot("ur5")
    np.testing.assert_array_equal(robot.tau_max, [150.0] * 3 + [28.0] * 3)
    np.testing.assert_array_equal(robot.taud_max, [1500.0] * 3 + [280.0] * 3)
    np.testing.assert_array_equal(robot.qd_max, [3.15] * 3 + [3.2] * 3)


@pytest.mark.parametrize("name, tolerance", [("panda", 1e-9), ("ur5", 2e-4)])  # ur5: centres rounded to 0.1 mm,
def test_spheres_sit_where_vamps_spherized_urdf_puts_them(name, tolerance):  # and vamp's base yaw 1.57 vs 1.5708
    robot = load_robot(name)
    source = VAMP / f"{name}_spherized.urdf"
    model = pin.buildModelFromUrdf(str(source))
    data = model.createData()
    spheres = urdf_spheres(source)
    np.testing.assert_array_equal(robot.sphere_radius, [s.radius for s in spheres])
    for _ in range(5):
        q = RNG.uniform(robot.q_lower, robot.q_upper)
        full = pin.neutral(model)
        for j, joint in enumerate(robot.joint_names):
            full[model.joints[model.getJointId(joint)].idx_q] = q[j]
        pin.framesForwardKinematics(model, data, full)
        expected = [data.oMf[model.getFrameId(s.link)].act(np.asarray(s.center)) for s in spheres]
        np.testing.assert_allclose(sphere_centers(robot, q), expected, atol=tolerance)


def test_mbms_start_is_free_and_gravity_is_within_the_torque_limits():
    robot = load_robot("panda")
    assert collision_report(robot, Scene(), READY) == []
    gravity = pin.computeGeneralizedGravity(robot.model, robot.model.createData(), READY)
    assert np.all(np.abs(gravity) < 0.8 * robot.tau_max)


@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_the_outside_checker_builds_the_same_model_from_the_spec(name):
    """tests/outside_check.py reads urdf, base and locked on its own: same frames and torques as ocpkit."""
    import yaml
    from outside_check import robot_model, spec_urdf

    from ocpkit.robots.robot import DATA_DIR

    spec_file = DATA_DIR / name / "spec.yaml"
    robot, model = load_robot(name), robot_model(yaml.safe_load(spec_file.read_text()), spec_urdf(
        yaml.safe_load(spec_file.read_text()), str(spec_file)))
    ours, theirs = robot.model.createData(), model.createData()
    for _ in range(3):
        q, qd = RNG.uniform(robot.q_lower, robot.q_upper), RNG.uniform(-1, 1, robot.n)
        pin.framesForwardKinematics(robot.model, ours, q)
        pin.framesForwardKinematics(model, theirs, q)
        for frame in ("panda_hand", "panda_leftfinger") if name == "panda" else ("base_link", "tool0"):
            np.testing.assert_allclose(theirs.oMf[model.getFrameId(frame)].homogeneous,
                                       ours.oMf[robot.model.getFrameId(frame)].homogeneous, atol=1e-12)
        np.testing.assert_allclose(pin.rnea(model, theirs, q, qd, qd), pin.rnea(robot.model, ours, q, qd, qd),
                                   atol=1e-10)
