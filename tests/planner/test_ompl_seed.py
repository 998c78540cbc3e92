"""The OMPL seed: a timed motion without verification, the same one the ompl-toppra baseline verifies, and the
simultaneous planner's "ompl" guess (slowed, on the NLP grid) made from it without any verification."""

from __future__ import annotations

import dataclasses
import gc
import importlib
import time
import weakref
from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest
from helpers import REPO, discretize

import ocpkit
from ocpkit.baselines.ompl_toppra import plan_ompl_toppra
from ocpkit.errors import OptionError
from ocpkit.planner.guesses import GUESS_SLOWDOWN, ompl_guess
from ocpkit.planner import ompl_seed as ompl_seed_module
from ocpkit.planner.ompl_seed import PathMotion, SeedOptions, ompl_seed, slowed


@pytest.fixture(scope="module")
def case1():
    return ocpkit.load_scenario(REPO / "scenarios/paper/case1.yaml")


@pytest.fixture
def no_verify(monkeypatch):
    """`verify` replaced, where the planners call it, by a stand-in that raises."""
    def refuse(*args, **kwargs):
        raise AssertionError("verify was called")

    names = ("ocpkit.verify", "ocpkit.result", "ocpkit.planner.refinement")
    modules = [importlib.import_module(name) for name in names]
    for module in modules:  # all imported first: one imported after the patch would keep the stand-in for good
        monkeypatch.setattr(module, "verify", refuse)


def test_the_seed_is_the_baselines_motion_and_its_figures(case1):
    seed, plan = ompl_seed(case1, SeedOptions(seed=2)), plan_ompl_toppra(case1, seed=2)
    assert seed.stopped is None and isinstance(seed.trajectory.interpolant, PathMotion)
    np.testing.assert_array_equal(seed.trajectory.knots.q, plan.trajectory.knots.q)
    assert seed.path == plan.stats.path and seed.message == plan.stats.solver_message
    assert seed.timing.path_search > 0 and seed.timing.path_timing > 0 and seed.timing.guess is None


def test_the_ompl_guess_never_verifies(case1, no_verify):
    nlp = discretize(case1, "chebyshev", "casadi-rnea", knots=6)
    decoded = nlp.decode(ompl_guess(case1, nlp))
    np.testing.assert_allclose(decoded.knots.q[[0, -1]], [case1.start, case1.goal], atol=1e-9)
    assert decoded.tf > case1.velocity_lower_bound()
    with pytest.raises(AssertionError, match="verify was called"):
        plan_ompl_toppra(case1)  # the baseline does verify: the stand-in is in place


def test_without_a_path_the_seed_has_no_motion_and_says_why(case1, no_verify):
    seed = ompl_seed(case1, SeedOptions(planning_time=0.0))
    assert seed.trajectory is None and seed.stopped == "no_path" and "no exact path" in seed.message
    assert seed.path.waypoints == 0 and seed.timing.smooth == 0.0


def test_the_guess_counts_its_checkers_construction_against_its_planning_time(case1, monkeypatch):
    build, searched = ompl_seed_module.planning_space, []

    def slow_build(problem, margin):
        time.sleep(0.3)
        return build(problem, margin)

    def search(problem, free, planner_name, planning_time, *args):
        searched.append(planning_time)
        return ompl_seed_module.OmplPath(None, 0.0, 0.0)

    monkeypatch.setattr(ompl_seed_module, "planning_space", slow_build)
    monkeypatch.setattr(ompl_seed_module, "ompl_path", search)
    nlp = discretize(case1, "chebyshev", "casadi-rnea", knots=6)
    ompl_guess(case1, nlp, planning_time=1.0)
    ompl_seed(case1, SeedOptions(planning_time=1.0))  # the baselines' search: planning_time is OMPL's own
    assert searched[0] <= 0.7 and searched[1] == 1.0


def test_an_option_the_seed_does_not_take_is_refused_by_the_planner(case1):
    with pytest.raises(OptionError, match="guess 'ompl'.*knots"):
        ocpkit.plan(case1, knots=6, guess="ompl", guess_options={"knots": 3}, fallbacks=())


