"""Refinement: re-solve where the dense verification found a path constraint violated between check times.

After a converged solve whose trajectory fails `verify`, the next round moves the adaptive check slots to the
violation times (newest first), grows the clearance margin by PENETRATION_FACTOR times the deepest contact (at
least MIN_MARGIN_STEP), shrinks the velocity, torque and torque-rate limits the NLP uses by the excess found plus
LIMIT_BACKOFF (to no less than MIN_SHRINK of them in one round), and re-solves warm-started from the last
solution, all through NLP parameters (no rebuild). A check at the worst time alone rarely suffices: with the
constraint active, the interpolant then dips just beside the new check.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ocpkit.nlp import Refinement
from ocpkit.problem import Problem
from ocpkit.solvers import PreparedSolver, SolverResult, SolverStatus
from ocpkit.trajectory import Trajectory
from ocpkit.transcription import Discretization
from ocpkit.verify import Verification, verify

DEFAULT_ROUNDS = 5  # refinement rounds after the first solve, at most
MIN_MARGIN_STEP = 0.005  # m
PENETRATION_FACTOR = 2.0
LIMIT_BACKOFF = 0.005  # fraction of each limit
MIN_SHRINK = 0.5  # one round never takes more than half of a limit away


@dataclass(frozen=True)
class Refined:
    """The last solve's result, its trajectory and verification, the iterations of all solves, and the
    refinement rounds taken."""

    result: SolverResult
    trajectory: Trajectory
    verification: Verification
    iterations: int
    rounds: int


def next_refinement(previous: Refinement, verification: Verification, tf: float) -> Refinement | None:
    """The refinement after a converged solve with motion time tf (s) verified as `verification`; None when there
    is nothing to fix by one (verified, or no violation between check times)."""
    fresh = verification.violation_times / tf
    if verification.ok or not len(fresh):
        return None
    excess = verification.limit_excess
    shrink = max(1.0 - excess - LIMIT_BACKOFF, MIN_SHRINK) if excess > 0 else 1.0
    return Refinement(np.concatenate([fresh, previous.check_fractions]),  # the newest take the slots
                      previous.extra_margin + margin_step(verification.penetration), previous.limit_scale * shrink)


def margin_step(penetration: float) -> float:
    """Extra clearance margin (m) after a round that found spheres `penetration` m deep in contact."""
    return max(PENETRATION_FACTOR * penetration, MIN_MARGIN_STEP) if penetration > 0 else 0.0


def solve_refined(discretization: Discretization, solver: PreparedSolver, problem: Problem, guess: np.ndarray,
                  rounds: int = DEFAULT_ROUNDS) -> Refined:
    """Solve `problem` on `discretization` from `guess`, verify, and refine for at most `rounds` rounds."""
    refinement, iterations, taken = Refinement(), 0, 0
    while True:
        result = solver.solve(guess, discretization.parameters(problem, refinement),
                              discretization.bounds(problem, refinement))
        iterations += result.iterations
        trajectory = discretization.decode(result.w)
        verification = verify(problem, trajectory)
        following = next_refinement(refinement, verification, trajectory.tf)
        if following is None or result.status != SolverStatus.CONVERGED or taken >= rounds:
            return Refined(result, trajectory, verification, iterations, taken)
        refinement, guess, taken = following, result.w, taken + 1
