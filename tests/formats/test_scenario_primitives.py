"""Boxes and cylinders in scenario files: loaded with their orientation, every malformed field named with its
path, start and goal in contact name the obstacle."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from helpers import REPO, load

from ocpkit.errors import ScenarioError
from ocpkit.formats.scenario import load_scenario

BOXES = REPO / "scenarios/shapes/boxes.yaml"


@pytest.fixture
def boxes() -> dict:
    return yaml.safe_load(BOXES.read_text())


def test_boxes_and_cylinders_load_with_sizes_and_rotations():
    scene = load_scenario(BOXES).scene
    assert (len(scene.obstacle_radii), len(scene.boxes), len(scene.cylinders)) == (0, 2, 2)
    np.testing.assert_allclose(scene.boxes.sizes[0], [0.6, 1.6, 0.4])
    np.testing.assert_allclose(scene.boxes.rotations[0], np.eye(3))
    np.testing.assert_allclose(scene.cylinders.rotations[1] @ [0, 0, 1], [0, -1, 0], atol=1e-6)  # 90° about x
    assert scene.obstacle_labels() == ["obstacle 0 (box 'table')", "obstacle 2 (box 'hanging box')",
                                       "obstacle 1 (cylinder 'post')", "obstacle 3 (cylinder 'bar')"]


@pytest.mark.parametrize("index, kind, field, value, message", [
    (2, "box", "orientation", [0, 0, 0.5, 0.5],
     r"scene.obstacles\[2\].box.orientation must be a unit quaternion \[x, y, z, w\] .* got norm 0.707107"),
    (2, "box", "orientation", [0, 0, 1], r"scene.obstacles\[2\].box.orientation needs 4 values, got 3"),
    (0, "box", "size", [0.6, -1.6, 0.4], r"scene.obstacles\[0\].box.size\[1\] must be > 0, got -1.6"),
    (1, "cylinder", "length", 0, r"scene.obstacles\[1\].cylinder.length must be > 0, got 0"),
    (1, "cylinder", "radius", "wide", r"scene.obstacles\[1\].cylinder.radius must be a number, got 'wide'"),
    (3, "cylinder", "orientation", [0, 0, 0, float("nan")],
     r"scene.obstacles\[3\].cylinder.orientation\[3\] must be finite"),
])
def test_a_malformed_primitive_is_named_with_its_path(boxes, index, kind, field, value, message):
    boxes["scene"]["obstacles"][index][kind][field] = value
    with pytest.raises(ScenarioError, match=message):
        load(boxes)


def test_a_missing_field_and_an_unknown_kind_are_named(boxes):
    del boxes["scene"]["obstacles"][1]["cylinder"]["length"]
    with pytest.raises(ScenarioError, match=r"missing 'scene.obstacles\[1\].cylinder.length'"):
        load(boxes)
    boxes["scene"]["obstacles"][1] = {"cone": {"center": [0, 0, 0]}}
    with pytest.raises(ScenarioError, match=r"scene.obstacles\[1\] must be .*\{box: ...\} or \{cylinder: ...\}"):
        load(boxes)


def test_a_slightly_unnormalised_quaternion_is_accepted_and_normalised(boxes):
    boxes["scene"]["obstacles"][2]["box"]["orientation"] = [0.0, 0.2589, 0.0, 0.9660]  # MoveIt's printed digits
    rotation = load(boxes).scene.boxes.rotations[1]
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-12)


@pytest.mark.parametrize("kind, body, name", [
    ("box", {"center": [0.42, 1.15, 0.6], "size": [0.1, 0.1, 0.1], "name": "crate"}, "obstacle 4 \\(box 'crate'\\)"),
    ("cylinder", {"center": [0.42, 1.15, 0.6], "radius": 0.02, "length": 0.1}, r"obstacle 4 \(cylinder\)"),
])
def test_goal_inside_a_primitive_names_it(boxes, kind, body, name):
    boxes["scene"]["obstacles"].append({kind: body})  # at the place position
    with pytest.raises(ScenarioError, match=rf"goal configuration is in collision: sphere \d+ \(link_\d\) overlaps "
                                            rf"{name} by"):
        load(boxes)


def test_a_problem_from_python_with_a_reflection_or_a_bad_size_is_rejected():
    import dataclasses

    from ocpkit.validation import validate
    problem = load_scenario(BOXES)
    mirrored = dataclasses.replace(problem.scene.boxes, rotations=problem.scene.boxes.rotations * [1, 1, -1])
    with pytest.raises(ScenarioError, match=r"scene.boxes.rotations\[0\] is not a rotation matrix"):
        validate(dataclasses.replace(problem, scene=dataclasses.replace(problem.scene, boxes=mirrored)))
    flat = dataclasses.replace(problem.scene.cylinders, lengths=np.array([0.6, 0.0]))
    with pytest.raises(ScenarioError, match=r"scene.cylinders.lengths must be > 0"):
        validate(dataclasses.replace(problem, scene=dataclasses.replace(problem.scene, cylinders=flat)))


def test_a_start_among_many_contacts_names_three_and_counts_the_rest(boxes):
    boxes["scene"]["obstacles"].append({"box": {"center": [0.0, 0.0, 0.9], "size": [3.0, 3.0, 2.0]}})
    with pytest.raises(ScenarioError, match=r"start configuration is in collision: .*; and \d+ more$") as error:
        load(boxes)
    assert str(error.value).count("overlaps") == 3


def test_names_that_do_not_match_the_obstacles_are_rejected_not_misused(boxes):
    import dataclasses

    from ocpkit.validation import validate
    problem = load(boxes)
    fewer = dataclasses.replace(problem.scene, names=problem.scene.names[:2])
    assert fewer.obstacle_labels()[0] == "obstacle 0 (box)"  # labels never come from a mismatched list
    with pytest.raises(ScenarioError, match=r"scene.names needs one name per obstacle \(4\), got 2"):
        validate(dataclasses.replace(problem, scene=fewer))
