"""The Dynamics interface: symbolic robot dynamics and sphere kinematics on CasADi expressions.

Backends differ in how they compute, never in what they return. Shapes: q, qd, qdd, tau are (n, 1)
CasADi column expressions in rad, rad/s, rad/s², N m; sphere centres are (M, 3) in metres.

A backend is a class registered in `DYNAMICS`, instantiated as `Backend(robot, **options)`: its options are
its constructor's keyword parameters after `robot`, each changing how it computes, never what (e.g. `cse`).
"""

from __future__ import annotations

import inspect
from typing import Any, Protocol

import casadi as ca

from ocpkit.errors import OptionError
from ocpkit.registry import Registry
from ocpkit.robots import Robot


class Dynamics(Protocol):
    """Symbolic dynamics of one robot, friction included."""

    name: str
    robot: Robot

    @property
    def options(self) -> dict[str, Any]:
        """The options the instance was made with ({} for a backend without options)."""

    @property
    def key(self) -> tuple:
        """(name, robot.key, sorted options items): hashable, equal exactly when two instances build the same
        expressions, for build caches."""

    def friction(self, qd: ca.SX) -> ca.SX:
        """Joint friction torque (n, 1), N m."""

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
        for symbolic backends; a backend that cannot live in an SX graph (a callback) rewrites them in MX,
        sets exact_hessian=False and forgets what it recorded for this build, so one instance serves several
        builds one after the other."""


DYNAMICS: Registry[type] = Registry("dynamics backend", "ocpkit.dynamics")


def make_dynamics(spec: str | Dynamics, robot: Robot, **options: Any) -> Dynamics:
    """The dynamics backend `spec` for `robot`: a registered name, instantiated with `options`, or an instance
    made for a robot of the same content (robot.key), returned as is. OptionError names an option the backend
    does not take, options given with an instance, or an instance made for another robot."""
    if isinstance(spec, str):
        return _instantiate(spec, robot, options)
    return _checked_instance(spec, robot, options)


def _instantiate(name: str, robot: Robot, options: dict[str, Any]) -> Dynamics:
    backend = DYNAMICS.get(name)
    accepted = list(inspect.signature(backend).parameters)[1:]  # after `robot`
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise OptionError(f"dynamics backend {name!r} has no option {unknown[0]!r}; "
                          f"its options: {', '.join(accepted) or 'none'}")
    return backend(robot, **options)


def _checked_instance(dynamics: Dynamics, robot: Robot, options: dict[str, Any]) -> Dynamics:
    if options:
        raise OptionError(f"options {', '.join(sorted(options))} cannot be applied to the existing dynamics "
                          f"backend instance {dynamics.name!r}; pass its name instead")
    if dynamics.robot.key != robot.key:
        raise OptionError(f"dynamics backend instance {dynamics.name!r} was made for another robot "
                          f"({dynamics.robot.name!r}, key {dynamics.robot.key[:12]}), not for {robot.name!r} "
                          f"(key {robot.key[:12]})")
    return dynamics
