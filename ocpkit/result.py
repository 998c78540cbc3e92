"""What every planner returns: a `Plan` (trajectory, status, verification, stats), made by one `finish`."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from ocpkit.formats.trajectory import Trajectory
from ocpkit.problem import Problem
from ocpkit.verify import GEOMETRY_CHECKS, SCALED_LIMITS, Verification, verify

STOPPED_HINTS = {
    "infeasible": "the solver found the problem locally infeasible from its start point: try another guess "
                  "(guess=ompl), or check that time.max and the torque limits allow the motion",
    "iteration_limit": "the solver reached its iteration limit: raise max_iterations or start from a better guess "
                       "(guess=ompl)",
    "time_limit": "the plan reached its wall-time limit: raise max_wall_time or start from a better guess "
                  "(guess=ompl)",
    "no_path": "OMPL found no path within its budget, so there is no trajectory: raise planning_time",
}
"""The hint of a plan that stopped with this status (`failed` quotes the solver's message instead)."""
VIOLATED_HINTS = (
    (("motion_time",), "the solver's iterate left the time bounds (the solver diverged): try another solver or "
                       "guess (guess=ompl)"),
    (("dynamics", "qd_consistency", "qdd_consistency"),
     "the interpolant does not resolve the dynamics between knots: use more knots or segments"),
    (GEOMETRY_CHECKS, "contact remains between the check times after the refinement rounds: use more knots or "
                      "refinements"),
    (("position", *SCALED_LIMITS), "a limit is exceeded between the check times after the refinement rounds: use "
                                   "more knots or refinements"),
    (("boundary",), "the motion does not start and end at rest at the start and goal: check the planner's "
                    "boundary conditions"),
)
"""(failed checks, hint) of a violated plan, most fundamental cause first."""


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
    not finish: `infeasible`, `iteration_limit`, `time_limit`, `failed` (the solver's; also an iterate outside
    its variable bounds, named in the message), `no_path` (no path found). `method` names the planner and its
    components. `hint` says in one sentence what to try.

    `found` is False when the planner found no trajectory (`no_path`; the baseline's `infeasible`): then
    `trajectory` only holds the start at rest for time.min seconds (its t_f is that held time, not a motion
    time), `stats.iterations` is 0 and `stats.solver_message` says that no trajectory was found."""

    trajectory: Trajectory
    status: str
    verification: Verification
    stats: PlanStats
    method: dict
    found: bool = True

    @property
    def ok(self) -> bool:
        return self.status == "verified"

    @property
    def hint(self) -> str:
        """What to try, one sentence: the planner's own (stats.extra["hint"]) if it gave one, else from the status
        and the verification or solver message; "" when verified."""
        if self.ok:
            return ""
        if "hint" in self.stats.extra:  # a planner's own word (the fallback ladder's)
            return self.stats.extra["hint"]
        if self.status == "failed":
            return f"the solver failed ({self.stats.solver_message}); try another guess (guess=ompl) or solver"
        if self.status in STOPPED_HINTS:
            return STOPPED_HINTS[self.status]
        failed = {c.name for c in self.verification.checks if not c.ok}
        return next((hint for names, hint in VIOLATED_HINTS if failed.intersection(names)),
                    f"the plan ended with status {self.status}: {self.verification.summary()}")


def finish(problem: Problem, trajectory: Trajectory, stopped: str | None, method: dict, started: float, *,
           setup_time: float = 0.0, iterations: int = 0, rounds: int = 0, message: str = "",
           extra: dict | None = None, verification: Verification | None = None, found: bool = True) -> Plan:
    """The Plan of `trajectory` for `problem`. `stopped` is the planner's word when it did not finish (then it is
    the status), None when it did (then the status is `verified` or `violated`, as the dense verification says;
    `verification` is computed here unless given). `started` is the time.perf_counter() when planning began:
    the computation time runs until now, less `setup_time`. `found`: see `Plan`."""
    verification = verification or verify(problem, trajectory)
    status = stopped or ("verified" if verification.ok else "violated")
    stats = PlanStats(time.perf_counter() - started - setup_time, setup_time, iterations, rounds, message,
                      extra or {})
    return Plan(trajectory, status, verification, stats, method, found)
