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
from ocpkit.formats.record import trajectory_header
from ocpkit.formats.trajectory import Samples, Trajectory, write_json
from ocpkit.geometry.scene import Scene
from ocpkit.result import finish

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


def test_outside_box_and_cylinder_distances_match_coal():
    """The outside checker's own distances (numpy + pinocchio) against coal, tilted, inside and outside."""
    import coal
    from outside_check import obstacle_distance, rotation

    rng = np.random.default_rng(8)
    quaternion = rng.normal(size=4)
    quaternion /= np.linalg.norm(quaternion)
    center, R = np.array([0.3, -0.2, 0.5]), rotation(quaternion)
    shapes = {"box": ({"size": [0.4, 0.2, 0.6]}, coal.Box(0.4, 0.2, 0.6)),
              "cylinder": ({"radius": 0.15, "length": 0.5}, coal.Cylinder(0.15, 0.5))}
    points = center + rng.uniform(-0.5, 0.5, (200, 3))
    for kind, (fields, shape) in shapes.items():
        ours = obstacle_distance({kind: {"center": center.tolist(), "orientation": quaternion.tolist(), **fields}},
                                 points)
        request = coal.DistanceRequest()
        request.gjk_tolerance = 1e-10
        theirs = np.array([coal.distance(shape, coal.Transform3s(R, center), coal.Capsule(1e-3, 1e-9),
                                         coal.Transform3s(np.eye(3), p), request, coal.DistanceResult()) + 1e-3
                           for p in points])
        assert (theirs < 0).sum() > 10 and (theirs > 0).sum() > 10
        np.testing.assert_allclose(ours, theirs, atol=1e-4)


def test_the_json_records_every_check_with_its_tolerance(tmp_path):
    motion = polynomial_motion(FREE, 3.0, MINIMUM_JERK)
    plan = finish(FREE, motion, None, {}, 0.0)
    header = trajectory_header(FREE, plan)
    write_json(tmp_path / "t.json", motion, header)
    checks = {c["name"]: c for c in __import__("json").loads((tmp_path / "t.json").read_text())["checks"]}
    assert set(checks) == {c.name for c in plan.verification.checks}
    assert checks["position"]["tolerance"] == 1e-4 and checks["position"]["unit"] == "rad"
    assert checks["velocity"]["tolerance"] == 0.01 and checks["obstacle"]["tolerance"] == 0.0
    assert checks["position"]["where"] in FREE.robot.joint_names
