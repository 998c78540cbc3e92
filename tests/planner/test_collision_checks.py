"""The path search's yes/no collision tests, compiled (ocpkit.planner.sphere_check) and coal's
(ocpkit.geometry.coal_check), against the NumPy clearances they stand in for."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from helpers import REPO, unaligned_chain

import ocpkit
from ocpkit.bench.random import random_problems
from ocpkit.geometry.clearances import clearances, sphere_centers_batch
from ocpkit.geometry.coal_check import CoalCheck
from ocpkit.geometry.scene import Boxes, Scene
from ocpkit.planner import sphere_check
from ocpkit.planner.sphere_check import SphereCheck, collision_check
from ocpkit.solvers import chain

MARGIN = 0.01
CHECKS = {"compiled": SphereCheck, "coal": CoalCheck}
PROBLEMS = {"mbm box (boxes, a cylinder)": REPO / "scenarios/mbm/panda/box/0001.yaml",
            "shapes (spheres, boxes, cylinders)": REPO / "scenarios/shapes/boxes.yaml"}


def smallest_clearance(problem: ocpkit.Problem, q: np.ndarray) -> np.ndarray:
    c = clearances(problem.robot, problem.scene, sphere_centers_batch(problem.robot, q))
    flat = [values.reshape(len(q), -1) for values in (c.self_pairs, c.obstacles, c.workspace)]
    return np.concatenate(flat, axis=1).min(axis=1, initial=np.inf)


def problems() -> list[tuple[str, ocpkit.Problem]]:
    loaded = [(name, ocpkit.load_scenario(path)) for name, path in PROBLEMS.items()]
    return loaded + [("random industrial6 (spheres, a workspace)", list(random_problems(500, 1))[0])]


@pytest.mark.parametrize("check", CHECKS.values(), ids=CHECKS.keys())
@pytest.mark.parametrize("margin", [MARGIN, 0.0, -0.02])  # coal's grown spheres: margin > 0, = 0, < 0
@pytest.mark.parametrize("name,problem", problems(), ids=lambda v: v if isinstance(v, str) else "")
def test_the_tests_answer_what_the_clearances_answer(name, problem, margin, check):
    robot = problem.robot
    q = np.random.default_rng(3).uniform(robot.q_lower, robot.q_upper, (1500, robot.n))
    smallest = smallest_clearance(problem, q)
    decided = np.abs(smallest - margin) > 1e-9  # coal's distances round differently within a nanometre
    assert 0.1 < (smallest >= margin).mean() < 0.95  # both answers occur
    assert (np.abs(smallest - margin) < 0.01).sum() >= 10  # and near misses, within 1 cm of the margin
    got = check(robot, problem.scene, margin).free(q)
    np.testing.assert_array_equal(got[decided], (smallest >= margin)[decided])


@pytest.mark.parametrize("check", CHECKS.values(), ids=CHECKS.keys())
def test_the_first_collision_along_a_batch_is_found_and_the_rest_skipped(check):
    problem = list(random_problems(500, 1))[0]
    robot, check = problem.robot, check(problem.robot, problem.scene, MARGIN)
    q = np.random.default_rng(4).uniform(robot.q_lower, robot.q_upper, (200, robot.n))
    free = smallest_clearance(problem, q) >= MARGIN
    assert check.first_collision(q) == int(np.argmin(free))
    assert check.first_collision(q[free]) is None


@pytest.mark.parametrize("check", CHECKS.values(), ids=CHECKS.keys())
def test_the_workspace_faces_bound_from_outside(check):
    problem = list(random_problems(500, 1))[0]
    assert problem.scene.workspace is not None
    check = check(problem.robot, problem.scene, MARGIN)
    assert check.free(problem.start[None])[0]  # a valid start is inside the workspace


def test_the_compiled_test_follows_prismatic_and_unaligned_joints():
    rng = np.random.default_rng(6)
    model, (a, b, c, d) = unaligned_chain()
    base = ocpkit.load_robot("industrial6")
    joints = np.array([0, a, a, b, c, d, b])  # not in joint order: the test sorts them into links
    robot = dataclasses.replace(base, model=model, sphere_joint=joints, sphere_offset=rng.normal(0, 0.3, (7, 3)),
                                sphere_radius=rng.uniform(0.05, 0.2, 7),
                                self_collision=np.array([[1, 4], [5, 2], [6, 1]]))
    boxes = Boxes(np.array([[0.4, 0.5, 0.6]]), np.array([[0.3, 0.8, 0.2]]), pin.rpy.rpyToMatrix(0.4, 0.1, -0.7)[None])
    problem = dataclasses.replace(problems()[0][1], robot=robot,
                                  scene=Scene(np.array([[-0.5, 0.2, 0.9]]), np.array([0.3]), boxes=boxes))
    q = rng.uniform(-1, 1, (3000, 4))
    smallest = smallest_clearance(problem, q)
    assert 0.1 < (smallest >= MARGIN).mean() < 0.9
    np.testing.assert_array_equal(SphereCheck(robot, problem.scene, MARGIN).free(q), smallest >= MARGIN)


def test_without_a_compiler_the_search_asks_coal(monkeypatch):
    problem = problems()[0][1]
    monkeypatch.setattr(sphere_check, "_kernel", lambda: None)
    assert isinstance(collision_check(problem.robot, problem.scene, MARGIN), CoalCheck)
    with pytest.raises(RuntimeError, match="did not compile"):
        SphereCheck(problem.robot, problem.scene, MARGIN)


def test_a_damaged_library_falls_back_to_coal_with_a_warning(monkeypatch, tmp_path):
    damaged = tmp_path / "damaged.so"
    damaged.write_bytes(b"not a library")
    monkeypatch.setattr(chain, "shared_library", lambda source, flags: damaged)
    sphere_check._kernel.cache_clear()
    try:
        with pytest.warns(UserWarning, match="cannot load"):
            assert sphere_check._kernel() is None
    finally:
        sphere_check._kernel.cache_clear()
