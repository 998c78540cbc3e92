"""Path constraints as plug-ins (registry `CONSTRAINTS`, entry-point group `ocpkit.constraints`):
`state-limits`, `torque`, `torque-rate` (limits.py), `collision` (collision.py) and `dynamics-consistency`
(consistency.py: not a default, added by choice)."""

from ocpkit.constraints.base import (CONSTRAINTS, DEFAULT_CONSTRAINTS, Constraint, Context, PointValues, Rows,
                                     make_constraints)

__all__ = ["CONSTRAINTS", "DEFAULT_CONSTRAINTS", "Constraint", "Context", "PointValues", "Rows", "make_constraints"]
