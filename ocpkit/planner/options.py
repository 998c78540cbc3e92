"""The options of one simultaneous plan, typed: `plan_simultaneous`'s and what a rung of the ladder sets."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ocpkit.constraints import DEFAULT_CONSTRAINTS, Constraint
from ocpkit.dynamics import Dynamics
from ocpkit.formats.trajectory import Trajectory
from ocpkit.planner.ladder import DEFAULT_LADDER, MAX_WALL_TIME, Rung
from ocpkit.planner.refinement import DEFAULT_ROUNDS
from ocpkit.transcription import TRANSCRIPTIONS
from ocpkit.transcription.pseudospectral import Pseudospectral


@dataclass(frozen=True)
class SimultaneousOptions:
    """Every option of `plan_simultaneous` (see there), and what a rung of the ladder adds (Rung.apply):

    `iteration_budget`: solver iterations all solves of the plan may use together (a capped rung's; no refinement
    round or rebuild starts after that many); `relaxed`: solve the problem relaxed first (a continuation,
    ocpkit.planner.refinement.RELAXED); `refines`: a motion to start from (guess "motion") instead of `guess`;
    `pace`: the first solve stops once that many iterations at its pace would not end in its time
    (PreparedSolver.solve).
    `guess_options` stay a mapping: each guess rule is a plug-in (registry GUESSES) with its own keyword options
    (the "ompl" rule's are ocpkit.planner.ompl_seed.SeedOptions, with `fallback` and `slowdown`)."""

    transcription: str = "chebyshev"
    knots: int = 12
    dynamics: str | Dynamics = "casadi-rnea"
    solver: str = "ipopt"
    guess: str | np.ndarray = "paper"
    refinements: int = DEFAULT_ROUNDS
    constraints: Sequence[str | type[Constraint]] = DEFAULT_CONSTRAINTS
    transcription_options: Mapping[str, Any] = field(default_factory=dict)
    solver_options: Mapping[str, Any] = field(default_factory=dict)
    dynamics_options: Mapping[str, Any] | None = None
    max_wall_time: float = MAX_WALL_TIME
    guess_options: Mapping[str, Any] = field(default_factory=dict)
    fallbacks: Sequence[Rung] = DEFAULT_LADDER
    screen: bool | None = None
    iteration_budget: float = math.inf
    relaxed: bool = False
    refines: Trajectory | None = field(default=None, compare=False, repr=False)
    pace: int | None = None

    def pseudospectral(self) -> bool:
        """Whether the transcription is pseudospectral (has `segments`)."""
        return issubclass(TRANSCRIPTIONS.get(self.transcription), Pseudospectral)

    def starting_guess(self) -> tuple[str | np.ndarray, dict]:
        """The guess rule (or decision vector) and its options: the motion `refines` if there is one."""
        if self.refines is not None:
            return "motion", {"trajectory": self.refines}
        return self.guess, dict(self.guess_options)

    def capped(self, iterations: float) -> SimultaneousOptions:
        """These options with every solve stopping after `iterations` (the rest of a capped rung's budget; inf:
        unchanged), so a rebuild's solve cannot take the rung past its budget."""
        if not np.isfinite(iterations):
            return self
        cap = min(int(iterations), self.solver_options.get("max_iterations", np.inf))
        return dataclasses.replace(self, solver_options={**self.solver_options, "max_iterations": cap})