@pytest.mark.slow
def test_ompl_guess_is_the_baseline_motion_slowed_on_the_nlp_grid(case1):
    nlp = discretize(case1, "chebyshev", "casadi-rnea", knots=6)
    baseline = plan_ompl_toppra(case1)
    w = ompl_guess(case1, nlp)
    assert w.shape == nlp.initial_guess(case1).shape
    decoded = nlp.decode(w)
    assert decoded.tf == pytest.approx(GUESS_SLOWDOWN * baseline.trajectory.tf)
    np.testing.assert_allclose(decoded.knots.q[[0, -1]], [case1.start, case1.goal], atol=1e-9)
    middle = baseline.trajectory.tf / 2
    np.testing.assert_allclose(decoded.interpolant(np.array([GUESS_SLOWDOWN * middle])).q,
                               baseline.trajectory.interpolant(np.array([middle])).q, atol=0.05)
    assert nlp.decode(ompl_guess(case1, nlp, slowdown=1.0)).tf == pytest.approx(baseline.trajectory.tf)
    np.testing.assert_array_equal(ompl_guess(case1, nlp, planning_time=0.0), nlp.initial_guess(case1))
    with pytest.raises(OptionError, match="slowdown"):
        ompl_guess(case1, nlp, slowdown=0.5)


@pytest.mark.slow
def test_a_slowed_motion_is_the_same_path_at_a_slower_pace_with_its_own_torque(case1):
    """q(t) = q₀(t / c), q̇ = q̇₀ / c, q̈ = q̈₀ / c², and the torque is pinocchio's RNEA of those plus friction."""
    motion = ompl_seed(case1).trajectory
    timed = motion.interpolant
    slower = dataclasses.replace(timed, slowdown=2.0)
    t = np.linspace(0.05, 0.9, 7) * 2.0 * timed.motion.path_interval[1]
    fast, slow = timed(t / 2.0), slower(t)
    np.testing.assert_allclose(slow.q, fast.q, atol=1e-12)
    np.testing.assert_allclose(slow.qd, fast.qd / 2.0, atol=1e-12)
    np.testing.assert_allclose(slow.qdd, fast.qdd / 4.0, atol=1e-12)
    robot = case1.robot
    data = robot.model.createData()
    expected = [pin.rnea(robot.model, data, *row).copy() for row in zip(slow.q, slow.qd, slow.qdd)]
    np.testing.assert_allclose(slow.tau, np.array(expected) + robot.friction(slow.qd), atol=1e-9)
    assert slowed(motion, 2.0).tf == pytest.approx(2.0 * motion.tf)


def test_a_hold_is_not_slowed(case1):
    still = ompl_seed(dataclasses.replace(case1, goal=case1.start.copy()))
    assert still.stopped is None and still.path is None and slowed(still.trajectory, 2.0) is still.trajectory


def test_a_repeated_search_reuses_the_path_found_with_its_checks(case1):
    free = ompl_seed_module.planning_space(case1, 0.01)
    first = ompl_seed_module.ompl_path(case1, free, "rrtconnect", 5.0, 4, 0.02, max_checks=10**6)
    again_free = ompl_seed_module.planning_space(case1, 0.01)
    again = ompl_seed_module.ompl_path(case1, again_free, "rrtconnect", 5.0, 4, 0.02, max_checks=10**6)
    assert first.waypoints is not None and again.waypoints is first.waypoints
    assert again.path_time == 0.0 and again_free.checks == free.checks > 0
    other = dataclasses.replace(case1)  # an equal problem, another object: searched again
    fresh = ompl_seed_module.ompl_path(other, ompl_seed_module.planning_space(other, 0.01), "rrtconnect", 5.0, 4,
                                       0.02, max_checks=10**6)
    assert fresh.path_time > 0.0
    np.testing.assert_array_equal(fresh.waypoints, first.waypoints)  # the same seed finds the same path


def test_a_search_counts_its_own_checks_apart_from_the_simplification(case1, monkeypatch):
    import ompl.geometric as og

    free = ompl_seed_module.planning_space(case1, 0.01)
    found = ompl_seed_module.ompl_path(case1, free, "rrtconnect", 5.0, 6, 0.02)
    monkeypatch.setattr(og.PathSimplifier, "simplifyMax", lambda _simplifier, _path: False)  # checks nothing
    other = dataclasses.replace(case1)  # another object: searched again, with the same seed
    bare_free = ompl_seed_module.planning_space(other, 0.01)
    bare = ompl_seed_module.ompl_path(other, bare_free, "rrtconnect", 5.0, 6, 0.02)
    assert bare.search_checks == bare_free.checks == found.search_checks < free.checks


