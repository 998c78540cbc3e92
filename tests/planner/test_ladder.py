"""Issue 11: the fallback ladder — rung order, first verified wins, best-of on failure, the shared time budget,
rung overrides, OMPL rungs without a path, and the single shot of the paper."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.bench import paper
from ocpkit.bench import random as random_suite
from ocpkit.bench.common import Results
from ocpkit.cli.main import _planner_options, parser
from ocpkit.errors import NoGuess, OptionError
from ocpkit.formats.trajectory import Trajectory
from ocpkit.geometry.clearances import sphere_centers
from ocpkit.geometry.scene import Boxes
from ocpkit.planner import GUESSES, PLANNERS
from ocpkit.planner.guesses import ompl_guess
from ocpkit.planner.ladder import (DEFAULT_LADDER, FINER_ITERATIONS, NET_KNOTS, NET_SEGMENTS, NO_PATH_HINT,
                                   OMPL_CHECKS, OMPL_RESOLUTION, PACE_ITERATIONS, RESERVE_SHARE,
                                   RUNG_SHARE, SINGLE_SHOT, Rung, climb, finer, finer_grid, ordered, rank)
from ocpkit.planner.ompl_seed import OMPL_PLANNER
from ocpkit.planner.options import SimultaneousOptions
from ocpkit.planner.simultaneous import _timed_path, plan_simultaneous
from ocpkit.result import Plan, PlanStats, RungRow, SolveTiming, Timing
from ocpkit.verify import Check, Verification

CASE2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")


def fake(status: str, worst: float = 0.0, seconds: float = 1.0, iterations: int = 10, check: str = "obstacle",
         trajectory: object = None) -> Plan:
    """A plan with `status`, one `check` of `worst` (failed if > 0; at t = 0.5 s a path violation a refinement
    round can fix unless the check is "dynamics"), `seconds` of computation and 0.5 s of set-up."""
    times = np.array([0.5]) if worst > 0 and check != "dynamics" else np.zeros(0)
    verification = Verification((Check(check, worst, 0.0, 0.5, "m"),), times)
    stats = PlanStats(seconds, 0.5, iterations, 1, f"{status} message", extra={"own": 1})
    return Plan(trajectory, status, verification, stats, {"planner": "fake"})


class Script:
    """An attempt function that returns the scripted plan of each rung and records (rung name, seconds left)."""

    def __init__(self, plans: dict[str, Plan]) -> None:
        self.plans, self.calls = plans, []

    def __call__(self, rung: Rung | None, left: float) -> Plan:
        self.calls.append((rung.name if rung else None, left))
        return self.plans[rung.name if rung else "none"]


LADDER = (Rung("a"), Rung("b", guess="ompl", seed=1), Rung("c", knots=16))


def rounded(calls: list[tuple[str | None, float]]) -> list[tuple[str | None, float]]:
    """(rung, seconds) pairs with the seconds rounded to the µs, to compare sums made in another order."""
    return [(name, round(seconds, 6)) for name, seconds in calls]


def test_the_first_verified_rung_wins_and_later_rungs_do_not_run():
    script = Script({"a": fake("infeasible", seconds=2.0), "b": fake("verified"), "c": fake("verified")})
    result = climb(script, LADDER, 60.0)
    assert [name for name, _ in script.calls] == ["a", "b"]
    assert result.ok and result.method["rung"] == "b"
    assert result.stats.rungs == (RungRow("a", "infeasible", 2.0, 10), RungRow("b", "verified", 1.0, 10))
    assert result.stats.figures()["rungs"] == [
        {"rung": "a", "status": "infeasible", "time_s": 2.0, "iterations": 10},
        {"rung": "b", "status": "verified", "time_s": 1.0, "iterations": 10}]
    assert (result.stats.solve_time, result.stats.setup_time, result.stats.iterations) == (3.0, 1.0, 20)


def test_without_a_verified_rung_the_smallest_violation_is_the_best():
    script = Script({"a": fake("violated", 0.02), "b": fake("infeasible"), "c": fake("violated", 0.005)})
    result = climb(script, LADDER, 60.0)
    assert result.status == "violated" and result.method["rung"] == "c"
    assert result.stats.solver_message == "rung c: violated message"
    stats = result.stats
    assert stats.extra["own"] == 1 and len(stats.rungs) == 3 and stats.skipped == ()
    assert stats.figures()["own"] == 1 and stats.figures()["skipped"] == []


@pytest.mark.parametrize("statuses, best", [(("time_limit", "infeasible", "iteration_limit"), "infeasible"),
                                            (("failed", "iteration_limit", "time_limit"), "iteration_limit")])
def test_a_failure_reports_the_best_rungs_status(statuses, best):
    script = Script({rung.name: fake(status) for rung, status in zip(LADDER, statuses)})
    assert climb(script, LADDER, 60.0).status == best


NETTED = (Rung("a"), Rung("b", guess="ompl", seed=1), Rung("net", guess="ompl", seed=1, safety_net=True),
          Rung("c", knots=16))


def test_a_verified_safety_net_ends_the_climb_and_its_plan_is_the_answer():
    script = Script({"a": fake("infeasible"), "b": fake("violated", 0.01), "net": fake("verified", seconds=2.0),
                     "c": fake("verified")})
    result = climb(script, NETTED, 60.0)
    assert [name for name, _ in script.calls] == ["a", "b", "net"]
    assert result.ok and result.method["rung"] == "net"
    assert result.stats.solve_time == 4.0 and [r.rung for r in result.stats.rungs] == ["a", "b", "net"]


def test_the_safety_net_is_skipped_where_its_seeds_search_found_no_path():
    script = Script({"a": fake("infeasible"), "b": fake("no_path"), "net": fake("verified"),
                     "c": fake("infeasible")})
    result = climb(script, NETTED, 60.0)
    assert [name for name, _ in script.calls] == ["a", "b", "c"] and result.stats.skipped == ("net",)
    assert result.status == "no_path"  # the search's evidence, as without the net


def test_rank_orders_by_status_then_violation():
    plans = [fake("time_limit"), fake("violated", 0.3), fake("verified"), fake("infeasible"), fake("violated", 0.1)]
    assert [(p.status, p.verification.checks[0].worst) for p in sorted(plans, key=rank)] == [
        ("verified", 0.0), ("violated", 0.1), ("violated", 0.3), ("infeasible", 0.0), ("time_limit", 0.0)]


def test_a_motion_that_was_not_verified_ranks_last_among_plans_of_its_status():
    unverified = dataclasses.replace(fake("time_limit"), verification=Verification.not_run("stopped"))
    plans = [unverified, fake("time_limit", 0.3), fake("no_path")]
    assert sorted(plans, key=rank) == [plans[1], unverified, plans[2]]


def test_every_rung_gets_the_time_left_and_none_starts_after_the_budget():
    script = Script({"a": fake("infeasible", seconds=5.0), "b": fake("iteration_limit", seconds=4.0),
                     "c": fake("verified")})
    result = climb(script, LADDER, 8.0)
    reserve = RESERVE_SHARE * 8.0
    assert rounded(script.calls) == rounded([("a", 8.0 - reserve), ("b", 2.5 - reserve)])  # a's 5.5 s spent
    assert result.status == "infeasible" and result.method["rung"] == "a"


def test_a_rung_is_given_the_time_left_less_the_longest_verification_so_far():
    """A rung's last solve is verified after its time is up: the budget keeps room for that verification."""
    rounds = (SolveTiming(2.0, 0.5, 10), SolveTiming(1.0, 1.5, 5))
    a = fake("infeasible", seconds=5.0)
    a = dataclasses.replace(a, stats=dataclasses.replace(a.stats, timing=Timing(rounds=rounds)))
    script = Script({"a": a, "b": fake("iteration_limit", seconds=1.0), "c": fake("verified")})
    climb(script, LADDER, 10.0)
    reserve = RESERVE_SHARE * 10.0  # 10 − 5.5 s − 1.5 s; then 1.5 s less
    assert rounded(script.calls) == rounded([("a", 10.0 - reserve), ("b", 3.0 - reserve), ("c", 1.5 - reserve)])


