"""`finish` (status and stats of a Plan) and `ocpkit.plan` (validation before any planner, option errors)."""

from __future__ import annotations

import dataclasses
import json
import types

import numpy as np
import pytest
from helpers import REPO, monomial, polynomial_motion

import ocpkit
from ocpkit import result as result_module
from ocpkit.errors import OptionError, ScenarioError
from ocpkit.formats.record import Recorded, result_row, trajectory_header
from ocpkit.geometry.clearances import sphere_centers
from ocpkit.geometry.scene import Scene
from ocpkit.planner import PLANNERS
from ocpkit.result import PathStats, PlanStats, RungRow, Screening, SolveTiming, Timing, finish
from ocpkit.verify import Check, Verification

CASE2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
FREE = dataclasses.replace(CASE2, scene=Scene(workspace=CASE2.scene.workspace))
PASSED = Verification((Check("torque", -0.5, 0.01, 0.1, "rel"),), np.zeros(0))
FAILED = Verification((Check("torque", 0.5, 0.01, 0.1, "rel"),), np.array([0.1]))
MINIMUM_JERK = 10 * monomial(3) - 15 * monomial(4) + 6 * monomial(5)


@pytest.fixture
def motion():
    return polynomial_motion(FREE, 4.0, MINIMUM_JERK)


@pytest.fixture
def clock(monkeypatch):
    """ocpkit.plan's clock, frozen at 10 s."""
    monkeypatch.setattr(result_module, "time", types.SimpleNamespace(perf_counter=lambda: 10.0))


@pytest.mark.parametrize("given, status", [(PASSED, "verified"), (FAILED, "violated")])
def test_a_finished_plan_is_verified_or_violated_as_the_verification_says(motion, given, status):
    result = finish(FREE, motion, None, {"planner": "test"}, 0.0, verification=given)
    assert result.status == status and result.ok == (status == "verified")
    assert result.verification is given and result.method == {"planner": "test"}


@pytest.mark.parametrize("given", [PASSED, FAILED])
def test_the_planners_word_is_the_status_when_it_stopped(motion, given):
    result = finish(FREE, motion, "iteration_limit", {}, 0.0, verification=given)
    assert result.status == "iteration_limit" and not result.ok


def test_finish_verifies_the_trajectory_when_no_verification_is_given(motion):
    result = finish(FREE, motion, None, {}, 0.0)
    assert result.status == "verified", result.verification.summary()
    assert {c.name for c in result.verification.checks} >= {"torque", "obstacle", "boundary"}
    moved = dataclasses.replace(FREE, goal=FREE.goal + 0.01)
    assert finish(moved, motion, None, {}, 0.0).status == "violated"  # the motion misses the goal


def test_solve_time_excludes_the_setup_time(motion, clock):
    result = finish(FREE, motion, None, {}, started=4.0, setup_time=1.5, iterations=12, rounds=2, message="ok",
                    extra={"k": 1}, verification=PASSED)
    stats = result.stats
    assert stats.solve_time == pytest.approx(4.5) and stats.setup_time == 1.5
    assert (stats.iterations, stats.rounds, stats.solver_message, stats.extra) == (12, 2, "ok", {"k": 1})


def test_stats_extra_defaults_to_an_empty_dict(motion, clock):
    assert finish(FREE, motion, None, {}, 10.0, verification=PASSED).stats.extra == {}


ROUND = SolveTiming(0.12, 0.01, 27, {"nlp_f": 0.002, "total": 0.11})


def test_the_simultaneous_planners_figures_keep_their_json_shape(motion):
    timing = Timing(guess=0.01, setup={"graph": 0.1, "solver": 0.6, "compile": 0.0}, rounds=(ROUND, ROUND))
    stats = finish(FREE, motion, None, {}, 0.0, timing=timing, screening=Screening(8, 0), verification=PASSED).stats
    assert stats.figures() == {
        "timing": {"guess": 0.01, "rounds": [{"solve": 0.12, "verify": 0.01, "iterations": 27, "nlp_f": 0.002,
                                              "total": 0.11}] * 2, "setup": {"graph": 0.1, "solver": 0.6,
                                                                             "compile": 0.0}},
        "screening": {"rows_per_point": 8, "rebuilds": 0}}
    assert (timing.solve, timing.verify, timing.refinement) == pytest.approx((0.24, 0.02, 0.13))
    ladder = dataclasses.replace(stats, rungs=(RungRow("first", "violated", 0.281, 27),), skipped=("uncapped",),
                                 hint="try this")
    assert ladder.figures()["rungs"] == [{"rung": "first", "status": "violated", "time_s": 0.281, "iterations": 27}]
    assert (ladder.figures()["skipped"], ladder.figures()["hint"]) == (["uncapped"], "try this")


