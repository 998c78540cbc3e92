"""Every NLP solver behind the Solver interface: a small constrained NLP with a known optimum converges,
one solver instance prepares several NLPs independently, an iteration limit is reported as such, and (slow)
each plans a paper case through `ocpkit.plan`."""

from __future__ import annotations

import functools
import numpy as np
import pytest
from helpers import REPO
from toy_nlps import BOUNDS, DISK, GUESS, PARAMS, optimum, rosenbrock_disk

import ocpkit
from ocpkit.errors import OptionError
from ocpkit.solvers.base import SOLVERS, SolverStatus



def for_toy_nlps(solver: type) -> type:
    """`solver` for the toy NLPs, which have no stage structure: one dense stage where it needs stages."""
    return functools.partial(solver, single_stage=True) if solver.needs_stages else solver


ALL_SOLVERS = {name: for_toy_nlps(SOLVERS.get(name)) for name in SOLVERS.names()}

@pytest.mark.parametrize("name", ALL_SOLVERS)
def test_small_nlp_converges_to_the_known_optimum(name):
    result = ALL_SOLVERS[name]().prepare(rosenbrock_disk()).solve(GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, optimum(), atol=1e-4)


@pytest.mark.parametrize("name", ALL_SOLVERS)
def test_a_solver_keeps_no_state_between_nlps(name):
    solver, disks = ALL_SOLVERS[name](), (DISK, 1.6)  # the same shape; with 1.6 the disk is inactive
    prepared = [solver.prepare(rosenbrock_disk(disk=disk)) for disk in disks]
    for nlp_solver, disk in zip(prepared, disks):
        result = nlp_solver.solve(GUESS, PARAMS, BOUNDS)
        assert result.status == SolverStatus.CONVERGED, result.message
        np.testing.assert_allclose(result.w, optimum(disk), atol=1e-4)


@pytest.mark.parametrize("name", ["ipopt", "sqpmethod", "scipy-trust-constr"])
def test_quasi_newton_when_the_nlp_has_no_exact_hessian(name):
    result = ALL_SOLVERS[name]().solve(rosenbrock_disk(exact_hessian=False), GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, optimum(), atol=1e-4)


