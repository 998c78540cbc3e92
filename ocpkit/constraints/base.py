"""The Constraint interface: path constraints at one time point, blind to the transcription.

A constraint is a plug-in (registry `CONSTRAINTS`, entry-point group `ocpkit.constraints`). It is made for one
problem (numeric set-up only, e.g. which collision terms can ever be active: that is its `shape`), names the
NLP parameters it reads, and turns the symbolic values at a point into rows lower ≤ g ≤ upper. Two class
attributes say how a transcription imposes it:

  at_knots    "rows": rows at every point;  "bounds": at the knots it is the bounds `variable_bounds` gives
              on the knot variables (rows only at check points between knots)
  reads_rate  it reads dτ/ds, which has a kink at a knot (the slopes on either side differ), so it is
              imposed once per one-sided slope there

Scene data that changes between queries of the same shape (obstacle positions, the workspace box) enters
through the constraint's parameters; the clearance margin and the limit scale a refinement round changes are
shared parameters (`Context`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar, NamedTuple

import casadi as ca
import numpy as np

from ocpkit.dynamics.base import Dynamics
from ocpkit.errors import RegistryError
from ocpkit.problem import Problem
from ocpkit.registry import Registry


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


@dataclass(frozen=True)
class Context:
    """What a constraint reads beyond the point: the dynamics backend (for kinematics), the shared NLP
    parameters `margin` (m, added to every clearance) and `limit_scale` (fraction of the velocity, torque and
    torque-rate limits in use), and its own parameter symbols by the names it declared."""

    dynamics: Dynamics
    margin: ca.SX
    limit_scale: ca.SX
    parameters: dict[str, ca.SX]


class Rows(NamedTuple):
    """Constraint rows lower ≤ g ≤ upper: g a column (m, 1), the bounds numeric arrays (m,)."""

    g: ca.SX
    lower: np.ndarray
    upper: np.ndarray


class Constraint(ABC):
    """A path constraint lower ≤ g(point; p) ≤ upper for the problem it was made for (module docstring)."""

    name: ClassVar[str]
    at_knots: ClassVar[str] = "rows"
    reads_rate: ClassVar[bool] = False

    def __init__(self, problem: Problem) -> None:
        self.robot = problem.robot

    def shape(self) -> tuple:
        """Hashable: what of the problem, besides the robot, fixes this constraint's rows."""
        return ()

    def parameter_shapes(self) -> dict[str, tuple[int, int]]:
        """Name → (rows, columns) of each NLP parameter this constraint reads; none by default."""
        return {}

    def parameter_values(self, problem: Problem) -> dict[str, np.ndarray]:
        """Name → value (shaped as declared) of each parameter, for a problem of this constraint's shape."""
        return {}

    def variable_bounds(self, limit_scale: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """For at_knots = "bounds": knot variable name ("q", "qd", ...) → (lower, upper) (n,), with the
        refinement's `limit_scale` applied."""
        return {}

    @property
    def term_count(self) -> int:
        """Rows per point that `screened` may leave out; 0 for a constraint that screens nothing."""
        return 0

    screened_at: float = 0.0
    """The distance (its own unit) `screened` kept its rows within; 0 when it was not screened."""

    def screened(self, problem: Problem, near: np.ndarray, distance: float) -> Constraint:
        """This constraint for `problem` without the rows that stay inactive by more than `distance` (its own unit)
        at every configuration of `near` (K, n) (ocpkit.planner.screening); itself when it has nothing to leave out."""
        return self

    def missing(self, problem: Problem, near: np.ndarray, distance: float) -> int:
        """How many rows `screened` left out are within `distance` of active in `problem` somewhere in `near`."""
        return 0

    @abstractmethod
    def evaluate(self, point: PointValues, context: Context) -> Rows:
        """The rows at one point."""


CONSTRAINTS: Registry[type[Constraint]] = Registry("constraint", "ocpkit.constraints")
DEFAULT_CONSTRAINTS = ("state-limits", "torque", "torque-rate", "collision")
"""The paper's path constraints, eqs. (6)–(8): what every planner imposes unless told otherwise."""


def make_constraints(problem: Problem, kinds: Sequence[str | type[Constraint]] = DEFAULT_CONSTRAINTS,
                     screen: tuple[np.ndarray, float] | None = None) -> list[Constraint]:
    """The constraints `kinds` (registered names or Constraint classes) made for `problem`; with `screen` =
    (near (K, n), distance), each `screened` to the rows that can be active near those configurations."""
    made = [(CONSTRAINTS.get(kind) if isinstance(kind, str) else kind)(problem) for kind in kinds]
    if screen is not None:
        made = [c.screened(problem, *screen) for c in made]
    names = [c.name for c in made]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise RegistryError(f"constraints listed more than once: {', '.join(repeated)}")
    return made
