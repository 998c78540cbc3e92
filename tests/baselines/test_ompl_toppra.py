"""The OMPL + TOPP-RA baseline: OMPL sees exactly the verifier's collision model, seeded runs repeat, bad
start/goal fail fast with the contact named, and a paper case is planned from rest to rest."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest
from helpers import REPO

import ocpkit
import ocpkit.baselines  # noqa: F401  (registers "ompl-toppra")
from ocpkit.baselines.ompl_toppra import plan_ompl_toppra
from ocpkit.errors import OptionError, RegistryError, ScenarioError
from ocpkit.geometry.clearances import clearances, sphere_centers
from ocpkit.planner.ompl_seed import MAX_STEP, FreeSpace, JointSpace, _planner, planning_space
from ocpkit.tolerances import GEOMETRY_TOLERANCE


@pytest.fixture(scope="module")
def case1():
    return ocpkit.load_scenario(REPO / "scenarios/paper/case1.yaml")


@pytest.fixture(scope="module")
def configurations(case1):
    """300 seeded uniform configurations inside the joint limits, (300, n)."""
    robot = case1.robot
    return np.random.default_rng(7).uniform(robot.q_lower, robot.q_upper, (300, robot.n))


def verifier_says_free(problem, q):
    """The verifier's geometric verdict per configuration: no penetration beyond its tolerance, shape (K,)."""
    c = clearances(problem.robot, problem.scene, sphere_centers(problem.robot, q))
    penetration = np.concatenate([-c.self_pairs, -c.obstacles.reshape(len(q), -1), -c.workspace.reshape(len(q), -1)],
                                 axis=1)
    return penetration.max(axis=1) <= GEOMETRY_TOLERANCE


def test_ompl_validity_checker_agrees_with_the_verifier(case1, configurations):
    space = JointSpace(case1, FreeSpace(case1, 0.0), resolution=0.01)
    ompl_free = np.array([space.si.isValid(space.state(q)) for q in configurations])
    expected = verifier_says_free(case1, configurations)
    assert 50 < expected.sum() < len(configurations) - 50  # both verdicts are well represented
    np.testing.assert_array_equal(ompl_free, expected)


def test_the_margin_rejects_configurations_closer_than_it(case1, configurations):
    touching = FreeSpace(case1, 0.0).clearance(configurations)
    kept = FreeSpace(case1, 0.05).free(configurations)
    np.testing.assert_array_equal(kept, touching >= 0.05)
    assert np.any((touching >= 0) & ~kept)


def test_a_segment_through_an_obstacle_is_rejected_although_its_ends_are_free(case1):
    free = FreeSpace(case1, 0.0)
    a, b = case1.start, case1.goal
    middle = a + np.outer(np.linspace(0, 1, 201), b - a)
    assert free.free(np.stack([a, b])).all() and not free.free(middle).all()  # case1's straight line hits
    assert not free.segment_free(a, b, resolution=0.01)
    assert free.segment_free(a, b, resolution=10.0)  # one check, at b: the resolution is what finds it


def test_an_unknown_ompl_planner_is_named_with_the_known_ones(case1):
    with pytest.raises(RegistryError, match="'rrt-magic'.*rrtconnect"):
        ocpkit.plan(case1, planner="ompl-toppra", planner_name="rrt-magic")


def test_a_goal_in_collision_fails_fast_naming_the_contact(case1, configurations):
    goal = configurations[~verifier_says_free(case1, configurations)][0]
    began = time.perf_counter()
    with pytest.raises(ScenarioError, match=r"goal configuration is in collision: .*sphere \d+ \(link_"):
        ocpkit.plan(dataclasses.replace(case1, goal=goal), planner="ompl-toppra", planning_time=30.0)
    assert time.perf_counter() - began < 2.0  # no planner ran into its budget


def test_a_start_outside_the_limits_names_the_joint(case1):
    start = case1.start.copy()
    start[2] = case1.robot.q_upper[2] + 0.1
    with pytest.raises(ScenarioError, match=r"start: joint 3 \(joint_3\)"):
        ocpkit.plan(dataclasses.replace(case1, start=start), planner="ompl-toppra")


def test_no_path_within_the_budget_is_a_status_and_the_robot_holds_still(case1):
    plan = plan_ompl_toppra(case1, planning_time=0.0)
    assert plan.status == "no_path" and not plan.ok
    samples = plan.trajectory.sample()
    np.testing.assert_array_equal(samples.q, np.tile(case1.start, (len(samples.t), 1)))
    assert not {c.name: c for c in plan.verification.checks}["boundary"].ok  # the goal is not reached


def test_a_budget_in_checks_stops_the_search_without_a_timer(case1):
    plan = plan_ompl_toppra(case1, planning_time=np.inf, max_checks=0)
    assert plan.status == "no_path" and "validity checks" in plan.stats.solver_message
    assert plan.stats.path.validity_checks < 1000  # checked between OMPL's steps: at most one segment late
    with pytest.raises(OptionError, match="prm"):
        plan_ompl_toppra(case1, planner_name="prm", max_checks=50)


def test_rrts_extend_at_most_max_step_and_a_step_that_is_not_positive_is_named(case1):
    si = JointSpace(case1, planning_space(case1, 0.01), 0.01).si
    assert _planner(si, "RRTConnect", 0.7).getRange() == 0.7
    assert _planner(si, "RRTstar", MAX_STEP).getRange() == MAX_STEP
    assert _planner(si, "LBKPIECE1", 0.7).getRange() == 0.7
    assert _planner(si, "RRTConnect", None).getRange() == 0.0  # OMPL's default, set when the planner is set up
    assert not hasattr(_planner(si, "BITstar", 0.7), "getRange")  # BIT* has no step: made as it is
    for step in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(OptionError, match="max_step"):
            plan_ompl_toppra(case1, max_step=step)


