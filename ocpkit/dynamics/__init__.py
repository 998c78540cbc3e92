"""Dynamics backends (registry `DYNAMICS`, entry-point group `ocpkit.dynamics`): `casadi` (ABA, forward form),
`casadi-rnea` (inverse form), both with option `cse`; `pinocchio` and `pinocchio-rnea` (the same forms through a
pinocchio callback, no options). `make_dynamics(name or instance, robot, **options)` gives one."""

from ocpkit.dynamics.base import DYNAMICS, Dynamics, make_dynamics

__all__ = ["DYNAMICS", "Dynamics", "make_dynamics"]