def test_a_capped_rung_takes_at_most_its_share_of_the_budget_and_one_stopped_by_it_is_tried_uncapped():
    capped = (Rung("a", max_iterations=300), Rung("b", guess="ompl", seed=1), Rung("a-uncapped"))
    script = Script({"a": fake("time_limit", seconds=15.0), "b": fake("infeasible", seconds=4.0),
                     "a-uncapped": fake("verified")})
    result = climb(script, capped, 30.0)
    reserve = RESERVE_SHARE * 30.0
    assert rounded(script.calls) == rounded([("a", RUNG_SHARE * 30.0), ("b", 14.5 - reserve),
                                             ("a-uncapped", 10.0 - reserve)])
    assert result.method["rung"] == "a-uncapped" and result.stats.skipped == ()


def test_no_rung_starts_with_less_time_left_than_the_last_build_took():
    slow_build = dataclasses.replace(fake("infeasible", seconds=5.0), stats=dataclasses.replace(
        fake("infeasible").stats, solve_time=5.0, setup_time=3.5))
    script = Script({"a": slow_build, "b": fake("verified")})
    result = climb(script, LADDER, 10.0)  # 1.5 s left after a: less than a's 3.5 s build
    assert rounded(script.calls) == rounded([("a", 10.0 * (1 - RESERVE_SHARE))]) and result.method["rung"] == "a"


