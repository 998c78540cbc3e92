"""MoveIt import: poses composed as pinocchio composes them, joints in the robot's order, everything unused
reported, malformed fields named; the CLI validates against a built-in robot; a real MBM problem converts."""

from __future__ import annotations

import copy

import numpy as np
import pinocchio as pin
import pytest
import yaml
from helpers import REPO

from ocpkit.cli.main import main
from ocpkit.errors import MoveItError, RobotError
from ocpkit.formats.moveit import convert_moveit, read_moveit, resolve_robot, scenario_text
from ocpkit.formats.scenario import load_scenario, problem_from_dict
from ocpkit.formats.schema import SCENARIO, check

DATA = REPO / "tests/data/moveit"
SCENE, REQUEST = DATA / "industrial6_scene.yaml", DATA / "industrial6_request.yaml"
JOINTS = [f"joint_{i}" for i in range(1, 7)]
PANDA = [f"panda_joint{i}" for i in range(1, 8)]


@pytest.fixture
def files() -> tuple[dict, dict]:
    return yaml.safe_load(SCENE.read_text()), yaml.safe_load(REQUEST.read_text())


def se3(position, quaternion) -> pin.SE3:
    x, y, z, w = quaternion
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.asarray(position, float))


def test_primitive_poses_are_composed_with_the_object_pose_as_pinocchio_does():
    scenario = read_moveit(SCENE, REQUEST, JOINTS, "industrial6").scenario
    obstacles = scenario["scene"]["obstacles"]
    assert [next(iter(o)) for o in obstacles] == ["box", "cylinder", "sphere", "cylinder"]
    quarter_z, quarter_x = [0, 0, np.sqrt(0.5), np.sqrt(0.5)], [np.sqrt(0.5), 0, 0, np.sqrt(0.5)]
    shelf = se3([1.5, 0, 0], quarter_z)
    for obstacle, local in zip(obstacles[:3], (se3([0.2, 0, 0.5], [0, 0, 0, 1]), se3([0, 0.1, 0.2], quarter_x),
                                               se3([0, 0, 1.0], [0, 0, 0, 1]))):
        world = shelf * local
        body = next(iter(obstacle.values()))
        np.testing.assert_allclose(body["center"], world.translation, atol=1e-12)
        if "orientation" in body:
            np.testing.assert_allclose(se3([0, 0, 0], body["orientation"]).rotation, world.rotation, atol=1e-12)
    box, cylinder, sphere, post = (next(iter(o.values())) for o in obstacles)
    assert box["size"] == [0.4, 0.2, 0.1] and box["name"] == "shelf/0"
    assert (cylinder["radius"], cylinder["length"]) == (0.05, 0.3)  # MoveIt: [height, radius]
    assert sphere == {"center": pytest.approx([1.5, 0, 1.0]), "radius": 0.1, "name": "shelf/2"}
    assert post == {"center": [-0.8, 0.0, 0.5], "radius": 0.04, "length": 1.0, "name": "post"}  # no orientation


def test_joints_come_in_the_robots_order_and_the_rest_is_reported():
    conversion = read_moveit(SCENE, REQUEST, JOINTS, "industrial6")
    s = conversion.scenario
    np.testing.assert_allclose(s["start"], np.radians([-70, 40, 0, 0, -115, 0]))
    np.testing.assert_allclose(s["goal"], np.radians([70, 45, -5, 0, -115, 30]))
    assert s["unit"] == "rad" and "workspace" not in s["scene"] and s["name"] == "industrial6_request"
    ignored = "\n".join(conversion.ignored)
    for expected in ("shelf/3: a cone", "shelf: 1 meshes", "post: header.frame_id 'base_link'",
                     "joints not planned: gripper_joint=0.02", "1 other goal(s)", "position_constraints",
                     "joint_constraints[2]: tolerances", "world: octomap", "robot_model_name",
                     "request: group_name, planner_id not used", "post: subframe_names, subframe_poses not used"):
        assert expected in ignored


def test_the_conversion_loads_as_a_valid_industrial6_problem():
    conversion = read_moveit(SCENE, REQUEST, JOINTS, "industrial6")
    problem = problem_from_dict(yaml.safe_load(scenario_text(conversion, ["a comment"])), base_dir=REPO)
    assert (len(problem.scene.obstacle_radii), len(problem.scene.boxes), len(problem.scene.cylinders)) == (1, 1, 2)
    assert problem.scene.obstacle_labels()[0] == "obstacle 2 (sphere 'shelf/2')"


