"""`plan`: the one call that solves a Problem with a chosen planner and components, then verifies it.

The simultaneous planner (transcription + dynamics + solver) builds one NLP per problem shape and caches
it with its prepared solver, so a second query of the same shape pays no set-up. After each solve the
trajectory is verified densely; where a path constraint is violated between check times, the adaptive
check slots are moved there, the clearance margin grows by twice the deepest contact found (at least 5 mm),
the velocity,
torque and torque-rate limits the NLP uses shrink by the excess found (plus 0.5 %), and the NLP is
re-solved warm-started (no rebuild), for at most `refinements` rounds. A check at the worst time alone
rarely suffices: with the constraint active, the polynomial then dips just beside the new check.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable

import numpy as np

from ocpkit.errors import OptionError
from ocpkit.problem import Problem
from ocpkit.registry import Registry
from ocpkit.solvers.base import SOLVERS, Solver, SolverStatus
from ocpkit.trajectory import Trajectory
from ocpkit.transcription.base import NLP, TRANSCRIPTIONS, Refinement
from ocpkit.verify import Verification, verify

PLANNERS: Registry[Any] = Registry("planner", "ocpkit.planners")
GUESSES: Registry[Callable[[Problem, NLP], np.ndarray]] = Registry("initial guess", "ocpkit.guesses")


def line_guess(problem: Problem, nlp: NLP) -> np.ndarray:
    """The transcription's straight joint-space line from start to goal (the paper's initial guess)."""
    return nlp.initial_guess(problem)


@dataclass(frozen=True)
class PlanStats:
    """Timing (s) and effort of one plan: set-up is the one-time build (0 when cached)."""

    solve_time: float
    setup_time: float
    iterations: int
    rounds: int
    solver_message: str
    extra: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Plan:
    """A planned trajectory with its status: `verified` only if the dense verification passed.

    Other statuses: `violated` (solver converged, verification failed), `infeasible`, `iteration_limit`,
    `time_limit`, `failed` (the solver's word)."""

    trajectory: Trajectory
    status: str
    verification: Verification
    stats: PlanStats
    method: dict

    @property
    def ok(self) -> bool:
        return self.status == "verified"


_BUILDS: dict[tuple, tuple[NLP, Solver, float]] = {}


def prepared(problem: Problem, transcription: str, dynamics: str, solver: str,
             transcription_options: dict, solver_options: dict) -> tuple[NLP, Solver, float]:
    """The cached (NLP, prepared solver, set-up seconds) for this problem's shape; builds on first use."""
    method = _construct(TRANSCRIPTIONS.get(transcription), transcription, transcription_options)
    key = (method.shape_key(problem, dynamics), solver, tuple(sorted(solver_options.items())))
    if key not in _BUILDS:
        start = time.perf_counter()
        nlp = method.build(problem, dynamics)
        nlp_solver = _construct(SOLVERS.get(solver), solver, solver_options)
        nlp_solver.prepare(nlp)
        _BUILDS[key] = (nlp, nlp_solver, time.perf_counter() - start)
        return _BUILDS[key]
    nlp, nlp_solver, _ = _BUILDS[key]
    return nlp, nlp_solver, 0.0


def _construct(component: Callable, name: str, options: dict) -> Any:
    """`component(**options)`; an option it does not take is the user's mistake, reported as an OptionError."""
    try:
        return component(**options)
    except TypeError as exc:
        raise OptionError(f"{name}: {exc} (options given: {sorted(options)})") from exc


def plan(problem: Problem, planner: str = "simultaneous", **options: Any) -> Plan:
    """Plan `problem` with the named planner; options go to that planner (see `plan_simultaneous`)."""
    return PLANNERS.get(planner)(problem, **options)


def plan_simultaneous(problem: Problem, transcription: str = "chebyshev", knots: int = 12,
                      dynamics: str = "casadi-rnea", solver: str = "ipopt", guess: str | np.ndarray = "line",
                      refinements: int = 5,
                      transcription_options: dict | None = None, solver_options: dict | None = None) -> Plan:
    """Path and timing together as one optimal control problem (the paper's method).

    `knots` is N (N + 1 knot points for Chebyshev); `guess` names a registered initial-guess rule ("line":
    the transcription's straight joint-space line, as in the paper; "ompl": the OMPL + TOPP-RA baseline's
    motion) or is a decision vector for this shape; `refinements` bounds the re-solve rounds. The guess is
    part of the computation time."""
    start = time.perf_counter()
    nlp, nlp_solver, setup = prepared(problem, transcription, dynamics, solver,
                                      {"knots": knots, **(transcription_options or {})}, solver_options or {})
    w = GUESSES.get(guess)(problem, nlp) if isinstance(guess, str) else np.asarray(guess, dtype=float)
    refinement = Refinement()
    iterations, rounds = 0, 0
    while True:
        result = nlp_solver.solve(nlp, w, nlp.parameters(problem, refinement), nlp.bounds(problem, refinement))
        iterations += result.iterations
        trajectory = nlp.decode(result.w)
        verification = verify(problem, trajectory)
        fresh = verification.violation_times / trajectory.tf
        if verification.ok or result.status != SolverStatus.CONVERGED or rounds >= refinements or not len(fresh):
            break
        excess = verification.limit_excess
        shrink = 1.0 - excess - 0.005 if excess > 0 else 1.0
        refinement = Refinement(np.concatenate([fresh, refinement.check_fractions]),  # newest take the slots
                                refinement.extra_margin + _margin_step(verification.penetration),
                                refinement.limit_scale * shrink)
        w, rounds = result.w, rounds + 1
    if result.status != SolverStatus.CONVERGED:
        status = result.status.value
    else:
        status = "verified" if verification.ok else "violated"
    method = {"planner": "simultaneous", "transcription": transcription, "knots": knots, "dynamics": dynamics,
              "solver": solver}
    stats = PlanStats(time.perf_counter() - start - setup, setup, iterations, rounds, result.message)
    return Plan(trajectory, status, verification, stats, method)


def _margin_step(penetration: float) -> float:
    """Extra clearance margin (m) after a round that found spheres `penetration` m deep in contact."""
    return max(2.0 * penetration, 0.005) if penetration > 0 else 0.0


