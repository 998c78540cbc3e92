"""The simultaneous planner (the paper's method): path and timing together as one optimal control problem.

A build of the problem's shape (ocpkit.build_cache: transcription + dynamics + constraints + prepared solver, reused
across queries), an initial guess, the solve with refinement rounds (ocpkit.refine), and `finish`.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Sequence

import numpy as np

from ocpkit.build_cache import build, construct
from ocpkit.constraints import DEFAULT_CONSTRAINTS, Constraint
from ocpkit.dynamics import Dynamics
from ocpkit.errors import OptionError
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
                      dynamics_options: dict | None = None, max_wall_time: float = 60.0,
                      guess_options: dict | None = None) -> Plan:
    """Plan `problem` with path and timing together.

    `knots` is N, the intervals per segment of a pseudospectral transcription (K N + 1 points on K `segments`) or
    the mesh intervals of a local one; `guess` names a registered initial-guess rule ("line": the paper's straight
    joint-space line; "ompl": the OMPL + TOPP-RA baseline's motion) or is a decision vector for this shape, with
    `guess_options` for the rule (e.g. {"seed": 3, "planning_time": 2.0} for "ompl", the baseline's options);
    `refinements` bounds the re-solve rounds. Components and options as for `ocpkit.build`. The guess is part of
    the computation time; the one-time set-up is not. `max_wall_time` (s) bounds the computation
    (guess, every solve and refinement round): each solve gets the time left (a solver that cannot be
    interrupted, blocksqp or fatrop, can overrun it by one solve), and the plan ends as `time_limit` when it
    runs out."""
    started = time.perf_counter()
    made = build(problem, transcription, knots, dynamics, solver, constraints, transcription_options,
                 solver_options, dynamics_options)
    deadline = time.perf_counter() + max_wall_time
    w = _guess(problem, made.discretization, guess, guess_options or {})
    refined = solve_refined(made.discretization, made.solver, problem, w, refinements, deadline)
    result = refined.result
    method = {"planner": "simultaneous", "transcription": transcription, "knots": knots,
              "dynamics": dynamics if isinstance(dynamics, str) else dynamics.name, "solver": solver}
    stopped = None if result.status == SolverStatus.CONVERGED else result.status.value
    return finish(problem, refined.trajectory, stopped, method, started, setup_time=made.setup_time,
                  iterations=refined.iterations, rounds=refined.rounds, message=result.message,
                  verification=refined.verification)


def _guess(problem: Problem, discretization: Discretization, guess: str | np.ndarray, options: dict) -> np.ndarray:
    """The decision vector w₀ (n_w,) of the named guess rule (with `options`), or `guess` itself; OptionError if its
    length is not n_w."""
    if isinstance(guess, str):
        return construct(functools.partial(GUESSES.get(guess), problem, discretization), f"guess {guess!r}", options)
    w = np.asarray(guess, dtype=float)
    expected = discretization.nlp.variables.size
    if w.shape != (expected,):
        raise OptionError(f"the guess vector has shape {w.shape}, this NLP needs {expected} values (n_w)")
    return w
