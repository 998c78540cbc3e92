"""tests/outside_check.py on exported trajectories: a consistent motion passes, one whose q̇ is not dq/dt (or
q̈ not dq̇/dt) is rejected, as `verify` rejects it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import yaml
from helpers import REPO, monomial, polynomial_motion
from outside_check import check

import ocpkit
from ocpkit.report import trajectory_header
from ocpkit.scene import Scene
from ocpkit.trajectory import Samples, Trajectory, write_json
from ocpkit.plan import finish

DATA = REPO / "ocpkit/robots/data/industrial6"
CASE2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
FREE = dataclasses.replace(CASE2, scene=Scene(workspace=CASE2.scene.workspace))
MINIMUM_JERK = 10 * monomial(3) - 15 * monomial(4) + 6 * monomial(5)


def exported(tmp_path, trajectory: Trajectory) -> dict[str, float]:
    """The outside checker's worst values for `trajectory` written as JSON."""
    path = tmp_path / "t.json"
    write_json(path, trajectory, trajectory_header(FREE, finish(FREE, trajectory, None, {}, 0.0)))
    spec = yaml.safe_load((DATA / "spec.yaml").read_text())
    scenario = {"scene": {"workspace": {"min": FREE.scene.workspace.lower.tolist(),
                                        "max": FREE.scene.workspace.upper.tolist()}}}
    return check(__import__("json").loads(path.read_text()), spec, str(DATA / "robot.urdf"), scenario)


def scaled(trajectory: Trajectory, field: str, factor: float) -> Trajectory:
    def at(t: np.ndarray) -> Samples:
        samples = trajectory.interpolant(t)
        return dataclasses.replace(samples, **{field: factor * getattr(samples, field)})

    return Trajectory(at(trajectory.knots.t), at)


def test_a_consistent_motion_passes_the_consistency_checks(tmp_path):
    worst = exported(tmp_path, polynomial_motion(FREE, 4.0, MINIMUM_JERK))
    assert worst["qd_consistency"] < 1e-4 and worst["qdd_consistency"] < 1e-4


@pytest.mark.parametrize("field, name, tolerance", [("qd", "qd_consistency", 0.01), ("qdd", "qdd_consistency", 0.05)])
def test_samples_that_are_not_derivatives_of_each_other_are_rejected(tmp_path, field, name, tolerance):
    worst = exported(tmp_path, scaled(polynomial_motion(FREE, 4.0, MINIMUM_JERK), field, 1.1))
    assert worst[name] > tolerance