def test_a_search_budgeted_in_time_or_in_fewer_checks_than_the_path_took_searches_again(case1):
    free = ompl_seed_module.planning_space(case1, 0.01)
    found = ompl_seed_module.ompl_path(case1, free, "rrtconnect", 5.0, 5, 0.02, max_checks=10**6)
    assert found.waypoints is not None and free.checks > 1
    short = ompl_seed_module.ompl_path(case1, ompl_seed_module.planning_space(case1, 0.01), "rrtconnect", 5.0, 5,
                                       0.02, max_checks=1)
    assert short.path_time > 0.0  # searched, not reused
    assert ompl_seed_module.ompl_path(case1, free, "rrtconnect", 0.0, 5, 0.02).waypoints is None


@pytest.mark.parametrize("margin", [0.005, 0.0])
def test_keeps_answers_what_the_clearances_answer_at_another_margin_and_counts_its_checks(case1, margin):
    free = ompl_seed_module.planning_space(case1, 0.01)
    rng = np.random.default_rng(3)
    q = rng.uniform(case1.robot.q_lower, case1.robot.q_upper, size=(400, case1.robot.n))
    reference = free.clearance(q) >= margin
    before = free.checks
    kept = free.keeps(q, margin)
    assert free.checks == before + len(q)
    assert 0 < kept.sum() < len(q)  # both answers occur
    np.testing.assert_array_equal(kept, reference)


def test_rrtconnect_then_lbkpiece_keeps_rrtconnects_path_or_finds_one_lazily_after_its_stage(case1, monkeypatch):
    def search(name: str) -> tuple[ompl_seed_module.OmplPath, ompl_seed_module.FreeSpace]:
        problem = dataclasses.replace(case1)  # another object each time: searched, not reused
        free = ompl_seed_module.planning_space(problem, 0.01)
        return ompl_seed_module.ompl_path(problem, free, name, 5.0, 6, 0.02, max_checks=10**6), free

    alone, _ = search("rrtconnect")
    staged, _ = search("rrtconnect-lbkpiece")
    np.testing.assert_array_equal(staged.waypoints, alone.waypoints)  # found within its stage: RRTConnect's path
    monkeypatch.setattr(ompl_seed_module, "STAGE_CHECKS", 1)  # RRTConnect stops at once, LBKPIECE1 goes on
    lazy, free = search("rrtconnect-lbkpiece")
    assert lazy.waypoints is not None and free.checks > 1
    np.testing.assert_array_equal(lazy.waypoints[[0, -1]], [case1.start, case1.goal])
    checker = ompl_seed_module.planning_space(case1, 0.01)
    assert all(checker.segment_free(a, b, 0.02) for a, b in zip(lazy.waypoints[:-1], lazy.waypoints[1:]))
    np.testing.assert_array_equal(search("rrtconnect-lbkpiece")[0].waypoints, lazy.waypoints)  # seeded: repeats


def test_ompl_counts_a_slow_joints_move_by_its_time_and_its_paths_end_exactly_at_start_and_goal(case1):
    robot = case1.robot
    space = ompl_seed_module.JointSpace(case1, ompl_seed_module.planning_space(case1, 0.01), 0.02)
    typical = np.median(robot.qd_max)
    slow = robot.qd_max < typical
    assert 0 < slow.sum() < robot.n  # the paper's robot has slow and fast joints
    q = 0.5 * (robot.q_lower + robot.q_upper)
    for joint in range(robot.n):
        moved = q.copy()
        moved[joint] += 0.3
        expected = 0.3 * typical / robot.qd_max[joint] if slow[joint] else 0.3  # seconds × typical speed, or rad
        assert space.si.distance(space.state(q), space.state(moved)) == pytest.approx(expected, rel=1e-12)
    np.testing.assert_allclose(space.q(space.state(q)), q, rtol=1e-15)
    found = ompl_seed_module.ompl_path(case1, ompl_seed_module.planning_space(case1, 0.01), "rrtconnect", 5.0, 7,
                                       0.02, max_checks=10**6)
    np.testing.assert_array_equal(found.waypoints[[0, -1]], [case1.start, case1.goal])


def test_a_joint_space_is_freed_once_dropped_so_no_ompl_object_outlives_its_search(case1):
    space = ompl_seed_module.JointSpace(case1, ompl_seed_module.planning_space(case1, 0.01), 0.02)
    checker = space.si.getStateValidityChecker()
    assert checker.isValid(space.state(case1.start))  # its checkers work ...
    alive = weakref.ref(space)
    del space, checker
    gc.collect()
    assert alive() is None  # ... and do not hold it: a cycle through OMPL's objects would keep it (and them)