def test_an_empty_ladder_is_one_attempt_with_the_calls_options():
    plan = fake("violated", 0.1)
    script = Script({"none": plan})
    assert climb(script, SINGLE_SHOT, 7.0) is plan and script.calls == [(None, 7.0)]


def test_a_safety_net_searches_as_its_ompl_rung_did_so_it_times_the_path_found(monkeypatch):
    """The search options are the found path's key (ocpkit.planner.ompl_seed.ompl_path): the same ones find it."""
    given = {}
    monkeypatch.setitem(PLANNERS._items, "ompl-topp3", lambda problem, **options: given.update(options))
    options = SimultaneousOptions()
    _timed_path(CASE2, DEFAULT_LADDER[2].apply(options, 7.0), 0, 7.0)
    searched = DEFAULT_LADDER[1].apply(options, 7.0).guess_options
    keys = ("planner_name", "seed", "resolution", "max_checks")
    assert {k: given[k] for k in keys} == {k: searched[k] for k in keys}


def test_a_rung_overrides_only_what_it_names():
    options = SimultaneousOptions(guess="line", guess_options={"planning_time": 2.0}, knots=12,
                                  transcription="chebyshev", transcription_options={"staged": False},
                                  solver_options={"tol": 1e-7})
    changed = Rung("x", guess="ompl", seed=3, knots=16, segments=2, max_iterations=300).apply(options, 9.0)
    assert changed == dataclasses.replace(
        options, guess="ompl", guess_options={"fallback": False, "seed": 3, "planner_name": OMPL_PLANNER,
                                              "max_checks": OMPL_CHECKS, "planning_time": 9.0,
                                              "resolution": OMPL_RESOLUTION}, knots=16,
        transcription_options={"staged": False, "segments": 2}, solver_options={"tol": 1e-7, "max_iterations": 300},
        iteration_budget=300)
    assert options.knots == 12 and options.solver_options == {"tol": 1e-7}
    assert Rung("same").apply(options, 9.0) == options
    line = Rung("line", guess="line").apply(options, 9.0)
    assert line.guess_options == {"fallback": False}
    capped = Rung("cap", max_iterations=300).apply(
        dataclasses.replace(options, solver_options={"max_iterations": 50}), 9.0)
    assert capped.solver_options == {"max_iterations": 50} and capped.iteration_budget == math.inf


@pytest.mark.parametrize("rung, changes", [
    (DEFAULT_LADDER[0], {"solver_options": {"max_iterations": 100}, "iteration_budget": 100}),
    (DEFAULT_LADDER[1], {"guess": "ompl", "knots": 6, "transcription_options": {"segments": 3},
                         "guess_options": {"fallback": False, "seed": 0, "planner_name": OMPL_PLANNER,
                                           "max_checks": OMPL_CHECKS,
                                           "planning_time": 7.0,
                                           "resolution": OMPL_RESOLUTION},
                         "solver_options": {"max_iterations": 300}, "iteration_budget": 300,
                         "pace": PACE_ITERATIONS}),
    (DEFAULT_LADDER[3], {"guess": "ompl", "knots": 6, "transcription_options": {"segments": 3},
                         "guess_options": {"fallback": False, "seed": 1, "planner_name": OMPL_PLANNER,
                                           "max_checks": OMPL_CHECKS,
                                           "planning_time": 7.0,
                                           "resolution": OMPL_RESOLUTION},
                         "solver_options": {"max_iterations": 300}, "iteration_budget": 300,
                         "pace": PACE_ITERATIONS}),
    (DEFAULT_LADDER[5], {"guess": "ompl", "knots": 16,
                         "guess_options": {"fallback": False, "seed": 2, "planner_name": OMPL_PLANNER,
                                           "max_checks": OMPL_CHECKS,
                                           "planning_time": 7.0,
                                           "resolution": OMPL_RESOLUTION},
                         "solver_options": {"max_iterations": 300}, "iteration_budget": 300,
                         "pace": PACE_ITERATIONS}),
    (DEFAULT_LADDER[7], {"relaxed": True, "solver_options": {"max_iterations": 300}, "iteration_budget": 300}),
    (DEFAULT_LADDER[8], {})])
