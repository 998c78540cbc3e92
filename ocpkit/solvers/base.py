"""The Solver interface: solve an `NLP` from a guess, for given numbers.

Every solver solves the same problem

    minimize f(w; p)  subject to  lbg ≤ g(w; p) ≤ ubg,  lbx ≤ w ≤ ubx

with w (n_w,), p (n_p,), g (n_g,) taken from `NLP` (x, p, f, g). A `Solver` holds options only;
`Solver.prepare(nlp)` does the one-time work for one NLP (derivative graphs, solver set-up) and returns a
`PreparedSolver`, whose `solve` is one query (guess, p, bounds). Whoever prepares keeps the PreparedSolver
for as long as it wants to reuse it; solvers cache nothing.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from enum import Enum
from typing import ClassVar

import numpy as np

from ocpkit.nlp import NLP
from ocpkit.registry import Registry

BOUND_TOLERANCE = 1e-6
"""How far, relative to max(ubx − lbx, 1), a solution may lie outside its variable bounds and count as inside."""


def bound_slack(lbx: np.ndarray, ubx: np.ndarray) -> np.ndarray:
    """How far each variable (n_w,) may lie outside [lbx, ubx] and still count as inside (BOUND_TOLERANCE)."""
    width = np.where(np.isfinite(ubx - lbx), ubx - lbx, 1.0)
    return BOUND_TOLERANCE * np.maximum(width, 1.0)


class SolverStatus(str, Enum):
    """What happened in a solve."""

    CONVERGED = "converged"
    INFEASIBLE = "infeasible"
    ITERATION_LIMIT = "iteration_limit"
    TIME_LIMIT = "time_limit"
    FAILED = "failed"


@dataclass(frozen=True)
class SolverResult:
    """Solution w (n_w,), status, iteration count, wall time (s), solver message, raw stats, and the
    multipliers where the solver reports them: lam_g (n_g,) of lbg ≤ g ≤ ubg and lam_x (n_w,) of the bounds,
    in CasADi's sign convention (positive on an active upper bound, negative on an active lower one)."""

    w: np.ndarray
    status: SolverStatus
    iterations: int
    wall_time: float
    message: str
    stats: dict = field(default_factory=dict, repr=False)
    lam_g: np.ndarray | None = field(default=None, repr=False)
    lam_x: np.ndarray | None = field(default=None, repr=False)

    @classmethod
    def failed(cls, guess: np.ndarray, started: float, message: str) -> SolverResult:
        """A solve that ended abnormally (an exception, not a status): the guess back, no iterations, the wall
        time since `started` (time.perf_counter s)."""
        return cls(np.asarray(guess, dtype=float), SolverStatus.FAILED, 0, time.perf_counter() - started, message)


def time_limit(own: float, given: float | None) -> float:
    """The wall-time limit (s) of one call: `given` if there is one, else the solver's `own`."""
    return own if given is None else given


class PreparedSolver(ABC):
    """A solver set up for one NLP (`nlp`): answers queries on it without redoing the set-up."""

    nlp: NLP

    @abstractmethod
    def solve(self, guess: np.ndarray, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              max_wall_time: float | None = None, pace: int | None = None) -> SolverResult:
        """Solve from `guess` (n_w,) with parameters `params` (n_p,) and variable bounds (lbx, ubx) (n_w,) each.

        `max_wall_time` (s) replaces the solver's own limit for this call (None: the solver's); a solver that
        cannot be interrupted reports an overrun as `time_limit` after the fact (its docstring says so).
        `pace`: stop as `time_limit` as soon as this many iterations, at the pace of those so far, would not fit
        in the call's limit (a solve that cannot converge in time gives its time back early); only the solvers
        that stop by iteration callback (ipopt, sqpmethod) heed it, the others ignore it."""


class Solver(ABC):
    """An NLP solver's options; it holds no state of any NLP.

    Constructors take `max_iterations` and `max_wall_time` (s) limits plus solver-specific options."""

    name: str
    needs_stages: ClassVar[bool] = False
    """Whether it needs the NLP's stage structure (ocpkit.nlp.Stages) to run at its speed: `ocpkit.build` then
    asks a transcription that can give it for it, and refuses one that cannot (STAGES_NEEDED) unless the solver
    is told `single_stage=True`."""

    @abstractmethod
    def prepare(self, nlp: NLP) -> PreparedSolver:
        """The one-time set-up for `nlp`; OptionError when this solver cannot take it."""

    def solve(self, nlp: NLP, guess: np.ndarray, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              max_wall_time: float | None = None) -> SolverResult:
        """One solve of `nlp` (prepared for this call only): see `PreparedSolver.solve`."""
        return self.prepare(nlp).solve(guess, params, bounds, max_wall_time)


SOLVERS: Registry[type] = Registry("solver", "ocpkit.solvers")

STAGES_NEEDED = ("{solver} needs the NLP's stage structure, and {what} has none: use a local transcription "
                 "(trapezoidal or hermite-simpson), which is staged for it, or solver_options={{'single_stage': "
                 "True}} to run it as one dense stage (slow)")
"""The error of a solver that needs stages (`Solver.needs_stages`) on an NLP without them."""
