"""Issue 10: diverged iterates, the wall-time budget, self-consistency of a non-converged iterate, guesses of
the wrong length."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.constraints import DEFAULT_CONSTRAINTS
from ocpkit.errors import OptionError
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.nlp import Layout
from ocpkit.planner.build_cache import build
from ocpkit.planner.refinement import checked, solve_refined
from ocpkit.planner.simultaneous import plan_simultaneous
from ocpkit.solvers import PreparedSolver, SolverResult, SolverStatus
from ocpkit.verify import verify

CASE2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")


def layout() -> Layout:
    """w = [q (2 knots × 2 joints), t_f]."""
    w = Layout("w")
    w.add("q", 2, 2)
    w.add("tf")
    return w


BOUNDS = (np.array([-1.0, -1.0, -1.0, -1.0, 0.1]), np.array([1.0, 1.0, 1.0, 1.0, 10.0]))


def result(w, status=SolverStatus.CONVERGED) -> SolverResult:
    return SolverResult(np.asarray(w, dtype=float), status, 7, 1.0, "Solve_Succeeded")


def test_a_tf_outside_its_bounds_fails_naming_it():
    found = checked(result([0.0, 0.0, 0.0, 0.0, 4369.0]), layout(), BOUNDS)
    assert found.status == SolverStatus.FAILED
    assert "t_f = 4369 s outside [0.1, 10] s" in found.message and "Solve_Succeeded" in found.message


def test_an_entry_outside_its_bounds_is_named_by_knot_and_joint():
    found = checked(result([0.0, 0.0, 0.0, 1.5, 1.0]), layout(), BOUNDS)  # column-major: knot 1, joint 2
    assert found.status == SolverStatus.FAILED and "q[knot 1, joint 2] = 1.5" in found.message


@pytest.mark.parametrize("w", [[1.0 + 1e-7, -1.0, 0.0, 0.0, 10.0 + 1e-6], [0.0, 0.0, 0.0, 0.0, 5.0]])
def test_a_solution_within_the_slack_is_left_alone(w):
    given = result(w)
    assert checked(given, layout(), BOUNDS) is given


def test_nan_is_outside_the_bounds():
    assert checked(result([np.nan, 0.0, 0.0, 0.0, 1.0]), layout(), BOUNDS).status == SolverStatus.FAILED


class Recording(PreparedSolver):
    """A prepared solver that returns the guess, clipped into the bounds, as converged after `pause` s and
    records its time limits."""

    def __init__(self, pause: float) -> None:
        self.pause, self.limits = pause, []

    def solve(self, guess, params, bounds, max_wall_time=None, pace=None):
        self.limits.append(max_wall_time)
        time.sleep(self.pause)
        return SolverResult(np.clip(guess, *bounds), SolverStatus.CONVERGED, 1, self.pause, "ok")


@pytest.fixture(scope="module")
def made():
    return build(CASE2, "chebyshev", 6, "casadi-rnea", "ipopt", DEFAULT_CONSTRAINTS, None, None, None)


def test_each_solve_gets_the_time_left(made):
    solver = Recording(0.0)
    guess = made.discretization.initial_guess(CASE2)  # the straight line hits case 2's obstacle: refinement wanted
    began = time.perf_counter()
    refined = solve_refined(made.discretization, solver, CASE2, guess, rounds=2, deadline=began + 10.0)
    assert len(solver.limits) == 3 and refined.rounds == 2
    assert 9.0 < solver.limits[0] <= 10.0 and all(a > b for a, b in zip(solver.limits, solver.limits[1:]))


def test_no_refinement_round_starts_after_the_deadline(made):
    solver = Recording(0.02)
    guess = made.discretization.initial_guess(CASE2)
    refined = solve_refined(made.discretization, solver, CASE2, guess, rounds=5, deadline=time.perf_counter() + 0.01)
    assert len(solver.limits) == 1 and refined.result.status == SolverStatus.TIME_LIMIT
    assert "before refinement round 1" in refined.result.message


def test_a_guess_of_the_wrong_length_names_the_expected_length(made):
    expected = made.discretization.nlp.variables.size
    with pytest.raises(OptionError, match=f"needs {expected} values"):
        plan_simultaneous(CASE2, knots=6, guess=np.zeros(3))


def test_the_plan_stops_at_its_wall_time_limit():
    result = plan_simultaneous(CASE2, knots=6, max_wall_time=1e-3)
    assert result.status == "time_limit" and "raise max_wall_time" in result.hint


def test_a_velocity_that_is_not_dq_dt_fails_the_consistency_check():
    """As the issue's knots-2 iterate (now refused at input): q̇ off dq/dt by up to 0.16 rad/s mid-motion, zero
    at both ends."""
    plan = plan_simultaneous(CASE2, knots=6)
    tf = plan.trajectory.tf

    def shifted(t: np.ndarray) -> Samples:
        s = plan.trajectory.interpolant(t)
        return dataclasses.replace(s, qd=s.qd + 0.16 * np.sin(np.pi * np.asarray(t) / tf)[:, None])

    verification = verify(CASE2, Trajectory(shifted(plan.trajectory.knots.t), shifted))
    consistency = {c.name: c for c in verification.checks}["qd_consistency"]
    assert plan.ok and not consistency.ok and consistency.worst > 0.03