def test_each_default_rung_changes_the_calls_options_as_it_says(rung, changes):
    call = SimultaneousOptions(guess_options={"seed": 9})
    assert rung.apply(call, 7.0) == dataclasses.replace(call, **changes)


def test_a_rebuild_solves_within_what_is_left_of_the_rungs_iteration_budget():
    options = SimultaneousOptions(guess="line", solver_options={"tol": 1e-7, "max_iterations": 300})
    assert options.capped(120.0).solver_options == {"tol": 1e-7, "max_iterations": 120}
    assert options.capped(500.0).solver_options["max_iterations"] == 300
    assert dataclasses.replace(options, solver_options={}).capped(40.0).solver_options == {"max_iterations": 40}
    assert options.capped(math.inf) is options and options.solver_options["max_iterations"] == 300


def test_a_transcription_without_segments_keeps_the_calls_grid_on_a_rung_with_segments():
    options = SimultaneousOptions(guess="line", knots=40, transcription="trapezoidal")
    changed = Rung("x", guess="ompl", knots=6, segments=3).apply(options, 9.0)
    assert changed.knots == 40 and changed.transcription_options == {} and changed.guess == "ompl"
    assert Rung("y", knots=16).apply(options, 9.0).knots == 16


def test_without_a_wall_time_limit_the_ladder_ends_by_its_budgets_in_work_and_repeats():
    ompl = Rung("o", guess="ompl", seed=0).apply(SimultaneousOptions(guess="line"), math.inf).guess_options
    assert ompl["planning_time"] == math.inf and ompl["max_checks"] == OMPL_CHECKS
    plans = [plan_simultaneous(CASE2, knots=6, max_wall_time=math.inf) for _ in range(2)]
    assert all(p.ok for p in plans) and plans[0].stats.iterations == plans[1].stats.iterations
    np.testing.assert_array_equal(plans[0].trajectory.knots.q, plans[1].trajectory.knots.q)


def test_the_default_ladder_starts_with_the_calls_guess_and_ends_uncapped():
    assert DEFAULT_LADDER[0].guess is None and DEFAULT_LADDER[-1] == Rung(DEFAULT_LADDER[-1].name)
    assert len({rung.name for rung in DEFAULT_LADDER}) == len(DEFAULT_LADDER)


def test_every_ompl_rung_of_the_default_ladder_is_followed_by_the_safety_net_of_its_seed():
    for rung, after in zip(DEFAULT_LADDER, DEFAULT_LADDER[1:]):
        if rung.guess == "ompl" and not rung.safety_net:
            assert after.safety_net and after.seed == rung.seed


def test_a_buried_line_moves_the_rungs_that_start_from_it_after_the_first_ompl_rung():
    relaxed = Rung("relaxed", relaxed=True)
    ladder = (Rung("a"), relaxed, Rung("b", guess="ompl", seed=1), Rung("c", knots=16))
    assert ordered(ladder, False) == ladder
    assert [r.name for r in ordered(ladder, True)] == ["relaxed", "b", "a", "c"]
    assert ordered(ladder[:2], True) == ladder[:2]  # no OMPL rung: nothing to move
    assert [r.name for r in ordered(DEFAULT_LADDER, True)][:3] == [
        DEFAULT_LADDER[1].name, DEFAULT_LADDER[2].name, DEFAULT_LADDER[0].name]  # the OMPL rung keeps its net
    assert [r.name for r in ordered(NETTED, True)] == ["b", "net", "a", "c"]