@pytest.mark.parametrize("edit, message", [
    (lambda s, r: r["goal_constraints"][0]["joint_constraints"].pop(1),
     r"goal_constraints gives no position for joint joint_1"),
    (lambda s, r: r["start_state"]["joint_state"]["position"].pop(),
     r"start_state.joint_state: 6 names but 5 positions"),
    (lambda s, r: r.pop("goal_constraints"), r"no goal_constraints with joint_constraints"),
    (lambda s, r: s["world"]["collision_objects"][0]["primitives"][1].update(dimensions=[0.3]),
     r"collision_objects\[0\].primitives\[1\].dimensions \(cylinder\) must be 2 finite numbers \[h, r\]"),
    (lambda s, r: s["world"]["collision_objects"][0]["primitives"][0].update(dimensions=[0.4, -0.2, 0.1]),
     r"collision_objects\[0\].primitives\[0\].dimensions \(box\) must be > 0"),
    (lambda s, r: s["world"]["collision_objects"][0]["pose"]["orientation"].update(w=3.0),
     r"collision_objects\[0\].pose.orientation must be a unit quaternion"),
    (lambda s, r: s["world"]["collision_objects"][0]["primitives"][0].update(type="torus"),
     r"collision_objects\[0\].primitives\[0\].type must be box, sphere, cylinder or cone"),
    (lambda s, r: s["world"]["collision_objects"][0]["primitive_poses"].pop(),
     r"collision_objects\[0\]: 4 primitives but 3 primitive_poses"),
])
def test_a_malformed_field_is_named(files, edit, message):
    scene, request = copy.deepcopy(files)
    edit(scene, request)
    with pytest.raises(MoveItError, match=message):
        convert_moveit(scene, request, JOINTS, "industrial6")


def test_a_real_mbm_problem_converts_with_an_explicit_joint_list():
    scene, request = DATA / "mbm_table_pick_panda_scene0001.yaml", DATA / "mbm_table_pick_panda_request0001.yaml"
    conversion = read_moveit(scene, request, PANDA, "panda", "table_pick_0001")
    s = conversion.scenario
    check(s, SCENARIO, MoveItError)
    assert s["start"] == [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
    assert s["goal"][0] == pytest.approx(-1.451140183264752) and len(s["goal"]) == 7
    names = [next(iter(o.values()))["name"] for o in s["scene"]["obstacles"]]
    assert len(names) == 12 and names[0] == "Can1" and names[-1] == "table_top"
    assert any("panda_finger_joint1=0.065" in line for line in conversion.ignored)
    shipped = yaml.safe_load((REPO / "scenarios/mbm/panda/table_pick/0001.yaml").read_text())
    assert shipped == s  # the shipped subset is this converter's output


def test_a_robot_not_built_in_needs_its_joints(tmp_path):
    with pytest.raises(RobotError, match="unknown robot 'no-such-arm'.*give the joint names"):
        resolve_robot("no-such-arm", tmp_path)
    assert resolve_robot("no-such-arm", tmp_path, ["a", "b"]) == ("no-such-arm", ["a", "b"], None)
    field, joints, robot = resolve_robot("industrial6", tmp_path)
    assert field == "industrial6" and joints == JOINTS and robot.name == "industrial6"


def test_cli_writes_a_validated_scenario_for_a_spec_path(tmp_path, capsys):
    out = tmp_path / "sub" / "converted.yaml"
    spec = REPO / "ocpkit/robots/data/industrial6/spec.yaml"
    assert main(["convert", "moveit", str(SCENE), str(REQUEST), "--robot", str(spec), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "ignored: shelf/3: a cone" in printed and "6 joints, 4 obstacles (validated)" in printed
    problem = load_scenario(out)  # the robot's relative paths resolve from the scenario's folder
    assert problem.robot.name == "industrial6" and problem.name == "converted"
    assert yaml.safe_load(out.read_text())["robot"]["urdf"].endswith("industrial6/robot.urdf")


def test_cli_refuses_a_problem_ocpkit_rejects_and_writes_nothing(tmp_path, files, capsys):
    scene, request = files
    scene["world"]["collision_objects"][0]["pose"]["position"] = {"x": 0.42, "y": 1.1, "z": 0.1}  # at the goal
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(scene))
    (tmp_path / "r.yaml").write_text(yaml.safe_dump(request))
    out = tmp_path / "out.yaml"
    code = main(["convert", "moveit", str(tmp_path / "s.yaml"), str(tmp_path / "r.yaml"), "--robot", "industrial6",
                 "-o", str(out)])
    error = capsys.readouterr().err
    assert code == 2 and error.count("\n") == 1 and not out.exists()
    assert "not valid for ocpkit" in error and "goal configuration is in collision" in error and "shelf" in error


def test_cli_writes_an_unvalidated_scenario_for_a_robot_not_built_in(tmp_path, capsys):
    out = tmp_path / "p.yaml"
    scene, request = DATA / "mbm_table_pick_panda_scene0001.yaml", DATA / "mbm_table_pick_panda_request0001.yaml"
    args = ["convert", "moveit", str(scene), str(request), "--robot", "panda", "-o", str(out)]
    if "panda" in __import__("ocpkit.robots", fromlist=["builtin_robots"]).builtin_robots():
        pytest.skip("panda is built in: the validated path is tested above")
    assert main(args) == 2 and "give the joint names" in capsys.readouterr().err
    assert main([*args, "--joints", ",".join(PANDA)]) == 0
    assert "not validated: robot 'panda' is not built in here" in capsys.readouterr().out
    assert yaml.safe_load(out.read_text())["robot"] == "panda"
    assert main([*args, "--joints", "a,,b"]) == 2
