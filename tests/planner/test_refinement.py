"""next_refinement on hand-made verifications: where the checks go, how the margin grows and the limits shrink."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.nlp import Refinement
from ocpkit.planner.build_cache import build
from ocpkit.planner.refinement import (DEFAULT_ROUNDS, LIMIT_BACKOFF, MIN_MARGIN_STEP, MIN_SHRINK, PENETRATION_FACTOR,
                                       RELAXED, STOPPED_BY_PACE, margin_step, next_refinement, solve_refined)
from ocpkit.solvers import SolverResult, SolverStatus
from ocpkit.verify import Check, Verification

CASE2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")


def verification(times=(0.3, 0.1), **worst) -> Verification:
    """A verification whose checks have the given worst values (tolerance 0.01 for limits, 0 for contact)."""
    tolerance = {"obstacle": 0.0, "self_collision": 0.0, "workspace": 0.0}
    checks = tuple(Check(name, value, tolerance.get(name, 0.01), 0.2, "rel") for name, value in worst.items())
    return Verification(checks, np.asarray(times, dtype=float))


def test_nothing_to_refine_when_verified():
    ok = verification(velocity=0.0, obstacle=-0.02)
    assert ok.ok and next_refinement(Refinement(), ok, 2.0) is None


def test_nothing_to_refine_without_violation_times():
    boundary_only = verification(times=(), boundary=1.0)
    assert not boundary_only.ok and next_refinement(Refinement(), boundary_only, 2.0) is None


def test_check_fractions_put_the_newest_violations_first():
    previous = Refinement(check_fractions=np.array([0.5, 0.9]))
    following = next_refinement(previous, verification((0.3, 0.1), obstacle=0.001), tf=2.0)
    np.testing.assert_allclose(following.check_fractions, [0.15, 0.05, 0.5, 0.9])


@pytest.mark.parametrize("penetration, step", [(0.001, 0.005), (0.0025, 0.005), (0.01, 0.02)])
def test_margin_grows_by_twice_the_penetration_at_least_5_mm(penetration, step):
    following = next_refinement(Refinement(extra_margin=0.01), verification(obstacle=penetration), 1.0)
    assert following.extra_margin == pytest.approx(0.01 + step)
    assert step == max(PENETRATION_FACTOR * penetration, MIN_MARGIN_STEP)


def test_the_deepest_contact_of_any_kind_sets_the_margin_step():
    following = next_refinement(Refinement(), verification(obstacle=0.004, self_collision=0.006, workspace=0.001), 1.0)
    assert following.extra_margin == pytest.approx(0.012)


def test_limit_violation_alone_keeps_the_margin_and_shrinks_the_limits():
    following = next_refinement(Refinement(limit_scale=0.9), verification(velocity=0.03, obstacle=-0.05), 1.0)
    excess = 0.03 - 0.01
    assert following.extra_margin == 0.0
    assert following.limit_scale == pytest.approx(0.9 * (1.0 - excess - LIMIT_BACKOFF))


def test_the_largest_limit_excess_sets_the_shrink():
    found = verification(velocity=0.02, torque=0.05, torque_rate=0.03)
    assert next_refinement(Refinement(), found, 1.0).limit_scale == pytest.approx(1.0 - 0.04 - LIMIT_BACKOFF)


def test_contact_alone_keeps_the_limit_scale():
    following = next_refinement(Refinement(limit_scale=0.8), verification(torque=0.005, obstacle=0.002), 1.0)
    assert following.limit_scale == 0.8


def test_margin_step_is_zero_without_contact():
    assert margin_step(0.0) == 0.0
    assert margin_step(-0.01) == 0.0
    assert margin_step(1e-6) == MIN_MARGIN_STEP


def test_a_large_limit_excess_shrinks_the_limits_by_at_most_min_shrink():
    following = next_refinement(Refinement(), verification(torque=1.2), 1.0)  # torque 120 % over its limit
    assert following.limit_scale == MIN_SHRINK


class Spy:
    """A prepared solver that records the parameters and guess of every solve and passes it on."""

    def __init__(self, solver) -> None:
        self.solver, self.calls = solver, []

    def solve(self, guess, parameters, bounds, max_wall_time=None, pace=None):
        self.calls.append((np.array(guess), np.array(parameters)))
        return self.solver.solve(guess, parameters, bounds, max_wall_time=max_wall_time, pace=pace)


@pytest.mark.slow
def test_a_continuation_solves_the_relaxed_problem_first_and_starts_the_real_one_there():
    made = build(CASE2, knots=8)
    discretization, spy = made.discretization, Spy(made.solver)
    w = discretization.initial_guess(CASE2)
    refined = solve_refined(discretization, spy, CASE2, w, relaxed=RELAXED)
    p = discretization.nlp.parameters
    (first_guess, relaxed), (second_guess, real) = spy.calls[:2]
    np.testing.assert_array_equal(first_guess, w)
    assert p.read(relaxed, "limit_scale") == RELAXED.limit_scale and p.read(real, "limit_scale") == 1.0
    assert p.read(relaxed, "margin") == pytest.approx(p.read(real, "margin") + RELAXED.extra_margin)
    assert not np.array_equal(second_guess, w)  # warm-started from the relaxed solution
    assert refined.verification.ok and refined.iterations > 0


class Converges:
    """A solver that 'converges' in `iterations` iterations to the guess it is given, clipped into the bounds."""

    def __init__(self, iterations: int) -> None:
        self.iterations, self.calls, self.paces = iterations, 0, []

    def solve(self, guess, parameters, bounds, max_wall_time=None, pace=None):
        self.calls += 1
        self.paces.append(pace)
        return SolverResult(np.clip(guess, *bounds), SolverStatus.CONVERGED, self.iterations, 0.0, "converged")


@pytest.mark.parametrize("budget, solves", [(np.inf, 1 + DEFAULT_ROUNDS), (250, 3), (100, 1)])
def test_no_refinement_round_starts_once_the_iteration_budget_is_spent(budget, solves, monkeypatch):
    always_one_more = lambda *_: Refinement()  # noqa: E731
    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "next_refinement", always_one_more)
    discretization = build(CASE2, knots=6).discretization
    solver = Converges(100)  # the straight line "converged": it collides, so it never verifies
    refined = solve_refined(discretization, solver, CASE2, discretization.initial_guess(CASE2),
                            iteration_budget=budget)
    assert solver.calls == solves and refined.iterations == 100 * solves and not refined.verification.ok


def test_only_the_first_solve_keeps_a_pace_the_rounds_start_near_a_solution(monkeypatch):
    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "next_refinement", lambda *_: Refinement())
    discretization = build(CASE2, knots=6).discretization
    solver = Converges(10)
    solve_refined(discretization, solver, CASE2, discretization.initial_guess(CASE2), rounds=2, pace=100)
    assert solver.paces == [100, None, None]


class StopsByTime(Converges):
    """A solver whose solves all stop by time after `iterations` iterations."""

    def solve(self, guess, parameters, bounds, max_wall_time=None, pace=None):
        result = super().solve(guess, parameters, bounds, max_wall_time, pace)
        return SolverResult(result.w, SolverStatus.TIME_LIMIT, self.iterations, 0.0, "stopped")


def test_rounds_verify_the_limits_first_and_the_answer_is_verified_in_full(monkeypatch):
    """Without contact rows, each motion over a limit is refined without its contact check; the motion returned
    has every check. With them (the default), every motion is verified in full."""
    asked = []
    checked = sys.modules["ocpkit.planner.refinement"].verify

    def too_fast_first(problem, trajectory, limits_first=False):
        asked.append(limits_first)
        if limits_first:
            return Verification((Check("velocity", 0.5, 0.01, 0.1, "rel"),), np.array([0.1]), contact_checked=False)
        return checked(problem, trajectory)

    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "verify", too_fast_first)
    discretization = build(CASE2, knots=6).discretization
    solver = Converges(10)
    refined = solve_refined(discretization, solver, CASE2, discretization.initial_guess(CASE2), rounds=1,
                            limits_first=True)
    assert solver.calls == 2 and refined.rounds == 1 and asked == [True, True, False]
    assert refined.verification.contact_checked and "obstacle" in {c.name for c in refined.verification.checks}
    assert len(refined.timing) == 2
    asked.clear()
    solve_refined(discretization, Converges(10), CASE2, discretization.initial_guess(CASE2), rounds=1)
    assert asked == [False, False]


def test_without_contact_rows_a_contact_ends_the_rounds_no_round_could_fix_it():
    """Case 2's straight line, within its limits, runs through the obstacle: with contact rows a round follows,
    without them (limits first) none does."""
    discretization = build(CASE2, knots=6).discretization
    for limits_first, solves in ((False, 2), (True, 1)):
        solver = Converges(10)
        refined = solve_refined(discretization, solver, CASE2, discretization.initial_guess(CASE2), rounds=1,
                                limits_first=limits_first)
        checks = {c.name: c for c in refined.verification.checks}
        assert solver.calls == solves and checks["velocity"].ok and not checks["obstacle"].ok


@pytest.mark.parametrize("pace, verified", [(100, False), (None, True)])
def test_a_first_solve_stopped_by_time_under_a_pace_is_not_verified(pace, verified, monkeypatch):
    """Its rung hands its time on: a dense verification there would only spend it (the same solve without a
    pace is verified, to report how far its motion is from a plan)."""
    calls = []
    checked = sys.modules["ocpkit.planner.refinement"].verify
    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "verify",
                        lambda *args, **kwargs: calls.append(1) or checked(*args, **kwargs))
    discretization = build(CASE2, knots=6).discretization
    refined = solve_refined(discretization, StopsByTime(5), CASE2, discretization.initial_guess(CASE2), pace=pace)
    assert refined.result.status == SolverStatus.TIME_LIMIT and refined.iterations == 5
    assert bool(calls) == verified and not refined.verification.ok
    assert bool(refined.verification.checks) == verified
    assert (refined.verification.skipped == STOPPED_BY_PACE) != verified


def test_no_refinement_round_starts_once_the_motion_needs_rows_the_nlp_lacks(monkeypatch):
    """Screening: rounds on an NLP without the rows the motion now needs are wasted; the caller rebuilds."""
    always_one_more = lambda *_: Refinement()  # noqa: E731
    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "next_refinement", always_one_more)
    discretization = build(CASE2, knots=6).discretization
    asked = []
    lacking = lambda motion: asked.append(motion.tf) or len(asked) == 2  # noqa: E731  (after the second solve)
    solver = Converges(10)
    refined = solve_refined(discretization, solver, CASE2, discretization.initial_guess(CASE2), lacking=lacking)
    assert solver.calls == 2 and refined.rounds == 1 and not refined.verification.ok


def test_a_round_starts_from_the_last_solution_relifted_at_its_own_check_slots(monkeypatch):
    """A round that moves the adaptive checks starts with its lifting rows satisfied (Discretization.relifted),
    not from w lifted where the checks were."""
    moved = Refinement(np.array([0.37, 0.81]))
    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "next_refinement", lambda *_: moved)
    discretization = build(CASE2, knots=6).discretization
    seen = []

    class Records(Converges):
        def solve(self, guess, parameters, bounds, max_wall_time=None, pace=None):
            seen.append(np.array(guess))
            return super().solve(guess, parameters, bounds, max_wall_time, pace)

    w = discretization.initial_guess(CASE2)
    solve_refined(discretization, Records(10), CASE2, w, rounds=1)
    assert len(seen) == 2
    np.testing.assert_allclose(seen[1], discretization.relifted(np.clip(w, *discretization.bounds(CASE2)), moved))
    assert not np.allclose(seen[1], seen[0])
