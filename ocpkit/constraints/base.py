"""The Constraint interface: path constraints evaluated at one time point, blind to the transcription.

The transcription supplies the symbolic values at a point (knot or extra check time) in its own way;
a constraint turns them into `g` with numeric bounds `lower ≤ g ≤ upper`. Scene data that changes
between queries of the same shape (obstacle positions, workspace box) enters through CasADi parameters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import casadi as ca
import numpy as np

from ocpkit.problem import Problem


@dataclass(frozen=True)
class PointValues:
    """Symbolic values at one time point: q, qd, qdd, tau are (n, 1) in rad, rad/s, rad/s², N m.

    Time derivatives of tau are given on the transcription's normalized time s as `dtau_ds` (N m) with
    `dt_ds` (s), so a rate bound |dtau/dt| ≤ r reads |dtau_ds| ≤ dt_ds · r and t_f never divides.
    """

    q: ca.SX
    qd: ca.SX
    qdd: ca.SX
    tau: ca.SX
    dtau_ds: ca.SX
    dt_ds: ca.SX


class Constraint(Protocol):
    """A path constraint lower ≤ g(point; p) ≤ upper."""

    name: str
    enforced_by_knot_bounds: bool  # True if a transcription's variable bounds at knots already imply it

    @property
    def parameters(self) -> ca.SX:
        """Parameter symbols (column) this constraint reads; empty if none."""

    def parameter_values(self, problem: Problem) -> np.ndarray:
        """Numeric values for `parameters` taken from a problem of the same shape."""

    def evaluate(self, point: PointValues) -> tuple[ca.SX, np.ndarray, np.ndarray]:
        """(g, lower, upper) at one point; g is a column, the bounds numeric arrays of its length."""
