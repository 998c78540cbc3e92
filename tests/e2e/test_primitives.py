"""End to end among boxes and cylinders: scenarios/shapes/boxes.yaml plans to `verified` and its JSON passes the
outside check, whose exact box and cylinder distances know nothing of ocpkit."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.formats.record import trajectory_header
from ocpkit.geometry.clearances import clearances, sphere_centers

BOXES = REPO / "scenarios/shapes/boxes.yaml"
DATA = REPO / "ocpkit/robots/data/industrial6"
pytestmark = pytest.mark.slow


def test_boxes_scenario_is_verified_and_passes_the_outside_check(tmp_path):
    problem = ocpkit.load_scenario(BOXES)
    line = problem.start + np.outer(np.linspace(0, 1, 101), problem.goal - problem.start)
    assert clearances(problem.robot, problem.scene, sphere_centers(problem.robot, line)).obstacles.min() < -0.1
    result = ocpkit.plan(problem)
    assert result.status == "verified"
    obstacle = next(c for c in result.verification.checks if c.name == "obstacle")
    assert obstacle.worst > -0.05  # the plan does pass close to a primitive: the smooth rows are active
    path = tmp_path / "boxes.json"
    ocpkit.write_json(path, result.trajectory, trajectory_header(problem, result))
    check = subprocess.run([sys.executable, str(REPO / "tests/outside_check.py"), str(path), str(DATA / "spec.yaml"),
                            str(DATA / "robot.urdf"), str(BOXES)], capture_output=True, text=True)
    assert check.returncode == 0, check.stdout + check.stderr
    assert "obstacle        +0.0000 ok" in check.stdout
