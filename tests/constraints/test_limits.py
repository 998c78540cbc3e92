"""Limit constraints (state-limits, torque, torque-rate) and the constraint plug-in machinery: rows evaluated on
symbolic PointValues, substituted with numbers, against the closed forms of the limits."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.constraints import (CONSTRAINTS, DEFAULT_CONSTRAINTS, Constraint, Context, PointValues, Rows,
                                make_constraints)
from ocpkit.constraints.limits import StateLimits, TorqueLimit, TorqueRateLimit
from ocpkit.dynamics import make_dynamics
from ocpkit.errors import RegistryError

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
ROBOT = PROBLEM.robot
N = ROBOT.n
RNG = np.random.default_rng(7)


def evaluate(constraint: Constraint, values: dict, margin: float = 0.0, limit_scale: float = 1.0,
             parameters: dict | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(g, lower, upper) of `constraint` at the numeric point `values` (q, qd, qdd, tau, dtau_ds (n,), dt_ds),
    evaluated symbolically and then substituted through a ca.Function."""
    point = PointValues(*(ca.SX.sym(k, N) for k in ("q", "qd", "qdd", "tau", "dtau_ds")), ca.SX.sym("dt_ds"))
    shapes = constraint.parameter_shapes()
    symbols = {name: ca.SX.sym(name, *shape) for name, shape in shapes.items()}
    margin_sx, scale_sx = ca.SX.sym("margin"), ca.SX.sym("limit_scale")
    rows = constraint.evaluate(point, Context(make_dynamics("casadi", ROBOT), margin_sx, scale_sx, symbols))
    assert isinstance(rows, Rows) and rows.g.shape[1] == 1
    inputs = [point.q, point.qd, point.qdd, point.tau, point.dtau_ds, point.dt_ds, margin_sx, scale_sx,
              *symbols.values()]
    function = ca.Function("rows", inputs, [rows.g])
    given = parameters or {}
    numbers = [values.get(k, np.zeros(N)) for k in ("q", "qd", "qdd", "tau", "dtau_ds")]
    g = function(*numbers, values.get("dt_ds", 1.0), margin, limit_scale,
                 *(np.reshape(given[name], shapes[name]) for name in symbols))
    assert rows.lower.shape == rows.upper.shape == (rows.g.numel(),)
    return np.asarray(g).ravel(), rows.lower, rows.upper


def test_torque_rows_are_torque_over_scaled_limit_within_unit_bounds():
    tau = RNG.uniform(-1.5, 1.5, N) * ROBOT.tau_max
    g, lower, upper = evaluate(TorqueLimit(PROBLEM), {"tau": tau}, limit_scale=0.8)
    np.testing.assert_allclose(g, tau / ROBOT.tau_max / 0.8, rtol=1e-12)
    np.testing.assert_array_equal(lower, -np.ones(N))
    np.testing.assert_array_equal(upper, np.ones(N))


def test_torque_exactly_at_the_scaled_limit_gives_a_row_of_one():
    g, _, _ = evaluate(TorqueLimit(PROBLEM), {"tau": -0.9 * ROBOT.tau_max}, limit_scale=0.9)
    np.testing.assert_allclose(g, -np.ones(N), rtol=1e-12)


def test_torque_rate_rows_are_one_sided_and_zero_at_the_limit():
    dt_ds, scale = 0.4, 0.95
    at_limit = dt_ds * scale * ROBOT.taud_max  # dtau/dt = dtau_ds / dt_ds = scale · taud_max
    g, lower, upper = evaluate(TorqueRateLimit(PROBLEM), {"dtau_ds": at_limit, "dt_ds": dt_ds}, limit_scale=scale)
    assert g.shape == (2 * N,)
    np.testing.assert_allclose(g[:N], 0.0, atol=1e-12)  # rate − limit: on its upper bound
    np.testing.assert_allclose(g[N:], 2 * dt_ds * scale, rtol=1e-12)  # rate + limit: far from its lower bound
    np.testing.assert_array_equal(lower, np.concatenate([np.full(N, -np.inf), np.zeros(N)]))
    np.testing.assert_array_equal(upper, np.concatenate([np.zeros(N), np.full(N, np.inf)]))
    g, _, _ = evaluate(TorqueRateLimit(PROBLEM), {"dtau_ds": -at_limit, "dt_ds": dt_ds}, limit_scale=scale)
    np.testing.assert_allclose(g[N:], 0.0, atol=1e-12)


def test_torque_rate_rows_match_the_closed_form():
    dtau_ds, dt_ds, scale = RNG.uniform(-2, 2, N) * ROBOT.taud_max, 0.7, 0.6
    g, lower, upper = evaluate(TorqueRateLimit(PROBLEM), {"dtau_ds": dtau_ds, "dt_ds": dt_ds}, limit_scale=scale)
    rate = dtau_ds / ROBOT.taud_max
    np.testing.assert_allclose(g, np.concatenate([rate - dt_ds * scale, rate + dt_ds * scale]), rtol=1e-12)
    inside = (g >= lower) & (g <= upper)
    within = np.abs(dtau_ds / dt_ds) <= scale * ROBOT.taud_max  # |dtau/dt| ≤ scaled limit
    np.testing.assert_array_equal(inside[:N] & inside[N:], within)
    assert TorqueRateLimit.reads_rate and not TorqueLimit.reads_rate


