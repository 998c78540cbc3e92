"""The `pyomo` solver (ripopt on the NLP translated to Pyomo): its multipliers, what it cannot translate, and
a paper case planned to the same t_f as IPOPT (the generic solver tests are in test_solvers.py)."""

from __future__ import annotations

from dataclasses import replace

import casadi as ca
import numpy as np
import pytest
from helpers import REPO, discretize
from toy_nlps import (
    BOUNDS,
    DISK,
    GUESS,
    PARAMS,
    decision_vector,
    rosenbrock_disk,
    toy_nlp,
)

import ocpkit
from ocpkit.errors import OptionError
from ocpkit.nlp import Layout
from ocpkit.solvers.base import SolverStatus
from ocpkit.solvers.casadi_nlpsol import Ipopt
from ocpkit.solvers.pyomo_nlp import PyomoRipopt, _Dag


def test_constraint_multipliers_match_ipopt_in_sign_and_size():
    nlp = rosenbrock_disk()
    reference = Ipopt(tol=1e-10).prepare(nlp).solve(GUESS, PARAMS, BOUNDS)
    result = PyomoRipopt(tol=1e-10).prepare(nlp).solve(GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.CONVERGED, result.message
    assert reference.lam_g[0] > 0  # the active upper bound of the disk
    np.testing.assert_allclose(result.lam_g, reference.lam_g, rtol=1e-6)


def test_shared_nodes_are_lifted_above_the_tree_size_and_named_below():
    w = ca.SX.sym("w", 2)
    shared = ca.sin(w[0])  # used twice; its tree has 2 nodes (sin, w0)
    dag = _Dag.of(ca.Function("f", [w], [shared * w[1] + shared]))
    node = dag.ops.index(ca.OP_SIN)
    assert dag.shared_nodes(lift_above=1) == ([node], [])
    assert dag.shared_nodes(lift_above=2) == ([], [node])


@pytest.mark.parametrize("lift_above", [0.0, np.inf])
def test_lifting_shared_subexpressions_leaves_the_solution(lift_above):
    variables, w = decision_vector(3)
    parameters = Layout("p")
    p = parameters.add("p", 2)
    shared = w[0] ** 2  # used by f and g: lifted to a variable with lift_above 0, a named expression with ∞
    f = (p[0] - w[0]) ** 2 + 100 * (w[1] - shared) ** 2 + (w[2] - 1) ** 2
    g = ca.vertcat(shared + w[1] ** 2, w[0] + w[1] - p[1])
    nlp = toy_nlp(variables, f, g, [-np.inf, 0.0], [DISK, 0.0], parameters)
    result = PyomoRipopt(lift_above=lift_above).solve(nlp, GUESS, PARAMS, BOUNDS)
    reference = Ipopt().solve(nlp, GUESS, PARAMS, BOUNDS)
    assert result.status == SolverStatus.CONVERGED, result.message
    np.testing.assert_allclose(result.w, reference.w, atol=1e-6)


def test_an_mx_nlp_is_refused():
    nlp = replace(rosenbrock_disk(), x=ca.MX.sym("w", 3))  # as from a dynamics backend evaluated by a callback
    with pytest.raises(OptionError, match="evaluates through a callback"):
        PyomoRipopt().prepare(nlp)


@pytest.mark.parametrize("dynamics", ["pinocchio", "pinocchio-rnea"])
def test_an_nlp_around_a_callback_is_refused(dynamics):
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    nlp = discretize(problem, "chebyshev", dynamics, knots=6).nlp
    assert isinstance(nlp.x, ca.MX) and not nlp.exact_hessian
    with pytest.raises(OptionError, match="evaluates through a callback"):
        PyomoRipopt().prepare(nlp)


def test_an_operation_without_translation_is_named():
    nlp = rosenbrock_disk()
    nlp = replace(nlp, f=nlp.f + ca.atan2(nlp.x[0], nlp.x[1]))
    with pytest.raises(OptionError, match="OP_ATAN2"):
        PyomoRipopt().prepare(nlp)


@pytest.mark.slow
def test_plans_case_2_like_ipopt():
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    plan = ocpkit.plan(problem, knots=12, solver="pyomo")
    reference = ocpkit.plan(problem, knots=12, solver="ipopt")
    assert plan.status == "verified", plan.stats.solver_message
    assert plan.trajectory.tf == pytest.approx(reference.trajectory.tf, rel=0.01)