@pytest.mark.slow
def test_seeded_runs_repeat_exactly(case1):
    first, second = (plan_ompl_toppra(case1, seed=3) for _ in range(2))
    assert first.trajectory.tf == second.trajectory.tf
    np.testing.assert_array_equal(first.trajectory.knots.q, second.trajectory.knots.q)
    other = plan_ompl_toppra(case1, seed=4)
    assert other.trajectory.tf != first.trajectory.tf  # the seed is what fixes the path


def test_options_of_other_planners_are_refused_naming_the_baselines_own(case1):
    with pytest.raises(OptionError, match="'knots'.*planner_name, planning_time"):
        ocpkit.plan(case1, planner="ompl-toppra", knots=12)


@pytest.mark.slow
def test_case1_is_planned_from_rest_to_rest_and_only_the_torque_rate_fails(case1):
    plan = ocpkit.plan(case1, planner="ompl-toppra")
    samples = plan.trajectory.sample()
    np.testing.assert_allclose(samples.q[[0, -1]], [case1.start, case1.goal], atol=1e-9)
    np.testing.assert_allclose(samples.qd[[0, -1]], 0.0, atol=1e-9)
    np.testing.assert_allclose(samples.qdd[[0, -1]], 0.0, atol=1e-9)
    failed = {c.name for c in plan.verification.checks if not c.ok}
    assert failed <= {"torque_rate"}  # TOPP-RA cannot bound it; everything else holds
    assert plan.status == ("verified" if not failed else "violated")
    assert case1.velocity_lower_bound() < plan.trajectory.tf < 2.0
    assert plan.method == {"planner": "ompl-toppra", "path_planner": "rrtconnect-lbkpiece", "grid_points": 1000}
    path, timing = plan.stats.path, plan.stats.timing
    assert path.validity_checks > 0 and path.waypoints >= 2
    assert all(seconds > 0 for seconds in (timing.path_search, timing.simplify, timing.path_timing))
    figures = plan.stats.figures()
    assert set(figures) == {"path_time_s", "simplify_time_s", "smooth_time_s", "toppra_time_s", "validity_checks",
                            "waypoints", "repair_rounds", "margin_m", "path_searches"}
    assert (figures["validity_checks"], figures["toppra_time_s"]) == (path.validity_checks, timing.path_timing)


def test_a_goal_equal_to_the_start_is_a_verified_hold_at_the_start(case1):
    still = plan_ompl_toppra(dataclasses.replace(case1, goal=case1.start.copy()))
    assert still.status == "verified", still.verification.summary()
    assert still.trajectory.tf == case1.time.min and still.found
    np.testing.assert_array_equal(still.trajectory.sample().q, np.tile(case1.start, (101, 1)))


def test_no_path_says_that_no_trajectory_was_found(case1):
    plan = plan_ompl_toppra(case1, planning_time=0.0)
    assert not plan.found and plan.stats.iterations == 0
    assert "no trajectory" in plan.stats.solver_message and "raise planning_time" in plan.hint


def test_ompl_avoids_boxes_and_cylinders():
    """On scenarios/shapes/boxes.yaml (the straight line hits the post) the validity checker agrees with the exact
    distances and the path OMPL returns keeps clear of every box and cylinder at every dense sample."""
    problem = ocpkit.load_scenario(REPO / "scenarios/shapes/boxes.yaml")
    rng = np.random.default_rng(5)
    configurations = rng.uniform(problem.robot.q_lower, problem.robot.q_upper, (300, problem.robot.n))
    space = JointSpace(problem, FreeSpace(problem, 0.0), resolution=0.01)
    ompl_free = np.array([space.si.isValid(space.state(q)) for q in configurations])
    obstacle_free = clearances(problem.robot, problem.scene, sphere_centers(problem.robot, configurations)
                               ).obstacles.min(axis=(1, 2)) >= 0
    assert (~obstacle_free).sum() >= 20  # the boxes and cylinders do reject configurations
    np.testing.assert_array_equal(ompl_free, verifier_says_free(problem, configurations))
    line = problem.start + np.outer(np.linspace(0, 1, 101), problem.goal - problem.start)
    assert not FreeSpace(problem, 0.0).free(line).all()
    result = plan_ompl_toppra(problem, seed=0)
    q = result.trajectory.sample(1e-3).q
    assert clearances(problem.robot, problem.scene, sphere_centers(problem.robot, q)).obstacles.min() >= 0


def test_ompl_plans_with_at_most_half_the_ends_clearance_as_margin():
    cage = ocpkit.load_scenario(REPO / "scenarios/mbm/panda/cage/0001.yaml")  # its goal is 9.4 mm from a wall
    ends = FreeSpace(cage, 0.0).clearance(np.stack([cage.start, cage.goal])).min()
    assert 0.0 < ends < 0.02
    assert planning_space(cage, 0.01).margin == pytest.approx(0.5 * ends)
    case2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")  # clear ends: the margin as asked
    assert planning_space(case2, 0.01).margin == 0.01


def test_a_violated_plan_names_what_this_planner_can_change():
    """The baseline cannot bound the torque rate, and has no knots or refinements: its hint names ompl-topp3."""
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case1.yaml")
    plan = ocpkit.plan(problem, planner="ompl-toppra")
    failed = {c.name for c in plan.verification.checks if not c.ok}
    assert plan.status == "violated" and "torque_rate" in failed
    assert "ompl-topp3" in plan.hint and "knots" not in plan.hint
