"""Dynamics consistency between knots: the torque the plan commands stays within CONSISTENCY_BOUND of the torque
its motion needs, at the check points.

At a collocation point the transcription's defect makes τ = rnea(q, q̇, q̈) + friction(q̇) exactly; between them
τ and the motion are two interpolants that may drift apart, and `verify` fails a plan whose
|τ − rnea − friction| / (2 τ_max) exceeds its DYNAMICS_TOLERANCE anywhere. This constraint bounds that same
quantity at the check points, so a solve cannot end on a motion whose torque is consistent only at the knots. At the
knots it is the defect itself (`at_knots` "bounds" with no bounds of its own: no rows there).

Not a default: its rows hold the inverse dynamics at every check point, which makes every IPOPT iteration dearer
(figures: docs/design-notes.md). Add it to a plan's constraints when coarse knots leave a residual:
`ocpkit.plan(problem, constraints=(*DEFAULT_CONSTRAINTS, "dynamics-consistency"))`.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.constraints.base import Constraint, Context, PointValues, Rows
from ocpkit.tolerances import DYNAMICS_TOLERANCE

CONSISTENCY_BOUND = DYNAMICS_TOLERANCE / 2
"""|τ − rnea − friction| / (2 τ_max) at a check point: half the verification's tolerance, room for the
interpolants between check points."""


class DynamicsConsistency(Constraint):
    """Dynamics between knots: |τ − rnea − friction| / (2 τ_max) ≤ CONSISTENCY_BOUND at check points.

    rnea(q, q̇, q̈) + friction(q̇) is the torque the motion needs; the bound is dimensionless (module docstring)."""

    name = "dynamics-consistency"
    at_knots = "bounds"

    def evaluate(self, point: PointValues, context: Context) -> Rows:
        needed = context.dynamics.inverse(point.q, point.qd, point.qdd)
        rows = (point.tau - needed) / ca.DM(2.0 * self.robot.tau_max)
        bound = np.full(self.robot.n, CONSISTENCY_BOUND)
        return Rows(rows, -bound, bound)
