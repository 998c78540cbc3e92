"""The `scp` solver beyond the generic solver tests: infeasibility, bounds, convex problems, quasi-Newton
curvature, multipliers, QP solver failures and (slow) a paper case against IPOPT."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
import pytest
from helpers import REPO
from test_solvers import optimum, rosenbrock_disk

import ocpkit
from ocpkit.solvers import scp
from ocpkit.solvers.base import SolverStatus
from ocpkit.solvers.casadi_nlpsol import Ipopt
from ocpkit.solvers.scp import SequentialConvex
from ocpkit.transcription.base import NLP


@dataclass
class Expressions(NLP):
    """An NLP given by its expressions alone: the tests pass guess, parameters and bounds to `solve`."""

    def bounds(self, problem=None, refinement=None):
        raise NotImplementedError

    def parameters(self, problem=None, refinement=None):
        return np.zeros(0)

    def initial_guess(self, problem=None):
        raise NotImplementedError

    def decode(self, w):
        raise NotImplementedError

    def encode(self, trajectory):
        raise NotImplementedError


def expressions(w: ca.SX, f: ca.SX, g: ca.SX, lbg: list, ubg: list, key: str) -> Expressions:
    """The NLP min f(w) s.t. lbg ≤ g(w) ≤ ubg, without parameters."""
    return Expressions(w, ca.SX.sym("p", 0), f, g, np.array(lbg, dtype=float), np.array(ubg, dtype=float), (key,))


def solve(nlp: NLP, guess: list, lbx: list, ubx: list, **options):
    bounds = (np.array(lbx, dtype=float), np.array(ubx, dtype=float))
    return SequentialConvex(**options).solve(nlp, np.array(guess, dtype=float), nlp.parameters(), bounds)


def test_disjoint_constraints_are_infeasible():
    w = ca.SX.sym("w", 2)  # the unit disk and the half-plane w0 + w1 ≥ 3 do not meet
    nlp = expressions(w, ca.sumsqr(w), ca.vertcat(ca.sumsqr(w), w[0] + w[1]), [-np.inf, 3.0], [1.0, np.inf],
                      "disjoint")
    result = solve(nlp, [0.5, 0.5], [-5, -5], [5, 5])
    assert result.status == SolverStatus.INFEASIBLE, result.message
    assert result.stats["penalty"] == 1e4


def test_every_evaluated_point_lies_inside_the_bounds(monkeypatch):
    evaluated = []
    evaluate = scp._Evaluator.__call__
    monkeypatch.setattr(scp._Evaluator, "__call__", lambda self, w: evaluated.append(w) or evaluate(self, w))
    w = ca.SX.sym("w", 2)  # pushed far beyond the box [0, 1]²; the constraint is slack at the corner (1, 1)
    nlp = expressions(w, -10 * w[0] - 10 * w[1] + ca.sumsqr(w), w[0] ** 2 + w[1], [-np.inf], [3.0], "corner")
    result = solve(nlp, [0.2, 0.9], [0, 0], [1, 1], trust_radius=50.0)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, [1.0, 1.0], atol=1e-9)
    assert len(evaluated) > 1 and all(np.all((0 <= p) & (p <= 1)) for p in evaluated)


def test_a_convex_qp_takes_few_subproblems():
    w = ca.SX.sym("w", 3)  # the projection of (2, 1, 0) onto the half-space w0 + w1 + w2 ≤ 1; multiplier 4/3
    nlp = expressions(w, ca.sumsqr(w - ca.DM([2.0, 1.0, 0.0])), ca.sum1(w), [-np.inf], [1.0], "projection")
    result = solve(nlp, [0, 0, 0], [-10] * 3, [10] * 3, trust_radius=10.0, penalty=10.0)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, [4 / 3, 1 / 3, -2 / 3], atol=1e-6)
    assert result.iterations == 2  # with ρ above the multiplier the first step is exact; the second confirms


def test_damped_bfgs_without_an_exact_hessian():
    nlp = rosenbrock_disk(exact_hessian=False)
    result = SequentialConvex().solve(nlp, nlp.initial_guess(), nlp.parameters(), nlp.bounds())
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, optimum(), atol=1e-4)


def test_multipliers_match_ipopt():
    nlp = rosenbrock_disk()
    args = (nlp, nlp.initial_guess(), nlp.parameters(), nlp.bounds())
    ours, theirs = SequentialConvex(tol=1e-8).solve(*args), Ipopt(tol=1e-10).solve(*args)
    assert ours.status == SolverStatus.CONVERGED, ours.message
    np.testing.assert_allclose(ours.lam_g, theirs.lam_g, rtol=1e-3)


def test_a_qp_solver_failure_is_a_failed_status():
    nlp = rosenbrock_disk()
    result = SequentialConvex(qp_solver="OSQP", max_iter=1).solve(nlp, nlp.initial_guess(), nlp.parameters(),
                                                                   nlp.bounds())
    assert result.status == SolverStatus.FAILED and "OSQP" in result.message


def test_an_evaluation_error_is_a_failed_status():
    nlp = rosenbrock_disk()
    result = SequentialConvex().solve(nlp, np.zeros(5), nlp.parameters(), nlp.bounds())  # a guess too long
    assert result.status == SolverStatus.FAILED and "ValueError" in result.message


@pytest.mark.slow
def test_scp_verifies_case2_at_the_ipopt_time():
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    plan = ocpkit.plan(problem, knots=12, solver="scp")
    reference = ocpkit.plan(problem, knots=12, solver="ipopt")
    print(f"scp: {plan.status} t_f={plan.trajectory.tf:.5f} in {plan.stats.solve_time:.1f} s, "
          f"{plan.stats.iterations} QPs; ipopt: t_f={reference.trajectory.tf:.5f}")
    assert plan.status == "verified", plan.stats.solver_message
    assert abs(plan.trajectory.tf - reference.trajectory.tf) <= 0.01 * reference.trajectory.tf
