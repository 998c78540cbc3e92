"""Robot loading: built-in data, custom URDF + spec files, and clear errors for broken files."""

from __future__ import annotations

import re
import shutil

import numpy as np
import pinocchio as pin
import pytest
import yaml
from helpers import REPO, example_robot_urdf

from ocpkit import load_robot
from ocpkit.errors import RobotError
from ocpkit.geometry.clearances import sphere_centers
from ocpkit.robots import builtin_robots, rigid_torque, sphere_reach

SPEC = REPO / "ocpkit/robots/data/industrial6/spec.yaml"


def write_spec(path, **changes) -> None:
    spec = yaml.safe_load(SPEC.read_text())
    spec.update(changes)
    path.write_text(yaml.safe_dump(spec))


def test_builtin_industrial6():
    robot = load_robot("industrial6")
    assert "industrial6" in builtin_robots()
    assert robot.n == 6 and robot.model.nq == 6
    assert robot.sphere_radius.shape == (len(robot.sphere_link),)
    assert load_robot("industrial6") is robot  # cached by content: problems on one robot share its builds
    assert len(robot.key) == 64 and int(robot.key, 16) >= 0  # sha256 hex


def test_robot_identity_follows_file_content(tmp_path):
    for name in ("robot.urdf", "spec.yaml"):
        shutil.copy(SPEC.parent / name, tmp_path / name)
    files = {"urdf": "robot.urdf", "spec": "spec.yaml"}
    first = load_robot(files, tmp_path)
    assert load_robot(files, tmp_path) is first  # unchanged files: the same object and key
    spec = yaml.safe_load((tmp_path / "spec.yaml").read_text())
    spec["limits"]["velocity"][0] = 0.5
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    edited = load_robot(files, tmp_path)
    assert edited.qd_max[0] == 0.5 and first.qd_max[0] != 0.5  # the files are read again
    assert edited.key != first.key and edited is not first
    assert load_robot(files, tmp_path) is edited


def test_friction_is_viscous_plus_smooth_coulomb():
    robot = load_robot("industrial6")
    qd = np.linspace(-1, 1, 6)
    expected = robot.viscous * qd + robot.coulomb * np.tanh(qd / robot.friction_smoothing)
    np.testing.assert_allclose(robot.friction(qd), expected)
    h = 1e-7
    np.testing.assert_allclose(robot.friction_slope(qd), (robot.friction(qd + h) - robot.friction(qd - h)) / (2 * h),
                               rtol=1e-5)


def test_rigid_torque_is_rnea_at_every_row():
    robot = load_robot("industrial6")
    rng = np.random.default_rng(1)
    q, qd, qdd = rng.uniform(robot.q_lower, robot.q_upper, (5, 6)), rng.uniform(-2, 2, (5, 6)), rng.normal(size=(5, 6))
    expected = [pin.rnea(robot.model, robot.model.createData(), *row) for row in zip(q, qd, qdd)]
    np.testing.assert_allclose(rigid_torque(robot, q, qd, qdd), expected, atol=1e-12)
    assert rigid_torque(robot, q[:0], qd[:0], qdd[:0]).shape == (0, 6)


@pytest.mark.parametrize("name", ["industrial6", "panda"])
def test_sphere_reach_bounds_every_sphere_centre(name, tmp_path):
    robot = load_robot("industrial6") if name == "industrial6" else _panda(tmp_path)
    anchors, reach = sphere_reach(robot)
    assert anchors.shape == (len(reach), 3) and len(reach) == len(robot.sphere_radius)
    q = np.random.default_rng(2).uniform(robot.q_lower, robot.q_upper, (200, robot.n))
    distance = np.linalg.norm(sphere_centers(robot, q) - anchors, axis=-1)  # (K, M)
    assert np.all(distance <= reach + 1e-9)


def _panda(tmp_path):
    """Panda with its prismatic fingers (a stroke in the reach) and a sphere on a finger and on the base."""
    joints = [f"panda_joint{k}" for k in range(1, 8)] + ["panda_finger_joint1"]
    spec = {"name": "panda", "joints": joints,
            "limits": {"position": {"lower": [-2.8] * 7 + [0.0], "upper": [2.8] * 7 + [0.04]}, "velocity": [2] * 8,
                       "torque": [80] * 8, "torque_rate": [1000] * 8},
            "gear_ratios": [100] * 8, "friction": {"viscous": [0.1] * 8, "coulomb": [1] * 8, "smoothing": 0.05},
            "spheres": [{"link": "panda_leftfinger", "center": [0, 0.01, 0.03], "radius": 0.02},
                        {"link": "panda_link0", "center": [0, 0, 0.05], "radius": 0.1}]}
    (tmp_path / "panda.yaml").write_text(yaml.safe_dump(spec))
    return load_robot({"urdf": str(example_robot_urdf("panda")), "spec": str(tmp_path / "panda.yaml")})