def test_a_straight_line_with_a_sphere_centre_inside_an_obstacle_plans_the_ompl_rung_first(monkeypatch):
    base = sphere_centers(CASE2.robot, CASE2.start)[CASE2.robot.sphere_joint == 0][:1]  # a sphere that never moves
    box = Boxes(base, np.full((1, 3), 0.02), np.eye(3)[None])
    blocked = dataclasses.replace(CASE2, scene=dataclasses.replace(CASE2.scene, boxes=box))
    seen = []
    monkeypatch.setattr("ocpkit.planner.simultaneous.climb", lambda attempt, ladder, budget: seen.append(ladder))
    plan_simultaneous(blocked, knots=6)
    plan_simultaneous(blocked, knots=6, guess="ompl")  # a guess of its own: the ladder as given
    plan_simultaneous(CASE2, knots=6)  # its line is clear
    assert seen[0][0].guess == "ompl" and seen[1] == DEFAULT_LADDER and seen[2] == DEFAULT_LADDER


def test_a_safety_net_times_its_path_on_its_own_grid_with_the_calls_other_options(monkeypatch):
    attempts, timed = [], []
    monkeypatch.setattr("ocpkit.planner.simultaneous.climb", lambda attempt, ladder, budget: attempts.append(attempt))
    monkeypatch.setattr("ocpkit.planner.simultaneous._timed_path",
                        lambda problem, options, seed, left: timed.append((options, seed, left)))
    plan_simultaneous(CASE2, knots=6, solver_options={"tol": 1e-7})
    net = next(rung for rung in DEFAULT_LADDER if rung.safety_net)
    attempts[0](net, 5.0)
    options, seed, left = timed[0]
    assert (options.knots, options.transcription_options["segments"]) == (NET_KNOTS, NET_SEGMENTS)
    assert options.solver_options == {"tol": 1e-7} and (seed, left) == (net.seed, 5.0)
    assert all((r.knots, r.segments) == (NET_KNOTS, NET_SEGMENTS) for r in DEFAULT_LADDER if r.safety_net)


def test_a_plan_that_verifies_on_the_first_rung_reports_one_rung():
    result = plan_simultaneous(CASE2, knots=6)
    assert result.ok and result.method["rung"] == DEFAULT_LADDER[0].name
    assert [r.rung for r in result.stats.rungs] == [DEFAULT_LADDER[0].name]


def test_the_single_shot_reports_no_rungs():
    result = plan_simultaneous(CASE2, knots=6, fallbacks=SINGLE_SHOT)
    assert result.ok and result.stats.rungs == () and "rung" not in result.method
    assert "rungs" not in result.stats.figures()


def test_single_shot_on_the_command_line_means_no_fallbacks():
    args = parser().parse_args(["plan", "x.yaml", "--single-shot"])
    assert _planner_options(args) == {"fallbacks": ()}
    assert "fallbacks" not in _planner_options(parser().parse_args(["plan", "x.yaml"]))


def test_a_failed_ladder_where_ompl_found_no_path_says_so():
    script = Script({"a": fake("infeasible"), "b": fake("no_path"), "c": fake("iteration_limit")})
    result = climb(script, LADDER, 60.0)
    assert result.status == "no_path" and result.hint == NO_PATH_HINT  # the search's evidence, not rung a's failure
    assert result.method["rung"] == "b" and result.stats.solver_message == "rung b: no_path message"
    assert [r.status for r in result.stats.rungs] == ["infeasible", "no_path", "iteration_limit"]
    assert result.stats.hint == NO_PATH_HINT and result.stats.figures()["hint"] == NO_PATH_HINT
    script = Script({"a": fake("no_path"), "b": fake("verified")})
    assert climb(script, LADDER, 60.0).hint == ""
    ompl_twice = (Rung("a"), Rung("b", guess="ompl", seed=1), Rung("c", guess="ompl", seed=2))
    script = Script({"a": fake("infeasible"), "b": fake("violated", 0.1), "c": fake("no_path")})
    assert climb(script, ompl_twice, 60.0).status == "violated"  # one search found a path: not blocked


def test_an_ompl_guess_without_a_path_falls_back_to_the_papers_line_only_when_asked():
    discretization = ocpkit.build(CASE2, knots=6).discretization
    line = discretization.initial_guess(CASE2)  # the paper's rule, the planner's default
    np.testing.assert_array_equal(ompl_guess(CASE2, discretization, planning_time=0.0), line)
    with pytest.raises(NoGuess, match="no_path"):
        ompl_guess(CASE2, discretization, fallback=False, planning_time=0.0)


class Captured(Exception):
    """Raised by a stand-in planner with the options it was given."""


def capture(*args, **options):
    raise Captured(options)