def test_a_baselines_figures_keep_their_flat_keys(motion):
    timing = Timing(path_search=0.2, simplify=0.05, smooth=0.0, path_timing=0.0)
    stats = finish(FREE, motion, "no_path", {}, 0.0, timing=timing, path=PathStats(4240, 0, 0, 0.01),
                   verification=PASSED, found=False).stats
    assert stats.figures() == {"path_time_s": 0.2, "simplify_time_s": 0.05, "smooth_time_s": 0.0,
                               "toppra_time_s": 0.0, "validity_checks": 4240, "waypoints": 0, "repair_rounds": 0,
                               "margin_m": 0.01, "path_searches": 1}
    timed = dataclasses.replace(stats, path=PathStats(4240, 3, 1, 0.01, toppra_tf=0.9), extra={"own": "x"})
    assert (timed.figures()["toppra_tf_s"], timed.figures()["own"]) == (0.9, "x")
    assert PlanStats(1.0, 0.0, 0, 0, "").figures() == {}


def test_a_planners_hint_is_the_plans_hint(motion):
    result = finish(FREE, motion, "infeasible", {}, 0.0, verification=PASSED)
    assert "locally infeasible" in result.hint
    hinted = dataclasses.replace(result, stats=dataclasses.replace(result.stats, hint="the planner's own word"))
    assert hinted.hint == "the planner's own word"


OLD_EXTRA = ('{"timing": {"guess": 0.0128, "rounds": [{"solve": 0.121, "verify": 0.0094, "iterations": 27, '
             '"nlp_f": 0.0002, "total": 0.120}], "setup": {"graph": 0.137, "solver": 0.676, "compile": 0.0}}, '
             '"screening": {"rows_per_point": 8, "rebuilds": 0}, "rungs": [{"rung": "first", "status": "verified", '
             '"time_s": 0.281, "iterations": 27}], "skipped": []}')


def test_a_results_row_reads_back_old_and_new(motion):
    stats = finish(FREE, motion, None, {"planner": "simultaneous"}, 0.0, iterations=27,
                   timing=Timing(guess=0.01, rounds=(ROUND,)), screening=Screening(8, 0), verification=PASSED).stats
    result = finish(FREE, motion, None, {"planner": "simultaneous"}, 0.0, verification=PASSED)
    row = result_row("paper", "case2", dataclasses.replace(result, stats=stats), 0.2, 0.8)
    recorded = Recorded.of({k: str(v) for k, v in row.items()})
    assert recorded.extra == json.loads(json.dumps(stats.figures())) and recorded.iterations == 27
    old = {**row, "extra": OLD_EXTRA}
    assert Recorded.of(old).extra["rungs"][0]["time_s"] == 0.281
    assert set(Recorded.of(old).extra["timing"]) == set(recorded.extra["timing"]) == {"guess", "rounds", "setup"}
    assert Recorded.of({**row, "extra": ""}).extra == {}


def test_a_motion_that_was_not_verified_has_no_checks_and_no_violation_figure(motion):
    result = finish(FREE, motion, "time_limit", {}, 0.0, verification=Verification.not_run("stopped by time"))
    row = result_row("mbm", "box_0001", result, 1.0, 0.5)
    assert result.status == "time_limit" and row["checks"] == "not verified: stopped by time"
    assert np.isnan(row["max_violation"]) and np.isnan(Recorded.of({k: str(v) for k, v in row.items()}).max_violation)
    assert trajectory_header(FREE, result)["checks"] == []


@pytest.fixture
def spy(monkeypatch):
    """A registered planner `spy(problem, speed=1.0)` that records its calls."""
    calls = []

    def planner(problem, speed: float = 1.0):
        calls.append((problem, speed))
        return "planned"

    monkeypatch.setitem(PLANNERS._items, "spy", planner)
    return calls


def test_a_valid_problem_reaches_the_planner_with_its_options(spy):
    assert ocpkit.plan(CASE2, "spy", speed=2.0) == "planned"
    assert spy == [(CASE2, 2.0)]


