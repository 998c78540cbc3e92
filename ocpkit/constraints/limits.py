"""Actuator limits, eq. (6) of the paper: position, velocity, torque and torque-rate bounds."""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.constraints.base import PointValues
from ocpkit.problem import Problem
from ocpkit.robots import Robot


class _RobotLimit:
    """Shared parts of the limit constraints: the robot's limits, velocity, torque and torque rate scaled by
    `scale` (a CasADi expression ≤ 1 that a refinement round may lower; no parameters of their own)."""

    name = ""
    enforced_by_knot_bounds = False
    parameters = ca.SX(0, 1)

    def __init__(self, robot: Robot, scale: ca.SX) -> None:
        self.robot, self.scale = robot, scale

    def parameter_values(self, problem: Problem) -> np.ndarray:
        return np.zeros(0)


class StateLimits(_RobotLimit):
    """q_min ≤ q ≤ q_max and |qd| ≤ qd_max (qd scaled by qd_max); simple variable bounds at knots."""

    name = "state_limits"
    enforced_by_knot_bounds = True

    def evaluate(self, point: PointValues) -> tuple[ca.SX, np.ndarray, np.ndarray]:
        r = self.robot
        ones = np.ones(r.n)
        return (ca.vertcat(point.q, point.qd / ca.DM(r.qd_max) / self.scale), np.concatenate([r.q_lower, -ones]),
                np.concatenate([r.q_upper, ones]))


class TorqueLimit(_RobotLimit):
    """|tau| ≤ tau_max (scaled by tau_max, g dimensionless)."""

    name = "torque"

    def evaluate(self, point: PointValues) -> tuple[ca.SX, np.ndarray, np.ndarray]:
        return point.tau / ca.DM(self.robot.tau_max) / self.scale, -np.ones(self.robot.n), np.ones(self.robot.n)


class TorqueRateLimit(_RobotLimit):
    """|dtau/dt| ≤ taud_max, written as |dtau_ds / taud_max| ≤ dt_ds so t_f never divides."""

    name = "torque_rate"

    def evaluate(self, point: PointValues) -> tuple[ca.SX, np.ndarray, np.ndarray]:
        rate, limit = point.dtau_ds / ca.DM(self.robot.taud_max), point.dt_ds * self.scale
        n = self.robot.n
        return (ca.vertcat(rate - limit, rate + limit),
                np.concatenate([np.full(n, -np.inf), np.zeros(n)]), np.concatenate([np.zeros(n), np.full(n, np.inf)]))