def test_custom_files_relative_to_base_dir(tmp_path):
    (tmp_path / "robot.urdf").write_text((SPEC.parent / "robot.urdf").read_text())
    write_spec(tmp_path / "spec.yaml", name="copy")
    robot = load_robot({"urdf": "robot.urdf", "spec": "spec.yaml"}, base_dir=tmp_path)
    assert robot.name == "copy"


def test_ur5_from_example_robot_data_with_a_spec_of_its_own(tmp_path):
    spec = {"name": "ur5", "joints": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                                      "wrist_2_joint", "wrist_3_joint"],
            "limits": {"position": {"lower": [-6.28] * 6, "upper": [6.28] * 6}, "velocity": [3.14] * 6,
                       "torque": [150, 150, 150, 28, 28, 28], "torque_rate": [1500] * 6},
            "gear_ratios": [100] * 6, "friction": {"viscous": [0.1] * 6, "coulomb": [1] * 6, "smoothing": 0.05},
            "spheres": [{"link": "forearm_link", "center": [0, 0, 0.2], "radius": 0.06}], "self_collision": []}
    (tmp_path / "ur5.yaml").write_text(yaml.safe_dump(spec))
    robot = load_robot({"urdf": str(example_robot_urdf("ur5")), "spec": str(tmp_path / "ur5.yaml")})
    assert robot.n == 6 and robot.sphere_joint.tolist() == [3]


def test_missing_file_is_named(tmp_path):
    with pytest.raises(RobotError, match="robot file not found: .*nothing.urdf"):
        load_robot({"urdf": str(tmp_path / "nothing.urdf"), "spec": str(SPEC)})


@pytest.mark.parametrize("changes, message", [
    ({"joints": ["joint_1", "bogus"]}, r"joints not in the URDF: \['bogus'\]"),
    ({"joints": ["joint_2", "joint_1"]}, "must follow the URDF tree order"),
    ({"gear_ratios": [1, 2]}, "'gear_ratios' needs 6 values"),
    ({"spheres": [{"link": "nowhere", "center": [0, 0, 0], "radius": 0.1}]}, "unknown link 'nowhere'"),
    ({"joints": ["joint_1", "joint_1"]}, "each joint once"),
    ({"self_collision": [[0, 99]]}, "self_collision index outside"),
    ({"self_collision": [[3, 3]]}, r"paired with itself: self_collision\[0\] = \[3, 3\]"),
    ({"spheres": [{"link": "link_1", "center": [0, 0, 0], "radius": 0.1, "radious": 1}]},
     r"unknown keys \['spheres\[0\].radious'\]; allowed: \['center', 'link', 'radius'\]"),
    ({"friction": {"viscous": [0] * 6, "coulomb": [0] * 6, "smoothing": 0}}, "smoothing must be > 0"),
])
def test_broken_spec_is_explained(tmp_path, changes, message):
    write_spec(tmp_path / "spec.yaml", **changes)
    with pytest.raises(RobotError, match=message):
        load_robot({"urdf": str(SPEC.parent / "robot.urdf"), "spec": str(tmp_path / "spec.yaml")})


@pytest.mark.parametrize("robot, message", [
    ({"urdf": "x"}, "missing 'robot.spec'"),
    ({"urdf": 3, "spec": "s.yaml"}, "robot.urdf must be a string, got 3"),
    ({"spec": ["a"]}, "robot.spec must be a string"),
    (3, "robot must be a built-in robot name or a mapping with keys spec, urdf, got 3"),
    ("../data/industrial6", "unknown robot '../data/industrial6'"),  # a name, never a path
])
def test_robot_must_be_name_or_files(robot, message):
    with pytest.raises(RobotError, match=re.escape(message)):
        load_robot(robot)


def test_a_broken_urdf_is_one_line_with_the_parsers_reason(tmp_path, capfd):
    (tmp_path / "robot.urdf").write_text('<robot name="x"><link name="a"/><joint name="j" type="revolute">'
                                         '<parent link="a"/><child link="b"/></joint></robot>')
    with pytest.raises(RobotError) as error:
        load_robot({"urdf": "robot.urdf", "spec": str(SPEC)}, tmp_path)
    assert str(error.value).startswith(f"{tmp_path / 'robot.urdf'}: not a valid URDF: ")
    assert "does not specify limits" in str(error.value) and "\n" not in str(error.value)
    assert capfd.readouterr().err == ""  # the parser's console lines are in the message, not on the terminal