def test_a_start_outside_the_limits_is_refused_naming_the_joint(spy):
    start = CASE2.start.copy()
    start[1] = CASE2.robot.q_upper[1] + 0.1
    with pytest.raises(ScenarioError, match=r"start: joint 2 \(joint_2\)"):
        ocpkit.plan(dataclasses.replace(CASE2, start=start), "spy")
    assert spy == []


def test_a_start_in_collision_is_refused(spy):
    centre = sphere_centers(CASE2.robot, CASE2.start)[12]
    blocked = dataclasses.replace(CASE2, scene=Scene(centre[None], np.array([0.05]), CASE2.scene.workspace))
    with pytest.raises(ScenarioError, match="start configuration is in collision: .*sphere 12"):
        ocpkit.plan(blocked, "spy")
    assert spy == []


def test_nan_in_the_goal_is_refused(spy):
    goal = CASE2.goal.copy()
    goal[3] = np.nan
    with pytest.raises(ScenarioError, match="goal needs 6 finite joint values"):
        ocpkit.plan(dataclasses.replace(CASE2, goal=goal), "spy")
    assert spy == []


def test_an_option_the_planner_does_not_take_lists_its_options(spy):
    with pytest.raises(OptionError, match="bogus") as error:
        ocpkit.plan(CASE2, "spy", bogus=1)
    assert str(error.value).endswith("its options: speed") and spy == []


def test_an_option_the_simultaneous_planner_does_not_take_lists_its_options():
    with pytest.raises(OptionError, match="'planner_name'") as error:
        ocpkit.plan(CASE2, planner_name="rrtconnect")
    assert all(option in str(error.value) for option in ("knots", "solver", "refinements", "constraints"))


def verification_failing(*names: str) -> Verification:
    """A verification whose named checks fail (and a passing torque check)."""
    return Verification((Check("torque", -0.5, 0.01, 0.1, "rel"),)
                        + tuple(Check(name, 0.5, 0.01, 0.1, "rel") for name in names), np.zeros(0))


@pytest.mark.parametrize("stopped, failing, words", [
    ("infeasible", (), "locally infeasible"),
    ("iteration_limit", (), "raise max_iterations"),
    ("time_limit", (), "raise max_wall_time"),
    ("no_path", (), "raise planning_time"),
    (None, ("dynamics",), "more knots or segments"),
    (None, ("qd_consistency",), "more knots or segments"),
    (None, ("obstacle", "velocity"), "contact remains"),
    (None, ("torque_rate",), "a limit is exceeded"),
    (None, ("motion_time",), "solver diverged"),
])
def test_the_hint_follows_the_cause(motion, stopped, failing, words):
    result = finish(FREE, motion, stopped, {}, 0.0, message="Some_Status", verification=verification_failing(*failing))
    assert words in result.hint
    assert result.hint.count(". ") == 0  # one sentence


def test_a_failed_plan_quotes_the_solvers_message(motion):
    result = finish(FREE, motion, "failed", {}, 0.0, message="Search_Direction_Becomes_Too_Small",
                    verification=PASSED)
    assert "Search_Direction_Becomes_Too_Small" in result.hint


def test_a_verified_plan_has_no_hint(motion):
    assert finish(FREE, motion, None, {}, 0.0, verification=PASSED).hint == ""


def test_a_plan_has_a_trajectory_unless_the_planner_says_it_found_none(motion):
    assert finish(FREE, motion, None, {}, 0.0, verification=PASSED).found
    assert not finish(FREE, motion, "no_path", {}, 0.0, verification=PASSED, found=False).found


def test_each_planner_hints_at_what_it_can_change():
    from ocpkit.baselines.ompl_topp3 import TOPP3_HINTS
    from ocpkit.baselines.ompl_toppra import TOPPRA_HINTS
    from ocpkit.result import SIMULTANEOUS_HINTS

    rate = Verification((Check("torque_rate", 3.0, 0.01, 0.2, "rel"),), np.zeros(0))
    assert "ompl-topp3" in TOPPRA_HINTS.of("violated", rate, "")
    assert "knots" in TOPP3_HINTS.of("violated", rate, "") and "knots" in SIMULTANEOUS_HINTS.of("violated", rate, "")
    contact = Verification((Check("obstacle", 0.01, 0.0, 0.2, "m"),), np.zeros(0))
    contact_hint = TOPP3_HINTS.of("violated", contact, "")
    assert "margin" in contact_hint and "knots" not in contact_hint
    assert "max_iterations" in TOPP3_HINTS.of("iteration_limit", rate, "")
