"""Dynamics backends (registry `DYNAMICS`, entry-point group `ocpkit.dynamics`): `casadi` (ABA, forward form),
`casadi-rnea` (inverse form)."""

from ocpkit.dynamics.base import DYNAMICS, Dynamics, make_dynamics

__all__ = ["DYNAMICS", "Dynamics", "make_dynamics"]
