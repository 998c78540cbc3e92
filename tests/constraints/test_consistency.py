"""The dynamics-consistency constraint: its rows against pinocchio's RNEA, imposed at the check points only, and
a plan it turns from failing the dense dynamics check into a verified one."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
from helpers import REPO

import ocpkit
from ocpkit.constraints import DEFAULT_CONSTRAINTS, Context, PointValues
from ocpkit.constraints.consistency import CONSISTENCY_BOUND, DynamicsConsistency
from ocpkit.dynamics import make_dynamics
from ocpkit.tolerances import DYNAMICS_TOLERANCE

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
ROBOT = PROBLEM.robot
N = ROBOT.n


def test_rows_are_the_torque_mismatch_over_twice_the_limit_against_pinocchio():
    point = PointValues(*(ca.SX.sym(k, N) for k in ("q", "qd", "qdd", "tau", "dtau_ds")), ca.SX.sym("dt_ds"))
    context = Context(make_dynamics("casadi", ROBOT), ca.SX.sym("margin"), ca.SX.sym("scale"), {})
    rows = DynamicsConsistency(PROBLEM).evaluate(point, context)
    function = ca.Function("rows", [point.q, point.qd, point.qdd, point.tau], [rows.g])
    rng, data = np.random.default_rng(3), ROBOT.model.createData()
    for _ in range(5):
        q, qd, qdd = rng.uniform(-1, 1, N), rng.uniform(-2, 2, N), rng.uniform(-5, 5, N)
        tau = rng.uniform(-1, 1, N) * ROBOT.tau_max
        needed = pin.rnea(ROBOT.model, data, q, qd, qdd) + ROBOT.friction(qd)
        np.testing.assert_allclose(np.asarray(function(q, qd, qdd, tau)).ravel(),
                                   (tau - needed) / (2 * ROBOT.tau_max), rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(rows.upper, np.full(N, CONSISTENCY_BOUND))
    np.testing.assert_array_equal(rows.lower, -rows.upper)
    assert 0 < CONSISTENCY_BOUND < DYNAMICS_TOLERANCE


def test_it_adds_rows_at_the_check_points_only():
    plain = ocpkit.build(PROBLEM, knots=8).discretization
    checked = ocpkit.build(PROBLEM, knots=8, constraints=(*DEFAULT_CONSTRAINTS, "dynamics-consistency")).discretization
    checks = len(checked.check_sigma) + checked.nlp.parameters.index("adaptive_rows").shape[0]
    assert checked.nlp.g.numel() - plain.nlp.g.numel() == N * checks  # none at the 9 knots: the defect holds there


def test_it_turns_a_plan_that_fails_dynamics_between_knots_into_a_verified_one():
    """Paper case 3 at 6 knots: consistent at the knots only, the default plan fails the dense dynamics check."""
    case3 = ocpkit.load_scenario(REPO / "scenarios/paper/case3.yaml")
    plain = ocpkit.plan(case3, knots=6, fallbacks=())
    checked = ocpkit.plan(case3, knots=6, fallbacks=(), constraints=(*DEFAULT_CONSTRAINTS, "dynamics-consistency"))
    residual = [next(c for c in plan.verification.checks if c.name == "dynamics").worst for plan in (plain, checked)]
    assert plain.status == "violated" and residual[0] > DYNAMICS_TOLERANCE
    assert checked.status == "verified" and residual[1] < 0.6 * DYNAMICS_TOLERANCE
