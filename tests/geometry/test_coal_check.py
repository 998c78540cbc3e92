"""coal's yes/no test against the NumPy clearances it stands in for (ocpkit.geometry.coal_check)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.bench.random import random_problems
from ocpkit.geometry.clearances import clearances, sphere_centers_batch
from ocpkit.geometry.coal_check import CoalCheck

MARGIN = 0.01
PROBLEMS = {"mbm box (boxes, a cylinder)": REPO / "scenarios/mbm/panda/box/0001.yaml",
            "shapes (spheres, boxes, cylinders)": REPO / "scenarios/shapes/boxes.yaml"}


def smallest_clearance(problem: ocpkit.Problem, q: np.ndarray) -> np.ndarray:
    c = clearances(problem.robot, problem.scene, sphere_centers_batch(problem.robot, q))
    flat = [values.reshape(len(q), -1) for values in (c.self_pairs, c.obstacles, c.workspace)]
    return np.concatenate(flat, axis=1).min(axis=1, initial=np.inf)


def problems() -> list[tuple[str, ocpkit.Problem]]:
    loaded = [(name, ocpkit.load_scenario(path)) for name, path in PROBLEMS.items()]
    return loaded + [("random industrial6 (spheres, a workspace)", list(random_problems(500, 1))[0])]


@pytest.mark.parametrize("margin", [MARGIN, 0.0, -0.02])  # the broad phase's grown spheres: margin > 0, = 0, < 0
@pytest.mark.parametrize("name,problem", problems(), ids=lambda v: v if isinstance(v, str) else "")
def test_coal_answers_what_the_clearances_answer(name, problem, margin):
    robot = problem.robot
    q = np.random.default_rng(3).uniform(robot.q_lower, robot.q_upper, (1500, robot.n))
    smallest = smallest_clearance(problem, q)
    decided = np.abs(smallest - margin) > 1e-9  # coal's distances round differently within a nanometre
    assert 0.1 < (smallest >= margin).mean() < 0.95  # both answers occur
    assert (np.abs(smallest - margin) < 0.01).sum() >= 10  # and near misses, within 1 cm of the margin
    got = CoalCheck(robot, problem.scene, margin).free(q)
    np.testing.assert_array_equal(got[decided], (smallest >= margin)[decided])


def test_the_first_collision_along_a_batch_is_found_and_the_rest_skipped():
    problem = list(random_problems(500, 1))[0]
    robot, check = problem.robot, CoalCheck(problem.robot, problem.scene, MARGIN)
    q = np.random.default_rng(4).uniform(robot.q_lower, robot.q_upper, (200, robot.n))
    free = smallest_clearance(problem, q) >= MARGIN
    assert check.first_collision(q) == int(np.argmin(free))
    assert check.first_collision(q[free]) is None


def test_the_workspace_faces_bound_from_outside():
    problem = list(random_problems(500, 1))[0]
    assert problem.scene.workspace is not None
    check = CoalCheck(problem.robot, problem.scene, MARGIN)
    assert check.free(problem.start[None])[0]  # a valid start is inside the workspace
