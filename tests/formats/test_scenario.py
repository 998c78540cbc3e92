"""Scenario loading and validation: every user mistake gets a specific ScenarioError/RobotError."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from helpers import REPO, load

import ocpkit
from ocpkit import load_scenario
from ocpkit.errors import RobotError, ScenarioError
from ocpkit.formats.scenario import problem_from_dict

CASE1 = REPO / "scenarios/paper/case1.yaml"


@pytest.fixture
def case1() -> dict:
    return yaml.safe_load(CASE1.read_text())


def test_paper_cases_load_in_radians(case1):
    problem = load_scenario(CASE1)
    np.testing.assert_allclose(problem.start, np.radians(case1["start"]))
    assert problem.name == "case1" and problem.mu == 0.3 and problem.scene.n_obstacles == 1
    assert problem.time.guess == 10.0


def test_unit_rad_is_taken_as_is(case1):
    case1["unit"] = "rad"
    case1["start"], case1["goal"] = np.radians(case1["start"]).tolist(), np.radians(case1["goal"]).tolist()
    np.testing.assert_allclose(load(case1).start, load_scenario(CASE1).start)


def test_malformed_yaml_is_one_line_with_line_and_column(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("robot: industrial6\nstart: [0, 0\n")
    with pytest.raises(ScenarioError, match="malformed YAML at line 3, column 1: .*expected ',' or ']'") as error:
        load_scenario(bad)
    assert "\n" not in str(error.value)
    assert "(while parsing a flow sequence at line 2, column 8)" in str(error.value)


def test_a_file_that_is_not_utf8_is_named(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_bytes(b"robot: \xff\n")
    with pytest.raises(ScenarioError, match=r"bad.yaml: not UTF-8 text: byte 0xff at offset 7"):
        load_scenario(bad)


def test_missing_file(tmp_path):
    with pytest.raises(ScenarioError, match="cannot read scenario"):
        load_scenario(tmp_path / "nope.yaml")


def test_unknown_robot(case1):
    case1["robot"] = "robby"
    with pytest.raises(RobotError, match="unknown robot 'robby'.*industrial6"):
        load(case1)


@pytest.mark.parametrize("key", ["unit", "start", "goal", "robot"])
def test_missing_key(case1, key):
    del case1[key]
    with pytest.raises(ScenarioError, match=f"missing '{key}'"):
        load(case1)


def test_unknown_key_is_named(case1):
    case1["obstacles"] = []
    with pytest.raises(ScenarioError, match="unknown keys \\['obstacles'\\]"):
        load(case1)


@pytest.mark.parametrize("where, value, message", [
    (("scene",), {"obstacle": []}, r"unknown keys \['scene.obstacle'\]; allowed: \['obstacles', 'workspace'\]"),
    (("time",), {"maxx": 3}, r"unknown keys \['time.maxx'\]; allowed: \['guess', 'max', 'min'\]"),
    (("scene", "obstacles", 0, "sphere"), {"center": [1, 0, 0], "radious": 0.2},
     r"unknown keys \['scene.obstacles\[0\].sphere.radious'\]; allowed: \['center', 'name', 'radius'\]"),
])
def test_an_unknown_nested_key_is_named_with_its_path(case1, where, value, message):
    parent = case1
    for key in where[:-1]:
        parent = parent[key]
    parent[where[-1]] = value
    with pytest.raises(ScenarioError, match=message):
        load(case1)


@pytest.mark.parametrize("time, guess", [({"max": 3}, 3.0), ({"max": 20}, 10.0), ({"min": 12, "max": 20}, 12.0),
                                         ({}, 10.0)])
def test_the_default_guess_is_10_s_clipped_into_the_time_bounds(case1, time, guess):
    case1["time"] = time
    assert load(case1).time.guess == guess


def test_a_huge_value_is_echoed_cut_short(case1):
    case1["start"] = list(range(100_000))
    with pytest.raises(ScenarioError, match=r"'start' needs shape \(6,\), got \(100000,\): \[0, 1, 2") as error:
        load(case1)
    assert len(str(error.value)) < 200


def test_wrong_vector_length(case1):
    case1["goal"] = [0, 0, 0]
    with pytest.raises(ScenarioError, match="'goal' needs shape \\(6,\\)"):
        load(case1)


def test_bad_unit(case1):
    case1["unit"] = "grad"
    with pytest.raises(ScenarioError, match="unit must be 'deg' or 'rad'"):
        load(case1)


def test_start_outside_limits_names_the_joint(case1):
    case1["start"][4] = -130
    with pytest.raises(ScenarioError, match=r"start: joint 5 \(joint_5\) = -130.00 deg is outside \[-120.00, 100.00\]"):
        load(case1)


def test_start_exactly_at_a_limit_is_accepted(case1):
    case1["start"][4] = -120
    assert load(case1).start[4] == pytest.approx(np.radians(-120))


def test_goal_in_obstacle_names_the_sphere(case1):
    case1["scene"]["obstacles"][0]["sphere"]["center"] = [0.4, 1.09, 0.6]  # at the place position
    message = r"goal configuration is in collision: sphere \d+ \(link_\d\) overlaps obstacle 0"
    with pytest.raises(ScenarioError, match=message):
        load(case1)


def test_self_collision_names_the_pair(case1):
    case1["start"] = [0, 0, 200, 0, 0, 0]  # forearm folded back onto the upper arm
    with pytest.raises(ScenarioError, match=r"self-collision: sphere \d+ \(link_\d\) and sphere \d+ \(link_\d\)"):
        load(case1)


def test_start_outside_workspace_names_the_face(case1):
    case1["scene"]["workspace"]["max"][2] = 1.0
    with pytest.raises(ScenarioError, match="leaves the workspace at z max"):
        load(case1)


def test_impossible_time_bounds(case1):
    case1["time"] = {"min": 0.1, "max": 0.3, "guess": 0.3}
    with pytest.raises(ScenarioError, match="below the velocity-limited minimum"):
        load(case1)


@pytest.mark.parametrize("time, message", [({"min": 2, "max": 1}, "0 < min ≤ max"),
                                           ({"min": 1, "max": 5, "guess": 9}, "time.guess")])
def test_inconsistent_time_bounds(case1, time, message):
    case1["time"] = time
    with pytest.raises(ScenarioError, match=message):
        load(case1)


def test_obstacle_needs_positive_radius(case1):
    case1["scene"]["obstacles"][0]["sphere"]["radius"] = -0.1
    with pytest.raises(ScenarioError, match="radius must be > 0"):
        load(case1)


def test_workspace_min_below_max(case1):
    case1["scene"]["workspace"]["min"][0] = 5.0
    with pytest.raises(ScenarioError, match="min .* must be below max"):
        load(case1)


def test_scenario_must_be_a_mapping():
    with pytest.raises(ScenarioError, match="must be a mapping"):
        problem_from_dict([1, 2, 3])


def test_an_edited_robot_spec_is_read_again_by_the_next_scenario_load(case1, tmp_path):
    robot_dir = REPO / "ocpkit/robots/data/industrial6"
    (tmp_path / "robot.urdf").write_text((robot_dir / "robot.urdf").read_text())
    spec = yaml.safe_load((robot_dir / "spec.yaml").read_text())
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    case1["robot"] = {"urdf": "robot.urdf", "spec": "spec.yaml"}
    (tmp_path / "case.yaml").write_text(yaml.safe_dump(case1))
    before = load_scenario(tmp_path / "case.yaml")

    spec["limits"]["velocity"][0] /= 2
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    after = load_scenario(tmp_path / "case.yaml")

    assert after.robot.qd_max[0] == pytest.approx(before.robot.qd_max[0] / 2)
    assert after.robot.key != before.robot.key
    discretization = ocpkit.build(after, knots=6).discretization  # a new build: the robot's content changed
    upper = discretization.bounds(after)[1][discretization.nlp.variables.index("qd")[1:-1, 0]]  # inner knots
    np.testing.assert_allclose(upper, after.robot.qd_max[0])
