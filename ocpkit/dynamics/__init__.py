"""Dynamics backends (registry `DYNAMICS`): `casadi` (ABA, forward form), `casadi-rnea` (inverse form)."""

from ocpkit.dynamics import casadi_aba  # noqa: F401  (registers the built-in backends)
from ocpkit.dynamics.base import DYNAMICS, Dynamics, make_dynamics

__all__ = ["DYNAMICS", "Dynamics", "make_dynamics"]
