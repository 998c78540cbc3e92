"""What every planner returns: a `Plan` (trajectory, status, verification, stats), made by one `finish`."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from ocpkit.problem import Problem
from ocpkit.trajectory import Trajectory
from ocpkit.verify import Verification, verify


@dataclass(frozen=True)
class PlanStats:
    """Timing (s) and effort of one plan: computation (guess, solves, verification; set-up excluded), the
    one-time set-up (0 when a build was reused), solver iterations, refinement rounds, the solver's message and
    planner-specific figures in `extra`."""

    solve_time: float
    setup_time: float
    iterations: int
    rounds: int
    solver_message: str
    extra: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Plan:
    """A planned trajectory with its status: `verified` only if the dense verification passed.

    Other statuses: `violated` (the planner finished, verification failed), or the planner's word on why it did
    not finish: `infeasible`, `iteration_limit`, `time_limit`, `failed` (the solver's), `no_path` (no path
    found). `method` names the planner and its components."""

    trajectory: Trajectory
    status: str
    verification: Verification
    stats: PlanStats
    method: dict

    @property
    def ok(self) -> bool:
        return self.status == "verified"


def finish(problem: Problem, trajectory: Trajectory, stopped: str | None, method: dict, started: float, *,
           setup_time: float = 0.0, iterations: int = 0, rounds: int = 0, message: str = "",
           extra: dict | None = None, verification: Verification | None = None) -> Plan:
    """The Plan of `trajectory` for `problem`. `stopped` is the planner's word when it did not finish (then it is
    the status), None when it did (then the status is `verified` or `violated`, as the dense verification says;
    `verification` is computed here unless given). `started` is the time.perf_counter() when planning began:
    the computation time runs until now, less `setup_time`."""
    verification = verification or verify(problem, trajectory)
    status = stopped or ("verified" if verification.ok else "violated")
    stats = PlanStats(time.perf_counter() - started - setup_time, setup_time, iterations, rounds, message,
                      extra or {})
    return Plan(trajectory, status, verification, stats, method)
