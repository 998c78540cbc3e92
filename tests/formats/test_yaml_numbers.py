"""Numbers as users write them (YAML 1.2's core schema): `1.0e6`, `2e-1`, `.inf` are numbers in every file."""

from __future__ import annotations

import math
import shutil

import pytest
import yaml
from helpers import REPO

from ocpkit.bench.suite import load_suite
from ocpkit.errors import ScenarioError
from ocpkit.formats.scenario import load_scenario
from ocpkit.formats.schema import read_yaml
from ocpkit.robots import load_robot


@pytest.mark.parametrize(("text", "value"), [
    ("1.0e6", 1.0e6), ("1e-3", 1e-3), ("2e-1", 0.2), ("1E+2", 100.0), (".5", 0.5), ("-3.", -3.0),
    (".inf", math.inf), ("-.Inf", -math.inf), ("+.INF", math.inf), ("7", 7), ("0.3", 0.3),
])
def test_yaml_1_2_floats_are_numbers(text, value):
    assert read_yaml(f"x: {text}".encode(), ScenarioError)["x"] == value


@pytest.mark.parametrize("text", ["1e", "e3", "1.0e6x", "'1e3'", "1_0e3", "inf", "nan"])
def test_what_is_no_number_stays_a_string(text):
    assert isinstance(read_yaml(f"x: {text}".encode(), ScenarioError)["x"], str)


def test_nan_is_still_a_number_the_schema_can_refuse():
    assert math.isnan(read_yaml(b"x: .nan", ScenarioError)["x"])


def test_scenario_mu_in_exponent_form(tmp_path):
    text = (REPO / "scenarios/paper/case1.yaml").read_text()
    data = yaml.safe_load(text)
    data["cost"] = {"mu": "MU"}
    (tmp_path / "case.yaml").write_text(yaml.safe_dump(data).replace("MU", "1.0e6"))
    assert load_scenario(tmp_path / "case.yaml").mu == 1.0e6


def test_robot_spec_radius_in_exponent_form(tmp_path):
    folder = REPO / "ocpkit/robots/data/industrial6"
    shutil.copy(folder / "robot.urdf", tmp_path / "robot.urdf")
    spec = (folder / "spec.yaml").read_text()
    old = "radius: 0.20}        # 1  J1 turret"
    assert old in spec
    (tmp_path / "spec.yaml").write_text(spec.replace(old, "radius: 2e-1}        # 1  J1 turret"))
    robot = load_robot({"urdf": str(tmp_path / "robot.urdf"), "spec": str(tmp_path / "spec.yaml")})
    assert robot.sphere_radius[1] == pytest.approx(0.2)


def test_suite_wall_time_in_every_written_form(tmp_path):
    shutil.copy(REPO / "scenarios/paper/case1.yaml", tmp_path / "a.yaml")
    (tmp_path / "s.yaml").write_text("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, "
                                     "max_wall_time: .inf}, {planner: simultaneous, max_wall_time: 3e1}]")
    unbounded, thirty = load_suite(tmp_path / "s.yaml").methods
    assert unbounded.options == {"max_wall_time": math.inf} and thirty.options == {"max_wall_time": 30.0}
