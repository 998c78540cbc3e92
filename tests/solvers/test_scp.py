"""The `scp` solver beyond the generic solver tests: infeasibility, bounds, convex problems, quasi-Newton
curvature, multipliers, QP solver failures and (slow) a paper case against IPOPT."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from helpers import REPO
from toy_nlps import BOUNDS, GUESS, PARAMS, decision_vector, optimum, rosenbrock_disk, toy_nlp

import ocpkit
from ocpkit.nlp import NLP
from ocpkit.solvers import scp
from ocpkit.solvers.base import SolverStatus
from ocpkit.solvers.casadi_nlpsol import Ipopt
from ocpkit.solvers.scp import SequentialConvex


def solve(nlp: NLP, guess: list, lbx: list, ubx: list, **options):
    """SequentialConvex(**options) on `nlp` (without parameters) from `guess` within lbx ≤ w ≤ ubx."""
    bounds = (np.array(lbx, dtype=float), np.array(ubx, dtype=float))
    return SequentialConvex(**options).solve(nlp, np.array(guess, dtype=float), np.zeros(0), bounds)


def test_disjoint_constraints_are_infeasible():
    variables, w = decision_vector(2)  # the unit disk and the half-plane w0 + w1 ≥ 3 do not meet
    nlp = toy_nlp(variables, ca.sumsqr(w), ca.vertcat(ca.sumsqr(w), w[0] + w[1]), [-np.inf, 3.0], [1.0, np.inf])
    result = solve(nlp, [0.5, 0.5], [-5, -5], [5, 5])
    assert result.status == SolverStatus.INFEASIBLE, result.message
    assert result.stats["penalty"] == 1e4


def test_every_evaluated_point_lies_inside_the_bounds(monkeypatch):
    evaluated = []
    evaluate = scp._Evaluator.__call__
    monkeypatch.setattr(scp._Evaluator, "__call__", lambda self, w: evaluated.append(w) or evaluate(self, w))
    variables, w = decision_vector(2)  # pushed far beyond the box [0, 1]²; the constraint is slack at (1, 1)
    nlp = toy_nlp(variables, -10 * w[0] - 10 * w[1] + ca.sumsqr(w), w[0] ** 2 + w[1], [-np.inf], [3.0])
    result = solve(nlp, [0.2, 0.9], [0, 0], [1, 1], trust_radius=50.0)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, [1.0, 1.0], atol=1e-9)
    assert len(evaluated) > 1 and all(np.all((0 <= p) & (p <= 1)) for p in evaluated)


def test_a_convex_qp_takes_few_subproblems():
    variables, w = decision_vector(3)  # the projection of (2, 1, 0) onto the half-space Σw ≤ 1; multiplier 4/3
    nlp = toy_nlp(variables, ca.sumsqr(w - ca.DM([2.0, 1.0, 0.0])), ca.sum1(w), [-np.inf], [1.0])
    result = solve(nlp, [0, 0, 0], [-10] * 3, [10] * 3, trust_radius=10.0, penalty=10.0)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, [4 / 3, 1 / 3, -2 / 3], atol=1e-6)
    assert result.iterations == 2  # with ρ above the multiplier the first step is exact; the second confirms


def test_damped_bfgs_without_an_exact_hessian():
    result = SequentialConvex().solve(rosenbrock_disk(exact_hessian=False), GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, optimum(), atol=1e-4)


def test_multipliers_match_ipopt():
    nlp = rosenbrock_disk()
    ours = SequentialConvex(tol=1e-8).prepare(nlp).solve(GUESS, PARAMS, BOUNDS)
    theirs = Ipopt(tol=1e-10).prepare(nlp).solve(GUESS, PARAMS, BOUNDS)
    assert ours.status == SolverStatus.CONVERGED, ours.message
    np.testing.assert_allclose(ours.lam_g, theirs.lam_g, rtol=1e-3)


def test_a_qp_solver_failure_is_a_failed_status():
    result = SequentialConvex(qp_solver="OSQP", max_iter=1).solve(rosenbrock_disk(), GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.FAILED and "OSQP" in result.message


def test_an_evaluation_error_is_a_failed_status():
    result = SequentialConvex().solve(rosenbrock_disk(), np.zeros(5), PARAMS, BOUNDS)  # a guess too long
    assert result.status == SolverStatus.FAILED and "ValueError" in result.message


@pytest.mark.slow
def test_scp_verifies_case2_at_the_ipopt_time():
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    plan = ocpkit.plan(problem, knots=8, solver="scp")  # 8 knots: a quarter of 12's time, the same agreement
    reference = ocpkit.plan(problem, knots=8, solver="ipopt")
    print(f"scp: {plan.status} t_f={plan.trajectory.tf:.5f} in {plan.stats.solve_time:.1f} s, "
          f"{plan.stats.iterations} QPs; ipopt: t_f={reference.trajectory.tf:.5f}")
    assert plan.status == "verified", plan.stats.solver_message
    assert abs(plan.trajectory.tf - reference.trajectory.tf) <= 0.01 * reference.trajectory.tf
