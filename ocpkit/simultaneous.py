"""The simultaneous planner (the paper's method): path and timing together as one optimal control problem.

A build of the problem's shape (ocpkit.build_cache: transcription + dynamics + constraints + prepared solver, reused
across queries), an initial guess, the solve with refinement rounds (ocpkit.refine), and `finish`.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from ocpkit.build_cache import build
from ocpkit.constraints import DEFAULT_CONSTRAINTS, Constraint
from ocpkit.dynamics import Dynamics
from ocpkit.plan import Plan, finish
from ocpkit.planner import GUESSES
from ocpkit.problem import Problem
from ocpkit.refine import DEFAULT_ROUNDS, solve_refined
from ocpkit.solvers import SolverStatus
from ocpkit.transcription import Discretization


def line_guess(problem: Problem, discretization: Discretization) -> np.ndarray:
    """The straight joint-space line from start to goal over t_f = time.guess (the paper's initial guess)."""
    return discretization.initial_guess(problem)


def plan_simultaneous(problem: Problem, transcription: str = "chebyshev", knots: int = 12,
                      dynamics: str | Dynamics = "casadi-rnea", solver: str = "ipopt", guess: str | np.ndarray = "line",
                      refinements: int = DEFAULT_ROUNDS,
                      constraints: Sequence[str | type[Constraint]] = DEFAULT_CONSTRAINTS,
                      transcription_options: dict | None = None, solver_options: dict | None = None,
                      dynamics_options: dict | None = None) -> Plan:
    """Plan `problem` with path and timing together.

    `knots` is N, the intervals per segment of a pseudospectral transcription (K N + 1 points on K `segments`) or
    the mesh intervals of a local one; `guess` names a registered initial-guess rule ("line": the
    paper's straight joint-space line; "ompl": the OMPL + TOPP-RA baseline's motion) or is a decision vector for
    this shape; `refinements` bounds the re-solve rounds. Components and options as for `ocpkit.build`. The guess
    is part of the computation time; the one-time set-up is not."""
    started = time.perf_counter()
    made = build(problem, transcription, knots, dynamics, solver, constraints, transcription_options,
                 solver_options, dynamics_options)
    w = GUESSES.get(guess)(problem, made.discretization) if isinstance(guess, str) else np.asarray(guess, float)
    refined = solve_refined(made.discretization, made.solver, problem, w, refinements)
    result = refined.result
    method = {"planner": "simultaneous", "transcription": transcription, "knots": knots,
              "dynamics": dynamics if isinstance(dynamics, str) else dynamics.name, "solver": solver}
    stopped = None if result.status == SolverStatus.CONVERGED else result.status.value
    return finish(problem, refined.trajectory, stopped, method, started, setup_time=made.setup_time,
                  iterations=refined.iterations, rounds=refined.rounds, message=result.message,
                  verification=refined.verification)