def test_state_limit_variable_bounds_scale_the_velocity_only():
    bounds = StateLimits(PROBLEM).variable_bounds(0.5)
    assert set(bounds) == {"q", "qd"}
    np.testing.assert_array_equal(bounds["q"][0], ROBOT.q_lower)
    np.testing.assert_array_equal(bounds["q"][1], ROBOT.q_upper)
    np.testing.assert_allclose(bounds["qd"][0], -0.5 * ROBOT.qd_max)
    np.testing.assert_allclose(bounds["qd"][1], 0.5 * ROBOT.qd_max)
    assert StateLimits.at_knots == "bounds" and TorqueLimit.at_knots == "rows"


def test_state_limit_rows_are_position_and_scaled_velocity():
    q = RNG.uniform(ROBOT.q_lower, ROBOT.q_upper)
    qd = RNG.uniform(-1, 1, N) * ROBOT.qd_max
    g, lower, upper = evaluate(StateLimits(PROBLEM), {"q": q, "qd": qd}, limit_scale=0.75)
    np.testing.assert_allclose(g, np.concatenate([q, qd / ROBOT.qd_max / 0.75]), rtol=1e-12)
    np.testing.assert_array_equal(lower, np.concatenate([ROBOT.q_lower, -np.ones(N)]))
    np.testing.assert_array_equal(upper, np.concatenate([ROBOT.q_upper, np.ones(N)]))


def test_limit_constraints_read_no_parameters_and_have_no_shape():
    for kind in (StateLimits, TorqueLimit, TorqueRateLimit):
        made = kind(PROBLEM)
        assert made.parameter_shapes() == {} and made.parameter_values(PROBLEM) == {} and made.shape() == ()


def test_registry_holds_the_four_paper_constraints_as_defaults_and_the_dynamics_consistency():
    assert CONSTRAINTS.names() == sorted(["state-limits", "torque", "torque-rate", "collision", "dynamics-consistency"])
    assert DEFAULT_CONSTRAINTS == ("state-limits", "torque", "torque-rate", "collision")
    assert [c.name for c in make_constraints(PROBLEM)] == list(DEFAULT_CONSTRAINTS)
    assert CONSTRAINTS.get("torque") is TorqueLimit


def test_a_repeated_constraint_is_a_registry_error_naming_it():
    with pytest.raises(RegistryError, match="torque") as error:
        make_constraints(PROBLEM, ["torque", "state-limits", TorqueLimit])
    assert "state-limits" not in str(error.value)


def test_an_unknown_constraint_name_is_a_registry_error_listing_the_known():
    with pytest.raises(RegistryError, match="collision"):
        make_constraints(PROBLEM, ["no-such-constraint"])


JOINT_ONE_FRACTION = 0.3


class JointOneSlow(Constraint):
    """Third-party constraint: |q̇_1| ≤ 0.3 q̇_1,max."""

    name = "joint-1-slow"

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        bound = JOINT_ONE_FRACTION * self.robot.qd_max[0]
        return Rows(point.qd[0] / bound, -np.ones(1), np.ones(1))


def test_a_constraint_class_can_be_passed_to_make_constraints():
    made = make_constraints(PROBLEM, ["torque", JointOneSlow])
    assert [type(c) for c in made] == [TorqueLimit, JointOneSlow]
    g, lower, upper = evaluate(made[1], {"qd": np.full(N, JOINT_ONE_FRACTION * ROBOT.qd_max[0])})
    np.testing.assert_allclose(g, [1.0])
    np.testing.assert_array_equal(lower, [-1.0])
    np.testing.assert_array_equal(upper, [1.0])


def test_a_third_party_constraint_adds_rows_to_the_built_nlp():
    plain = ocpkit.build(PROBLEM, knots=6)
    extra = ocpkit.build(PROBLEM, knots=6, constraints=DEFAULT_CONSTRAINTS + (JointOneSlow,))
    assert extra.discretization is not plain.discretization
    assert [c.name for c in extra.discretization.constraints] == [*DEFAULT_CONSTRAINTS, "joint-1-slow"]
    added = extra.discretization.nlp.g.numel() - plain.discretization.nlp.g.numel()
    assert added >= 5  # at least one row at each of the 5 knots


@pytest.mark.slow
def test_a_plan_with_a_third_party_constraint_respects_it():
    result = ocpkit.plan(PROBLEM, knots=8, constraints=DEFAULT_CONSTRAINTS + (JointOneSlow,))
    assert result.ok, result.verification.summary()
    bound = JOINT_ONE_FRACTION * ROBOT.qd_max[0]
    assert result.trajectory.tf >= abs(PROBLEM.goal[0] - PROBLEM.start[0]) / bound
    assert np.abs(result.trajectory.knots.qd[:, 0]).max() <= bound * (1 + 1e-6)
    assert np.abs(result.trajectory.sample().qd[:, 0]).max() <= bound * 1.02  # between checks: small overshoot
