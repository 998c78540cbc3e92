"""Dynamics backends `casadi` (forward form, the paper's) and `casadi-rnea` (inverse form).

Both use our own Featherstone ABA / RNEA in CasADi SX (ocpkit.dynamics.spatial), built from the
robot's pinocchio model parameters, plus friction tau_f = viscous·qd + coulomb·tanh(qd / smoothing).
"""

from __future__ import annotations

import casadi as ca

from ocpkit.dynamics.spatial import SymbolicModel
from ocpkit.robots import Robot


class CasadiAba:
    """The paper's forward form: the defect is qdd − ABA(q, qd, tau_rigid) in rad/s²."""

    name = "casadi"

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.symbolic = SymbolicModel(robot.model)

    def friction(self, qd: ca.SX) -> ca.SX:
        """Friction torque (n, 1), N m."""
        r = self.robot
        return ca.DM(r.viscous) * qd + ca.DM(r.coulomb) * ca.tanh(qd / r.friction_smoothing)

    def forward(self, q: ca.SX, qd: ca.SX, tau: ca.SX) -> ca.SX:
        """qdd (n, 1) = ABA(q, qd, tau - friction)."""
        return self.symbolic.forward_dynamics(q, qd, tau - self.friction(qd))

    def inverse(self, q: ca.SX, qd: ca.SX, qdd: ca.SX) -> ca.SX:
        """tau (n, 1) = RNEA(q, qd, qdd) + friction."""
        return self.symbolic.inverse_dynamics(q, qd, qdd) + self.friction(qd)

    def residual(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, tau_rigid: ca.SX) -> ca.SX:
        """qdd − ABA(q, qd, tau_rigid), rad/s²."""
        return qdd - self.symbolic.forward_dynamics(q, qd, tau_rigid)

    def lift(self, fields: dict) -> dict:
        """Unchanged: the whole NLP stays in SX."""
        return fields

    def sphere_centers(self, q: ca.SX) -> ca.SX:
        """Sphere centres (M, 3) by forward kinematics, metres."""
        placements = self.symbolic.joint_placements(q)
        rows = []
        for joint, offset in zip(self.robot.sphere_joint, self.robot.sphere_offset):
            rotation, position = placements[joint]
            rows.append(ca.transpose(ca.mtimes(rotation, ca.DM(offset)) + position))
        return ca.vertcat(*rows) if rows else ca.SX(0, 3)


class CasadiRnea(CasadiAba):
    """Inverse form: the defect is (RNEA(q, qd, qdd) − tau_rigid) / tau_max, dimensionless.

    Same feasible set as the forward form (M(q) is invertible), a cheaper and less nonlinear graph."""

    name = "casadi-rnea"

    def residual(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, tau_rigid: ca.SX) -> ca.SX:
        """(RNEA(q, qd, qdd) − tau_rigid) / tau_max, dimensionless."""
        return (self.symbolic.inverse_dynamics(q, qd, qdd) - tau_rigid) / ca.DM(self.robot.tau_max)


