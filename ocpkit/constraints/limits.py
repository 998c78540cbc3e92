"""Actuator limits, eq. (6) of the paper: position, velocity, torque and torque-rate bounds.

Velocity, torque and torque rate are scaled by the shared `limit_scale` parameter (≤ 1), which a refinement
round may lower; rows are dimensionless (value / limit)."""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.constraints.base import Constraint, Context, PointValues, Rows


class StateLimits(Constraint):
    """q_min ≤ q ≤ q_max and |q̇| ≤ q̇_max: the bounds of the knot variables, rows at check points."""

    name = "state-limits"
    at_knots = "bounds"

    def variable_bounds(self, limit_scale: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        r = self.robot
        return {"q": (r.q_lower, r.q_upper), "qd": (-r.qd_max * limit_scale, r.qd_max * limit_scale)}

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        r, ones = self.robot, np.ones(self.robot.n)
        return Rows(ca.vertcat(point.q, point.qd / ca.DM(r.qd_max) / context.limit_scale),
                    np.concatenate([r.q_lower, -ones]), np.concatenate([r.q_upper, ones]))


class TorqueLimit(Constraint):
    """|τ| ≤ τ_max."""

    name = "torque"

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        ones = np.ones(self.robot.n)
        return Rows(point.tau / ca.DM(self.robot.tau_max) / context.limit_scale, -ones, ones)


class TorqueRateLimit(Constraint):
    """|dτ/dt| ≤ τ̇_max, written as |dτ/ds / τ̇_max| ≤ dt/ds so t_f never divides (one-sided rows)."""

    name = "torque-rate"
    reads_rate = True

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        rate, limit = point.dtau_ds / ca.DM(self.robot.taud_max), point.dt_ds * context.limit_scale
        n = self.robot.n
        return Rows(ca.vertcat(rate - limit, rate + limit), np.concatenate([np.full(n, -np.inf), np.zeros(n)]),
                    np.concatenate([np.zeros(n), np.full(n, np.inf)]))