def test_the_random_bench_passes_its_ladder_to_the_planner(monkeypatch):
    monkeypatch.setattr(random_suite, "plan", capture)
    with pytest.raises(Captured) as caught:
        random_suite.run_random(1, 1, fallbacks=SINGLE_SHOT)
    assert caught.value.args[0]["fallbacks"] == SINGLE_SHOT
    with pytest.raises(Captured) as caught:
        random_suite.run_random(1, 1)
    assert caught.value.args[0]["fallbacks"] == DEFAULT_LADDER


def test_the_paper_bench_plans_single_shot(monkeypatch, tmp_path):
    monkeypatch.setattr(paper, "measure", capture)
    bench = paper._Bench(Results(tmp_path / "results.csv"), tmp_path, 1, "chebyshev", {})
    with pytest.raises(Captured) as caught:
        bench.simultaneous("paper", CASE2, 6, "casadi-rnea", guess="ompl")
    assert caught.value.args[0]["fallbacks"] == SINGLE_SHOT and caught.value.args[0]["guess"] == "ompl"


CAPPED = (Rung("capped", max_iterations=300), Rung("other", guess="ompl"), Rung("uncapped"))


@pytest.mark.parametrize("first, runs", [("infeasible", ["capped", "other"]),
                                         ("iteration_limit", ["capped", "other", "uncapped"])])
def test_an_uncapped_repeat_runs_only_after_the_cap_was_hit(first, runs):
    script = Script({"capped": fake(first), "other": fake("no_path"), "uncapped": fake("violated", 0.1)})
    result = climb(script, CAPPED, 60.0)
    assert [name for name, _ in script.calls] == runs
    assert result.stats.skipped == (() if "uncapped" in runs else ("uncapped",))


def test_a_rung_whose_guess_has_no_start_ends_no_path_before_any_solve(monkeypatch):
    def nothing(problem, discretization, fallback=True):
        raise NoGuess("no start here")

    monkeypatch.setitem(GUESSES._items, "nothing", nothing)
    plan = plan_simultaneous(CASE2, knots=6, fallbacks=(Rung("n", guess="nothing"),))
    assert plan.status == "no_path" and plan.stats.iterations == 0 and "no start here" in plan.stats.solver_message
    assert np.all(plan.trajectory.knots.q == CASE2.start) and plan.trajectory.tf == CASE2.time.min  # holds the start


def test_a_path_search_ends_by_the_plans_deadline_whatever_planning_time_it_was_given(monkeypatch):
    given = []

    def searching(problem, discretization, fallback=True, planning_time=None):
        given.append(planning_time)
        raise NoGuess("stand-in search")

    monkeypatch.setitem(GUESSES._items, "searching", searching)
    plan_simultaneous(CASE2, knots=6, guess="searching", guess_options={"planning_time": 100.0}, max_wall_time=5.0,
                      fallbacks=())
    assert 0.0 < given[0] < 5.0  # what is left of 5 s after the build, not the 100 s asked for


def test_a_guess_that_ends_past_the_deadline_ends_the_plan_time_limit_without_a_solve(monkeypatch):
    def slow(problem, discretization, fallback=True):
        time.sleep(0.3)
        return discretization.initial_guess(problem)

    monkeypatch.setitem(GUESSES._items, "slow", slow)
    plan = plan_simultaneous(CASE2, knots=6, guess="slow", max_wall_time=0.2, fallbacks=())
    assert plan.status == "time_limit" and plan.stats.iterations == 0 and "guess" in plan.stats.solver_message


class Recording(Script):
    """A Script that also records the rungs it was given."""

    def __call__(self, rung: Rung | None, left: float) -> Plan:
        self.rungs = [*getattr(self, "rungs", []), rung]
        return super().__call__(rung, left)


def test_a_plan_violated_only_by_the_dynamics_residual_is_re_solved_on_a_finer_grid_from_its_motion():
    motion = object()
    script = Recording({"a": fake("violated", 0.02, seconds=5.0, check="dynamics", trajectory=motion),
                        "a-finer": fake("verified", seconds=2.0), "b": fake("verified")})
    result = climb(script, LADDER, 20.0)
    # a finer rung is capped: half the budget at most
    assert rounded(script.calls) == rounded([("a", 20.0 * (1 - RESERVE_SHARE)), ("a-finer", 10.0)])
    assert script.rungs[1].refines is motion and script.rungs[1].knots == LADDER[0].knots
    assert result.ok and result.method["rung"] == "a-finer"


