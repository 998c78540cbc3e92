"""The Dynamics interface: symbolic robot dynamics and sphere kinematics on CasADi expressions.

Backends differ in how they compute, never in what they return. Shapes: q, qd, qdd, tau are (n, 1)
CasADi column expressions in rad, rad/s, rad/s², N m; sphere centres are (M, 3) in metres.
"""

from __future__ import annotations

from typing import Protocol

import casadi as ca

from ocpkit.registry import Registry
from ocpkit.robots import Robot


class Dynamics(Protocol):
    """Symbolic dynamics of one robot, friction included."""

    name: str
    robot: Robot

    def friction(self, qd: ca.SX) -> ca.SX:
        """Joint friction torque (n, 1)."""

    def forward(self, q: ca.SX, qd: ca.SX, tau: ca.SX) -> ca.SX:
        """Joint acceleration qdd (n, 1) produced by joint torque tau (friction included)."""

    def inverse(self, q: ca.SX, qd: ca.SX, qdd: ca.SX) -> ca.SX:
        """Joint torque tau (n, 1) needed for acceleration qdd (friction included)."""

    def residual(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, tau_rigid: ca.SX) -> ca.SX:
        """Dynamic defect (n, 1), zero exactly when the rigid-body torque tau_rigid = tau − friction(qd)
        produces qdd, scaled to order one; each backend picks its own form (e.g. qdd − ABA(q, qd, tau_rigid)
        or (RNEA(q, qd, qdd) − tau_rigid) / tau_max)."""

    def sphere_centers(self, q: ca.SX) -> ca.SX:
        """World positions (M, 3) of the robot's collision spheres."""

    def lift(self, fields: dict) -> dict:
        """The finished NLP's fields (x, p, f, g, lbg, ubg, shape_key) as the solver should get them: unchanged
        for symbolic backends; a backend that cannot live in an SX graph (a callback) rewrites them in MX
        and sets exact_hessian=False."""


DYNAMICS: Registry[type] = Registry("dynamics backend", "ocpkit.dynamics")


def make_dynamics(name: str, robot: Robot) -> Dynamics:
    """Instantiate the dynamics backend called `name` for `robot`."""
    return DYNAMICS.get(name)(robot)
