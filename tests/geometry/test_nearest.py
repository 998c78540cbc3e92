"""The smallest clearances per configuration against the full NumPy clearances (ocpkit.geometry.nearest)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.bench.random import random_problems
from ocpkit.geometry.clearances import clearances, sphere_centers_batch
import ocpkit.geometry.nearest
from ocpkit.geometry.nearest import FULL_TERMS, WITHIN, smallest_clearances, sphere_groups

PROBLEMS = {"mbm box (boxes, a cylinder)": REPO / "scenarios/mbm/panda/box/0001.yaml",
            "shapes (spheres, boxes, cylinders)": REPO / "scenarios/shapes/boxes.yaml"}


def problems() -> list[tuple[str, ocpkit.Problem]]:
    loaded = [(name, ocpkit.load_scenario(path)) for name, path in PROBLEMS.items()]
    return loaded + [("random industrial6 (spheres, a workspace)", list(random_problems(500, 1))[0])]


def per_configuration(values: np.ndarray) -> np.ndarray:
    """The smallest of values (K, ...) per configuration (K,), inf where there are none."""
    return values.reshape(len(values), -1).min(axis=1, initial=np.inf)


def wandering(problem: ocpkit.Problem, count: int) -> np.ndarray:
    """`count` configurations (count, n) along the start–goal line, swung to and fro across it."""
    robot = problem.robot
    s = np.linspace(0.0, 1.0, count)[:, None]
    swing = np.sin(9 * s) * np.random.default_rng(2).normal(0.0, 0.6, robot.n)
    return np.clip(problem.start + s * (problem.goal - problem.start) + swing, robot.q_lower, robot.q_upper)


@pytest.mark.parametrize("name,problem", problems(), ids=lambda v: v if isinstance(v, str) else "")
def test_every_clearance_up_to_the_threshold_is_exact_and_the_rest_bounded_below(name, problem, monkeypatch):
    monkeypatch.setattr(ocpkit.geometry.nearest, "FULL_TERMS", 0)  # the groups' way, however small the robot
    robot = problem.robot
    q = wandering(problem, 1200)
    full = clearances(robot, problem.scene, sphere_centers_batch(robot, q))
    got = smallest_clearances(robot, problem.scene, q)
    for kind in ("self_pairs", "obstacles", "workspace"):
        want, have = per_configuration(getattr(full, kind)), getattr(got, kind)
        close = want <= WITHIN
        np.testing.assert_allclose(have[close], want[close], rtol=0, atol=1e-12)
        assert np.all(have[~close] > WITHIN) and np.all(have <= want + 1e-12), kind
        assert have.min() == pytest.approx(want.min(), abs=1e-12), kind  # the worst is exact, however far
    obstacles = per_configuration(full.obstacles)
    assert (obstacles < 0).any() and (obstacles > WITHIN).any()  # contacts and free stretches both occur


def test_a_kind_with_nothing_to_check_is_inf():
    problem = ocpkit.load_scenario(PROBLEMS["mbm box (boxes, a cylinder)"])
    assert problem.scene.workspace is None
    got = smallest_clearances(problem.robot, problem.scene, wandering(problem, 5))
    assert np.all(np.isinf(got.workspace)) and np.all(np.isfinite(got.obstacles))


def test_the_groups_hold_every_sphere_once_inside_their_bounds():
    robot = ocpkit.load_robot("panda")
    groups = sphere_groups(robot)
    members = groups.members[groups.member_mask]
    assert sorted(members.tolist()) == list(range(len(robot.sphere_radius)))
    for g, (spheres, mask) in enumerate(zip(groups.members, groups.member_mask)):
        spheres = spheres[mask]
        assert np.all(robot.sphere_joint[spheres] == groups.joint[g])
        reach = np.linalg.norm(robot.sphere_offset[spheres] - groups.offset[g], axis=1) + robot.sphere_radius[spheres]
        assert np.all(reach <= groups.radius[g] + 1e-15)
    pairs = {(a, b) for first, second, mask in zip(groups.first, groups.second, groups.pair_mask)
             for a, b in zip(first[mask], second[mask])}
    assert pairs == set(map(tuple, robot.self_collision.tolist()))


def test_a_small_robot_among_few_obstacles_gets_every_clearance_exactly():
    problem = list(random_problems(500, 1))[0]
    robot, scene = problem.robot, problem.scene
    assert len(robot.self_collision) + len(robot.sphere_radius) * len(scene.obstacle_radii) <= FULL_TERMS
    q = wandering(problem, 300)
    full = clearances(robot, scene, sphere_centers_batch(robot, q))
    got = smallest_clearances(robot, scene, q)
    for kind in ("self_pairs", "obstacles", "workspace"):
        np.testing.assert_array_equal(getattr(got, kind), per_configuration(getattr(full, kind)))