@pytest.mark.parametrize("plan", [fake("violated", 0.02), fake("infeasible", 0.0, check="dynamics"),
                                  fake("verified")])
def test_no_finer_rung_follows_a_plan_a_refinement_round_could_fix_or_that_is_not_violated(plan):
    assert finer(Rung("a"), plan) is None


def test_a_finer_rung_is_capped_and_not_refined_again_nor_relaxed():
    plan = fake("violated", 0.02, check="dynamics", trajectory=object())
    rung = finer(Rung("a", guess="ompl", seed=2, segments=3, max_iterations=300, relaxed=True), plan)
    assert (rung.name, rung.segments, rung.max_iterations, rung.relaxed) == ("a-finer", 3, FINER_ITERATIONS, False)
    assert (rung.guess, rung.seed, rung.refines) == (None, None, plan.trajectory)  # its start is the motion
    assert finer(Rung("a", max_iterations=50), plan).max_iterations == 50
    assert finer(Rung("a"), plan).max_iterations == FINER_ITERATIONS
    assert finer(rung, plan) is None
    script = Script({"a": plan, "a-finer": fake("violated", 0.01, check="dynamics"), "b": fake("infeasible"),
                     "c": fake("infeasible")})
    climb(script, LADDER, 60.0)
    assert [name for name, _ in script.calls] == ["a", "a-finer", "b", "c"]


@pytest.mark.parametrize("transcription, options, rung, grid", [
    ("chebyshev", {}, Rung("x"), (12, {"segments": 2})),
    ("chebyshev", {"segments": 2}, Rung("x", knots=6, segments=3), (6, {"segments": 4})),
    ("lgl", {"staged": False}, Rung("x"), (12, {"staged": False, "segments": 2})),
    ("trapezoidal", {}, Rung("x", knots=6, segments=3), (18, {})),
    ("hermite-simpson", {}, Rung("x", knots=15), (23, {}))])
def test_a_finer_rung_adds_a_segment_or_half_the_intervals_and_starts_from_the_motion(transcription, options,
                                                                                      rung, grid):
    motion = object()
    call = SimultaneousOptions(transcription=transcription, knots=12, transcription_options=options,
                               guess_options={"seed": 4})
    changed = dataclasses.replace(rung, refines=motion).apply(call, 9.0)
    assert (changed.knots, changed.transcription_options) == grid
    assert changed.starting_guess() == ("motion", {"trajectory": motion})
    assert call.starting_guess() == ("paper", {"seed": 4})


@pytest.mark.parametrize("transcription, knots, options, grid", [
    ("chebyshev", 12, {}, (12, {"segments": 2})), ("chebyshev", 6, {"segments": 3}, (6, {"segments": 4})),
    ("lgl", 8, {}, (8, {"segments": 2})), ("trapezoidal", 40, {}, (60, {})), ("trapezoidal", 5, {}, (8, {})),
    ("hermite-simpson", 15, {}, (23, {}))])
def test_the_finer_grid_is_one_more_segment_else_half_as_many_intervals_again(transcription, knots, options, grid):
    finer = finer_grid(SimultaneousOptions(transcription=transcription, knots=knots,
                                           transcription_options=options))
    assert (finer.knots, finer.transcription_options) == grid


def test_the_motion_guess_samples_a_trajectory_on_another_grid():
    plan = plan_simultaneous(CASE2, knots=6, fallbacks=SINGLE_SHOT)
    coarse = plan.trajectory
    discretization = ocpkit.build(CASE2, knots=6, transcription_options={"segments": 2}).discretization
    w = GUESSES.get("motion")(CASE2, discretization, trajectory=coarse)
    sampled = discretization.decode(w)
    assert sampled.tf == pytest.approx(coarse.tf)
    np.testing.assert_allclose(sampled.knots.q, coarse.interpolant(sampled.knots.t).q, atol=1e-9)
    with pytest.raises(OptionError, match="guess 'motion' needs"):
        GUESSES.get("motion")(CASE2, discretization)
    fewer = Trajectory(dataclasses.replace(coarse.knots, q=coarse.knots.q[:, :5]), coarse.interpolant)
    with pytest.raises(OptionError, match="moves 5 joints, the robot has 6"):
        GUESSES.get("motion")(CASE2, discretization, trajectory=fewer)
