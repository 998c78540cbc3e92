"""The Solver interface: solve an NLP built by a transcription, from a guess, for given numbers.

Every solver solves the same problem

    minimize f(w; p)  subject to  lbg ≤ g(w; p) ≤ ubg,  lbx ≤ w ≤ ubx

with w (n_w,), p (n_p,), g (n_g,) taken from `NLP` (x, p, f, g). `prepare` does the one-time work
for an NLP shape (derivative graphs, code generation); `solve` is one query.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from ocpkit.registry import Registry
from ocpkit.transcription.base import NLP


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


class Solver(ABC):
    """An NLP solver; one instance may hold prepared state for several NLP shapes.

    Constructors take `max_iterations` and `max_wall_time` (s) limits plus solver-specific options."""

    name: str

    @abstractmethod
    def prepare(self, nlp: NLP) -> None:
        """One-time set-up for this NLP (idempotent)."""

    @abstractmethod
    def solve(self, nlp: NLP, guess: np.ndarray, params: np.ndarray,
              bounds: tuple[np.ndarray, np.ndarray]) -> SolverResult:
        """Solve from `guess` with parameters `params` and variable bounds (lbx, ubx)."""


SOLVERS: Registry[type] = Registry("solver", "ocpkit.solvers")
