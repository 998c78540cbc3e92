"""The Transcription interface and the Discretization it builds.

A transcription turns a Problem, a Dynamics backend and a list of Constraint plug-ins into a `Discretization`:
the `NLP` value the solvers get (ocpkit.nlp) plus the maps between a problem of that shape and the NLP's
numbers. It is built once per problem *shape*: start, goal, time bounds, μ and the obstacles' positions enter
through the variable bounds and the parameter vector, so many queries of the same shape share one NLP (and
one prepared solver). The equations of every transcription are in docs/transcription.md.
"""

from __future__ import annotations

import copy
from abc import ABC, abstractmethod
from collections.abc import Sequence
from itertools import count
from typing import ClassVar

import numpy as np

from ocpkit.constraints import Constraint
from ocpkit.constraints.collision import MAX_MARGIN
from ocpkit.dynamics import Dynamics
from ocpkit.errors import OptionError
from ocpkit.formats.trajectory import Trajectory
from ocpkit.nlp import NLP, Refinement
from ocpkit.problem import Problem
from ocpkit.registry import Registry
from ocpkit.transcription.ocp import OCP


class Discretization(ABC):
    """An NLP built for problems of one shape, with the maps from such a problem to bounds, parameters and a
    guess, and from a solution back to a Trajectory. Parts of the NLP's vectors are read by name:

      variables   the OCP's parts ("q", "qd", "qdd", "u" for the robot OCP) (knots, size) at every knot;
                  "start", "goal": the OCP's first `ends` node values at the start and goal knots ([q, q̇, q̈]
                  for a robot);  "tf": every copy of t_f
      parameters  "mu", "margin", "limit_scale", "<constraint>.<name>" per constraint, "ocp.<name>" per OCP
                  parameter, then the transcription's own (`own_parameters`)

    `margin` (m) is the default clearance margin; `ocp` the OCP discretized (ocpkit.transcription.ocp)."""

    def __init__(self, nlp: NLP, constraints: Sequence[Constraint], margin: float, ocp: OCP) -> None:
        self.nlp, self.constraints, self.margin, self.ocp = nlp, tuple(constraints), margin, ocp

    def bounds(self, problem: Problem | None, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """(lbx, ubx): the knot bounds of the constraints imposed that way (where the OCP's knot_bounds allow), the
        OCP's own bounds of its parts, its end bounds (for a robot: start and goal at rest, eq. (10)), the time
        bounds; everything else free."""
        w = self.nlp.variables
        lbx, ubx = np.full(w.size, -np.inf), np.full(w.size, np.inf)
        knot_bounds = [c.variable_bounds(refinement.limit_scale) for c in self.constraints] if self.ocp.knot_bounds \
            else []
        for bounds in [*knot_bounds, self.ocp.chain_bounds()]:
            for name, (lower, upper) in bounds.items():
                w.write(lbx, name, lower)
                w.write(ubx, name, upper)
        for name, (lower, upper) in zip(("start", "goal"), self.ocp.end_bounds(problem)):
            w.write(lbx, name, lower)
            w.write(ubx, name, upper)
        lower, upper = self.ocp.time_bounds(problem)
        w.write(lbx, "tf", lower)
        w.write(ubx, "tf", upper)
        return lbx, ubx

    def parameters(self, problem: Problem | None, refinement: Refinement = Refinement()) -> np.ndarray:
        """p for this problem after `refinement`. The clearance margin (grown by the refinement) is capped at
        MAX_MARGIN; each collision row caps it further at half its own clearance at the start and the goal, both
        fixed (`SphereCollision.margin_caps`): a larger margin would make the NLP infeasible."""
        p = self.nlp.parameters
        values = np.zeros(p.size)
        margin = min(self.margin + refinement.extra_margin, MAX_MARGIN)
        shared = {"mu": self.ocp.cost_weight(problem), "margin": margin, "limit_scale": refinement.limit_scale}
        owned = {f"{c.name}.{name}": value for c in self.constraints for name, value in
                 c.parameter_values(problem).items()}
        owned.update({f"ocp.{name}": value for name, value in self.ocp.parameter_values().items()})
        for name, value in {**shared, **owned, **self.own_parameters(refinement)}.items():
            p.write(values, name, value)
        return values

    def with_ocp(self, ocp: OCP) -> Discretization:
        """This discretization for another OCP of the same key (its numbers: parameters, encode, decode)."""
        if ocp.key != self.ocp.key:
            raise ValueError(f"an OCP of key {ocp.key} cannot use the NLP built for key {self.ocp.key}")
        other = copy.copy(self)
        other.ocp = ocp
        return other

    def initial_guess(self, problem: Problem | None) -> np.ndarray:
        """The OCP's default guess (`OCP.guess`): for the robot OCP the paper's straight joint-space line over
        t_f = time.guess (`ocp.straight_line`)."""
        return self.encode(self.ocp.guess(problem))

    @abstractmethod
    def own_parameters(self, refinement: Refinement) -> dict[str, np.ndarray]:
        """Name → value of the transcription's own parameters (e.g. where the adaptive checks sit)."""

    @abstractmethod
    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """A decision vector w that samples `trajectory` on this NLP's grid: a warm start. For the robot OCP any
        planner's trajectory; for another OCP a trajectory of its chain (x, ẋ, ẍ in the Samples' q, qd, qdd)."""

    @abstractmethod
    def write_checks(self, values: np.ndarray, trajectory: Trajectory, refinement: Refinement) -> None:
        """Write `trajectory` sampled at the check times of `refinement` into the lifted check variables of w
        `values` (n_w,), in place."""

    def relifted(self, w: np.ndarray, refinement: Refinement) -> np.ndarray:
        """w (n_w,) with its lifted check variables resampled from its own motion at the check times of
        `refinement`: the warm start of a solve whose checks sit elsewhere than those w was solved with (a
        refinement round, a rebuild), which would otherwise start with the lifting rows violated."""
        values = np.array(w, dtype=float)
        self.write_checks(values, self.decode(values, chain=True), refinement)
        return values

    @abstractmethod
    def decode(self, w: np.ndarray, chain: bool = False) -> Trajectory:
        """The trajectory that the decision vector w represents; with `chain`, the trajectory of the OCP's chain
        (x, ẋ, ẍ in the Samples' q, qd, qdd; u and du/dt as tau and taud), as `encode` and `write_checks` take it."""


class Transcription(ABC):
    """A transcription method with its options (knots, ...); `build` makes its Discretization for a problem.

    Its constructor checks the knot count (`check_knots`) before anything is built."""

    name: str
    max_intervals: ClassVar[int]
    """The most knot intervals (over all segments) it builds: a larger NLP takes too long and too much memory to
    build (figures: docs/design-notes.md)."""

    @abstractmethod
    def free_path_values(self, knots: int) -> int:
        """How many values of each joint's path the NLP at `knots` leaves free besides t_f: q, q̇, q̈ at every
        point, less the collocation rows and the 6 fixed by rest at start and goal (u follows from the dynamics)."""

    def check_knots(self, knots: int, intervals: int) -> None:
        """OptionError unless the NLP at `knots` (`intervals` in all) leaves the path a free value and has at most
        max_intervals: with fewer knots the start and goal conditions fix or over-determine the path."""
        if self.free_path_values(knots) < 1:
            smallest = next(n for n in count(2) if self.free_path_values(n) >= 1)
            raise OptionError(f"{self.name} needs knots ≥ {smallest}{self._segments_text()}, got {knots}: with fewer "
                              "the start and goal conditions leave the path no free values")
        if intervals > self.max_intervals:
            raise OptionError(f"{self.name} takes at most {self.max_intervals} knot intervals (knots × segments), "
                              f"got {intervals}: a larger NLP takes too long and too much memory to build")

    def _segments_text(self) -> str:
        """" on K segments" where that changes the bound, else ""."""
        segments = getattr(self, "segments", 1)
        return f" on {segments} segments" if segments > 1 else ""

    @abstractmethod
    def options_key(self) -> tuple:
        """Hashable: the options that shape the NLP."""

    def shape_key(self, dynamics: Dynamics | None, constraints: Sequence[Constraint], ocp: OCP | None = None) -> tuple:
        """Hashable, equal for problems that can share one build: the options, the dynamics backend (its robot
        included), each constraint's class and shape, and the OCP's key unless it is the robot OCP (None). Start,
        goal, time bounds, μ and obstacle positions are numbers."""
        key = self.options_key(), dynamics and dynamics.key, tuple((type(c), c.shape()) for c in constraints)
        return key if ocp is None else (*key, ocp.key)

    @abstractmethod
    def build(self, problem: Problem, dynamics: Dynamics, constraints: Sequence[Constraint],
              ocp: OCP | None = None) -> Discretization:
        """The Discretization of `ocp` (the robot OCP of problems of this problem's shape by default)."""


TRANSCRIPTIONS: Registry[type[Transcription]] = Registry("transcription", "ocpkit.transcriptions")
