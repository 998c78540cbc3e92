"""Every NLP solver behind the Solver interface: a small constrained NLP with a known optimum converges,
an iteration limit is reported as such, and (slow) each plans a paper case through `ocpkit.plan`."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.errors import OptionError
from ocpkit.solvers.base import SOLVERS, SolverStatus
from ocpkit.transcription.base import NLP

ALL_SOLVERS = {name: SOLVERS.get(name) for name in SOLVERS.names()}


@dataclass
class RosenbrockDisk(NLP):
    """min (p0 - w0)² + 100 (w1 - w0²)² + (w2 - 1)² s.t. w0² + w1² ≤ 1.532 and w0 + w1 = p1, with w2
    fixed to 3 by its bounds; p = (1, 1.75). Both constraints are active at the optimum."""

    def bounds(self, problem=None, refinement=None):
        return np.array([-5.0, -5.0, 3.0]), np.array([5.0, 5.0, 3.0])

    def parameters(self, problem=None, refinement=None):
        return np.array([1.0, 1.75])

    def initial_guess(self, problem=None):
        return np.array([-1.0, 2.0, 3.0])

    def decode(self, w):
        raise NotImplementedError

    def encode(self, trajectory):
        raise NotImplementedError


def rosenbrock_disk(exact_hessian: bool = True) -> RosenbrockDisk:
    w, p = ca.SX.sym("w", 3), ca.SX.sym("p", 2)
    f = (p[0] - w[0]) ** 2 + 100 * (w[1] - w[0] ** 2) ** 2 + (w[2] - 1) ** 2
    g = ca.vertcat(w[0] ** 2 + w[1] ** 2, w[0] + w[1] - p[1])
    return RosenbrockDisk(w, p, f, g, np.array([-np.inf, 0.0]), np.array([1.532, 0.0]), ("rosenbrock-disk",),
                          exact_hessian)


def optimum() -> np.ndarray:
    """On the line w1 = 1.75 - w0 the disk leaves |w0 - 0.875| ≤ √((1.532 - 1.53125) / 2); the cost falls
    towards the unconstrained line optimum w0 ≈ 0.914, so w0 sits on the disk's upper end."""
    w0 = np.linspace(0.875, 0.875 + np.sqrt((1.532 - 1.53125) / 2), 1_000_001)
    cost = (1 - w0) ** 2 + 100 * (1.75 - w0 - w0 ** 2) ** 2
    best = w0[np.argmin(cost)]
    return np.array([best, 1.75 - best, 3.0])


@pytest.mark.parametrize("name", ALL_SOLVERS)
def test_small_nlp_converges_to_the_known_optimum(name):
    nlp = rosenbrock_disk()
    result = ALL_SOLVERS[name]().solve(nlp, nlp.initial_guess(), nlp.parameters(), nlp.bounds())
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, optimum(), atol=1e-4)


@pytest.mark.parametrize("name", ["ipopt", "sqpmethod", "scipy-trust-constr"])
def test_quasi_newton_when_the_nlp_has_no_exact_hessian(name):
    nlp = rosenbrock_disk(exact_hessian=False)
    result = ALL_SOLVERS[name]().solve(nlp, nlp.initial_guess(), nlp.parameters(), nlp.bounds())
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, optimum(), atol=1e-4)


@pytest.mark.parametrize("name", ALL_SOLVERS)
def test_iteration_limit_is_reported(name):
    nlp = rosenbrock_disk()
    result = ALL_SOLVERS[name](max_iterations=2).solve(nlp, nlp.initial_guess(), nlp.parameters(), nlp.bounds())
    assert result.status == SolverStatus.ITERATION_LIMIT, result.message


@pytest.mark.parametrize("name", ["ipopt", "sqpmethod", "scipy-slsqp", "scipy-trust-constr", "pyomo", "scp"])
def test_time_limit_is_reported(name):  # blocksqp and fatrop cannot be interrupted
    nlp = rosenbrock_disk()
    result = ALL_SOLVERS[name](max_wall_time=1e-9).solve(nlp, nlp.initial_guess(), nlp.parameters(), nlp.bounds())
    assert result.status == SolverStatus.TIME_LIMIT, result.message


@pytest.mark.parametrize("name", ["sqpmethod", "fatrop"])
def test_casadi_errors_become_a_failed_status(name):
    nlp = rosenbrock_disk()
    result = ALL_SOLVERS[name]().solve(nlp, np.zeros(5), nlp.parameters(), nlp.bounds())  # a guess too long
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


@pytest.mark.slow
@pytest.mark.parametrize("name", [name for name in ALL_SOLVERS if name != "ipopt"])
def test_solver_plans_a_paper_case(name):
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    plan = ocpkit.plan(problem, knots=8, solver=name, solver_options={"max_wall_time": 15.0})
    print(f"{name}: {plan.status} t_f={plan.trajectory.tf:.4f} iterations={plan.stats.iterations}")
    assert plan.status in {"verified", "violated", "iteration_limit", "time_limit", "failed", "infeasible"}
    if name in VERIFIES:
        assert plan.status == "verified", plan.stats.solver_message