@pytest.mark.parametrize("name", ALL_SOLVERS)
def test_iteration_limit_is_reported(name):
    result = ALL_SOLVERS[name](max_iterations=2).solve(rosenbrock_disk(), GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.ITERATION_LIMIT, result.message


@pytest.mark.parametrize("name", ["ipopt", "sqpmethod", "scipy-slsqp", "scipy-trust-constr", "pyomo", "scp"])
def test_time_limit_is_reported(name):  # blocksqp and fatrop cannot be interrupted
    result = ALL_SOLVERS[name](max_wall_time=1e-9).solve(rosenbrock_disk(), GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.TIME_LIMIT, result.message


@pytest.mark.parametrize("name", ["sqpmethod", "fatrop"])
def test_casadi_errors_become_a_failed_status(name):
    result = ALL_SOLVERS[name]().solve(rosenbrock_disk(), np.zeros(5), PARAMS, BOUNDS)  # a guess too long
    assert result.status == SolverStatus.FAILED and "x0" in result.message


@pytest.mark.parametrize("name, options, exact_hessian, words", [
    ("fatrop", {}, False, "exact Hessian"),  # a callback backend's NLP
    ("sqpmethod", {"qpsol": "hpipm"}, True, "cannot be set up"),  # hpipm wants stage structure
])
def test_a_solver_that_cannot_take_the_nlp_says_so_at_set_up(name, options, exact_hessian, words):
    with pytest.raises(OptionError, match=words):
        ALL_SOLVERS[name](**options).prepare(rosenbrock_disk(exact_hessian))


VERIFIES = {"ipopt", "sqpmethod", "pyomo", "scp"}
"""Solvers that reliably verify case 2 at 8 knots; the others must end in a reported status."""
VERIFY_TIME = 120.0
"""s a solver of VERIFIES gets for its single shot: the test asks whether it converges, not how fast (sqpmethod's
dense QPs take seconds an iteration, and a tight limit made the test depend on the machine)."""


@pytest.mark.slow  # scp: tests/solvers/test_scp.py plans the same case at 8 knots and also compares t_f with ipopt's
@pytest.mark.parametrize("name", [name for name in ALL_SOLVERS if name not in ("ipopt", "scp")])
def test_solver_plans_a_paper_case(name):
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    grid = {"transcription": "hermite-simpson"} if SOLVERS.get(name).needs_stages else {}  # staged by itself
    limit = VERIFY_TIME if name in VERIFIES else 15.0
    plan = ocpkit.plan(problem, knots=8, solver=name, solver_options={"max_wall_time": limit}, max_wall_time=limit,
                       fallbacks=(), **grid)  # the solver's own solve, not the ladder's rungs
    print(f"{name}: {plan.status} t_f={plan.trajectory.tf:.4f} iterations={plan.stats.iterations}")
    assert plan.status in {"verified", "violated", "iteration_limit", "time_limit", "failed", "infeasible"}
    if name in VERIFIES:
        assert plan.status == "verified", plan.stats.solver_message


@pytest.mark.parametrize("name", sorted(set(ALL_SOLVERS) - {"blocksqp", "fatrop"}))  # these cannot be interrupted
def test_a_per_call_time_limit_overrides_the_solvers_own(name):
    prepared = ALL_SOLVERS[name](max_wall_time=60.0).prepare(rosenbrock_disk())
    assert prepared.solve(GUESS, PARAMS, BOUNDS, max_wall_time=1e-9).status == SolverStatus.TIME_LIMIT
    assert prepared.solve(GUESS, PARAMS, BOUNDS).status == SolverStatus.CONVERGED  # the next call: its own again


@pytest.mark.parametrize("name", ["ipopt", "sqpmethod"])
def test_a_solve_whose_pace_cannot_fit_its_iterations_in_its_time_stops_early(name):
    prepared = ALL_SOLVERS[name](max_wall_time=60.0).prepare(rosenbrock_disk())
    hopeless = prepared.solve(GUESS, PARAMS, BOUNDS, pace=10**12)  # 10¹² iterations cannot fit in 60 s
    assert hopeless.status == SolverStatus.TIME_LIMIT and "pace" in hopeless.message
    assert hopeless.iterations < 5
    assert prepared.solve(GUESS, PARAMS, BOUNDS, pace=100).status == SolverStatus.CONVERGED  # fast enough


@pytest.mark.parametrize("name", ["blocksqp", "fatrop"])
def test_an_uninterruptible_solver_reports_an_overrun_of_the_per_call_limit(name):
    prepared = ALL_SOLVERS[name](max_wall_time=60.0, max_iterations=2).prepare(rosenbrock_disk())
    assert prepared.solve(GUESS, PARAMS, BOUNDS, max_wall_time=1e-9).status == SolverStatus.TIME_LIMIT


CASE2 = REPO / "scenarios/paper/case2.yaml"


@pytest.mark.parametrize("transcription", ["trapezoidal", "hermite-simpson"])
def test_a_solver_that_needs_stages_gets_the_staged_nlp_by_name(transcription):
    problem = ocpkit.load_scenario(CASE2)
    assert ocpkit.build(problem, transcription, 6, solver="fatrop").discretization.nlp.stages is not None
    assert ocpkit.build(problem, transcription, 6, solver="ipopt").discretization.nlp.stages is None


@pytest.mark.parametrize("transcription, options", [("chebyshev", {}), ("lgr", {}),
                                                    ("trapezoidal", {"staged": False})])
def test_a_solver_that_needs_stages_refuses_an_nlp_without_them_saying_how_to_ask(transcription, options):
    problem = ocpkit.load_scenario(CASE2)
    with pytest.raises(OptionError, match="stage structure") as error:
        ocpkit.build(problem, transcription, 6, solver="fatrop", transcription_options=options)
    assert "single_stage" in str(error.value) and "\n" not in str(error.value)
    unstaged = ocpkit.build(problem, transcription, 6, solver="fatrop", solver_options={"single_stage": True},
                            transcription_options=options)
    assert unstaged.discretization.nlp.stages is None  # asked for: one dense stage
