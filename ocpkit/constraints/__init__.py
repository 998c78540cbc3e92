"""Path constraints as plug-ins (registry `CONSTRAINTS`, entry-point group `ocpkit.constraints`):
`state-limits`, `torque`, `torque-rate` (limits.py) and `collision` (collision.py)."""

from ocpkit.constraints.base import (CONSTRAINTS, DEFAULT_CONSTRAINTS, Constraint, Context, PointValues, Rows,
                                     make_constraints)

__all__ = ["CONSTRAINTS", "DEFAULT_CONSTRAINTS", "Constraint", "Context", "PointValues", "Rows", "make_constraints"]