def test_a_robot_without_slow_joints_plans_in_radians():
    panda = ocpkit.load_scenario(REPO / "scenarios/mbm/panda/box/0001.yaml").robot
    np.testing.assert_array_equal(ompl_seed_module.time_scale(panda), np.ones(panda.n))


def test_the_time_floor_is_each_segments_slowest_joint_at_its_limit():
    robot = type("Limits", (), {"qd_max": np.array([1.0, 2.0])})()
    waypoints = np.array([[0.0, 0.0], [1.0, 0.5], [1.0, 2.0], [0.0, 2.0]])
    assert ompl_seed_module.time_floor(robot, waypoints) == pytest.approx(1.0 + 0.75 + 1.0)
    assert ompl_seed_module.time_floor(robot, waypoints[:1]) == 0.0


@pytest.fixture
def searches_by_seed(monkeypatch):
    """`_search` replaced by a stand-in whose path for seed s moves the first joint out and back over
    `floors[s]` seconds at its velocity limit (no path for a seed not there); the seeds searched are in `asked`."""
    searches = SimpleNamespace(asked=[], floors={})

    def search(problem, free, planner_name, planning_time, seed, *args):
        searches.asked.append(seed)
        floor = searches.floors.get(seed)
        if floor is None:
            return ompl_seed_module.OmplPath(None, 0.1, 0.0)
        out = problem.start.copy()
        out[0] += floor / 2 * problem.robot.qd_max[0]
        return ompl_seed_module.OmplPath(np.array([problem.start, out, problem.start]), 0.1, 0.01)

    monkeypatch.setattr(ompl_seed_module, "_search", search)
    ompl_seed_module._found.clear()
    return searches


def test_a_slow_path_is_searched_again_and_the_fastest_kept(case1, searches_by_seed):
    problem = dataclasses.replace(case1, time=dataclasses.replace(case1.time, max=10.0))
    slow, faster, fastest_but_slow = 0.7 * 10.0, 0.65 * 10.0, 0.62 * 10.0  # all over SLOW_PATH = 0.6 of time.max
    searches_by_seed.floors = {0: slow, 1000: fastest_but_slow, 2000: faster}
    found = ompl_seed_module.ompl_path(problem, ompl_seed_module.planning_space(problem, 0.01), "rrtconnect", 5.0, 0,
                                       0.02)
    assert searches_by_seed.asked == [0, 1000, 2000] and found.searches == ompl_seed_module.SEARCHES == 3
    assert ompl_seed_module.time_floor(problem.robot, found.waypoints) == pytest.approx(fastest_but_slow)
    assert found.path_time == pytest.approx(0.3) and found.simplify_time == pytest.approx(0.03)


def test_a_path_fast_enough_or_found_again_is_searched_once(case1, searches_by_seed):
    problem = dataclasses.replace(case1, time=dataclasses.replace(case1.time, max=10.0))
    searches_by_seed.floors = {3: 0.5 * 10.0, 1003: 0.1}
    found = ompl_seed_module.ompl_path(problem, ompl_seed_module.planning_space(problem, 0.01), "rrtconnect", 5.0, 3,
                                       0.02, max_checks=10**6)
    assert searches_by_seed.asked == [3] and found.searches == 1
    searches_by_seed.floors = {4: 0.9 * 10.0}  # slow, and no second path: the first is kept
    found = ompl_seed_module.ompl_path(problem, ompl_seed_module.planning_space(problem, 0.01), "rrtconnect", 5.0, 4,
                                       0.02, max_checks=10**6)
    assert searches_by_seed.asked == [3, 4, 1004, 2004] and found.searches == 3 and found.waypoints is not None
    again = ompl_seed_module.ompl_path(problem, ompl_seed_module.planning_space(problem, 0.01), "rrtconnect", 5.0, 4,
                                       0.02, max_checks=10**6)
    assert searches_by_seed.asked == [3, 4, 1004, 2004] and again.waypoints is found.waypoints and again.searches == 3


def test_no_search_again_once_the_time_is_spent(case1, searches_by_seed):
    problem = dataclasses.replace(case1, time=dataclasses.replace(case1.time, max=10.0))
    searches_by_seed.floors = {0: 9.0, 1000: 1.0}
    ompl_seed_module.ompl_path(problem, ompl_seed_module.planning_space(problem, 0.01), "rrtconnect", 0.0, 0, 0.02)
    assert searches_by_seed.asked == [0]
