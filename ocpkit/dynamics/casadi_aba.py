"""Dynamics backends `casadi` (forward form, the paper's) and `casadi-rnea` (inverse form).

Both use our own Featherstone ABA / RNEA in CasADi SX (ocpkit.dynamics.spatial), built from the
robot's pinocchio model parameters, plus the friction law of ocpkit.robots.friction.

Option `cse` (default False): apply `casadi.cse` (common-subexpression elimination) to the symbolic residual
and sphere centres returned; it changes how they are computed, never their values.
"""

from __future__ import annotations

import functools
from typing import Any

import casadi as ca

from ocpkit.dynamics.spatial import SymbolicModel
from ocpkit.errors import OptionError
from ocpkit.robots import Robot, friction_torque


class CasadiAba:
    """The paper's forward form: the defect is qdd − ABA(q, qd, tau_rigid) in rad/s²."""

    name = "casadi"

    def __init__(self, robot: Robot, cse: bool = False) -> None:
        if not isinstance(cse, bool):
            raise OptionError(f"dynamics backend {self.name!r}: option 'cse' must be true or false, got {cse!r}")
        self.robot, self.cse = robot, cse

    @functools.cached_property
    def symbolic(self) -> SymbolicModel:
        """The symbolic model, made on first use (a build cache asks only for `key`)."""
        return SymbolicModel(self.robot.model)

    @property
    def options(self) -> dict[str, Any]:
        """The options this instance was made with."""
        return {"cse": self.cse}

    @property
    def key(self) -> tuple:
        """(name, robot.key, sorted options): equal keys give identical expressions, for build caches."""
        return (self.name, self.robot.key, tuple(sorted(self.options.items())))

    def friction(self, qd: ca.SX) -> ca.SX:
        """Friction torque (n, 1), N m, at qd (n, 1) rad/s."""
        r = self.robot
        return friction_torque(qd, ca.DM(r.viscous), ca.DM(r.coulomb), r.friction_smoothing, ca.tanh)

    def forward(self, q: ca.SX, qd: ca.SX, tau: ca.SX) -> ca.SX:
        """qdd (n, 1) = ABA(q, qd, tau - friction)."""
        return self.symbolic.forward_dynamics(q, qd, tau - self.friction(qd))

    def inverse(self, q: ca.SX, qd: ca.SX, qdd: ca.SX) -> ca.SX:
        """tau (n, 1) = RNEA(q, qd, qdd) + friction."""
        return self.symbolic.inverse_dynamics(q, qd, qdd) + self.friction(qd)

    def residual(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, tau_rigid: ca.SX) -> ca.SX:
        """qdd − ABA(q, qd, tau_rigid), rad/s²."""
        return self._finish(qdd - self.symbolic.forward_dynamics(q, qd, tau_rigid))

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
        return self._finish(ca.vertcat(*rows)) if rows else ca.SX(0, 3)

    def _finish(self, expr: ca.SX) -> ca.SX:
        """expr after common-subexpression elimination if the `cse` option is set."""
        return ca.cse(expr) if self.cse else expr


class CasadiRnea(CasadiAba):
    """Inverse form: the defect is (RNEA(q, qd, qdd) − tau_rigid) / tau_max, dimensionless.

    Same feasible set as the forward form (M(q) is invertible), a cheaper and less nonlinear graph."""

    name = "casadi-rnea"

    def residual(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, tau_rigid: ca.SX) -> ca.SX:
        """(RNEA(q, qd, qdd) − tau_rigid) / tau_max, dimensionless."""
        return self._finish((self.symbolic.inverse_dynamics(q, qd, qdd) - tau_rigid) / ca.DM(self.robot.tau_max))
