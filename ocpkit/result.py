"""What every planner returns: a `Plan` (trajectory, status, verification, stats), made by one `finish`."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

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
    (("motion_time",), ("the solver's iterate left the time bounds (the solver diverged): try another solver or "
                       "guess (guess=ompl)")),
    (("dynamics", "qd_consistency", "qdd_consistency"),
     "the interpolant does not resolve the dynamics between knots: use more knots or segments"),
    (GEOMETRY_CHECKS, ("contact remains between the check times after the refinement rounds: use more knots or "
                      "refinements")),
    (("position", *SCALED_LIMITS), ("a limit is exceeded between the check times after the refinement rounds: use "
                                   "more knots or refinements")),
    (("boundary",), ("the motion does not start and end at rest at the start and goal: check the planner's "
                    "boundary conditions")),
)
"""(failed checks, hint) of a violated plan, most fundamental cause first."""


@dataclass(frozen=True)
class Hints:
    """What a planner can change, by how its plan failed: `stopped` maps a status it stopped with to a hint,
    `violated` pairs failed checks with a hint (most fundamental cause first), `failed` follows the solver's message.
    Each planner names its own options (`finish(..., hints=...)`)."""

    stopped: Mapping[str, str]
    violated: tuple[tuple[tuple[str, ...], str], ...]
    failed: str = "try another guess (guess=ompl) or solver"

    def of(self, status: str, verification: Verification, solver_message: str) -> str:
        """The hint of a plan that ended with `status`, its `verification` and the solver's message."""
        if status == "failed":
            return f"the solver failed ({solver_message}); {self.failed}"
        if status in self.stopped:
            return self.stopped[status]
        failed = {c.name for c in verification.checks if not c.ok}
        return next((hint for names, hint in self.violated if failed.intersection(names)),
                    f"the plan ended with status {status}: {verification.summary()}")


SIMULTANEOUS_HINTS = Hints(STOPPED_HINTS, VIOLATED_HINTS)
"""The simultaneous planner's hints, the default of `finish`."""


@dataclass(frozen=True)
class SolveTiming:
    """One solve (the first, or a refinement round): the solver call's wall time (s), the dense verification's (s),
    its iterations, and the solver's own wall time (s) per NLP evaluation kind where it reports them
    (ocpkit.planner.refinement.CALLBACKS)."""

    solve: float
    verify: float
    iterations: int
    callbacks: Mapping[str, float] = field(default_factory=dict)

    def figures(self) -> dict:
        """As JSON: {"solve", "verify", "iterations", and each callback kind}."""
        return {"solve": self.solve, "verify": self.verify, "iterations": self.iterations, **self.callbacks}


@dataclass(frozen=True)
class Timing:
    """Where a plan's computation went (s); None for a step the planner does not take. `guess`: the simultaneous
    planner's initial guess (an OMPL seed's search and timing included); `path_search`, `simplify`, `smooth`,
    `path_timing`: a decomposition baseline's OMPL search, its path shortening, smoothing and TOPP-RA timing;
    `setup`: the one-time set-up's split (ocpkit.planner.build_cache.Build.setup_parts; empty when reused);
    `rounds`: each solve in order, the first and then the refinement rounds."""

    guess: float | None = None
    path_search: float | None = None
    simplify: float | None = None
    smooth: float | None = None
    path_timing: float | None = None
    setup: Mapping[str, float] = field(default_factory=dict)
    rounds: tuple[SolveTiming, ...] = ()

    @property
    def solve(self) -> float:
        """Seconds in solver calls, all rounds."""
        return sum(r.solve for r in self.rounds)

    @property
    def verify(self) -> float:
        """Seconds in dense verification, all rounds."""
        return sum(r.verify for r in self.rounds)

    @property
    def refinement(self) -> float:
        """Seconds of the rounds after the first (solve and verification)."""
        return sum(r.solve + r.verify for r in self.rounds[1:])


@dataclass(frozen=True)
class RungRow:
    """One rung a fallback ladder tried (ocpkit.planner.ladder): its name, its plan's status, computation time (s,
    to the ms) and solver iterations."""

    rung: str
    status: str
    time_s: float
    iterations: int


@dataclass(frozen=True)
class Screening:
    """Active-set screening of a plan (ocpkit.planner.screening): collision rows per point of its last build and
    the rebuilds it took."""

    rows_per_point: int
    rebuilds: int


@dataclass(frozen=True)
class PathStats:
    """A decomposition baseline's path: configurations checked for collision, waypoints, smoothing repair rounds,
    the clearance margin planned with (m), TOPP-RA's t_f (s; None where not reported) and the path searches made
    (ocpkit.planner.ompl_seed.ompl_path searches a slow path again)."""

    validity_checks: int
    waypoints: int
    repair_rounds: int
    margin: float
    toppra_tf: float | None = None
    searches: int = 1


@dataclass(frozen=True)
class PlanStats:
    """Timing (s) and effort of one plan: computation (guess, solves, verification; set-up excluded), the
    one-time set-up (0 when a build was reused), solver iterations, refinement rounds, the solver's message;
    where the time went (`timing`); for a fallback ladder the rungs tried, those skipped and the hint of its
    failure (`Plan.hint`); screening; a baseline's path. `extra`: figures of a planner these fields do not
    describe (a third-party planner's, the bench's record of a planner that raised), kept beside them in
    `figures`."""

    solve_time: float
    setup_time: float
    iterations: int
    rounds: int
    solver_message: str
    timing: Timing = field(default_factory=Timing)
    rungs: tuple[RungRow, ...] = ()
    skipped: tuple[str, ...] = ()
    hint: str | None = None
    screening: Screening | None = None
    path: PathStats | None = None
    extra: Mapping[str, Any] = field(default_factory=dict)

    def figures(self) -> dict:
        """The planner's own figures as JSON (results.csv's `extra` column): `timing` {guess (where there was
        one), rounds, setup} of a plan that guessed or solved; a baseline's path_time_s, simplify_time_s,
        smooth_time_s, toppra_time_s, validity_checks, waypoints, repair_rounds, margin_m, path_searches (and
        toppra_tf_s);
        `screening` {rows_per_point, rebuilds}; a ladder's `rungs` [{rung, status, time_s, iterations}] and
        `skipped`; `hint`; then `extra`."""
        t, figures = self.timing, {}
        if t.guess is not None or t.rounds:
            guess = {} if t.guess is None else {"guess": t.guess}
            figures["timing"] = {**guess, "rounds": [r.figures() for r in t.rounds], "setup": dict(t.setup)}
        for key, seconds in (("path_time_s", t.path_search), ("simplify_time_s", t.simplify),
                             ("smooth_time_s", t.smooth), ("toppra_time_s", t.path_timing)):
            if seconds is not None:
                figures[key] = seconds
        if self.path is not None:
            figures.update(validity_checks=self.path.validity_checks, waypoints=self.path.waypoints,
                           repair_rounds=self.path.repair_rounds, margin_m=self.path.margin,
                           path_searches=self.path.searches)
            if self.path.toppra_tf is not None:
                figures["toppra_tf_s"] = self.path.toppra_tf
        if self.screening is not None:
            figures["screening"] = dataclasses.asdict(self.screening)
        if self.rungs:
            figures["rungs"] = [dataclasses.asdict(r) for r in self.rungs]
            figures["skipped"] = list(self.skipped)
        if self.hint is not None:
            figures["hint"] = self.hint
        return {**figures, **self.extra}


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
    hints: Hints = field(default=SIMULTANEOUS_HINTS, compare=False, repr=False)

    @property
    def ok(self) -> bool:
        return self.status == "verified"

    @property
    def hint(self) -> str:
        """What to try, one sentence: the planner's own (stats.hint) if it gave one, else from the status
        and the verification or solver message; "" when verified."""
        if self.ok:
            return ""
        if self.stats.hint is not None:  # a planner's own word (the fallback ladder's)
            return self.stats.hint
        return self.hints.of(self.status, self.verification, self.stats.solver_message)


def finish(problem: Problem, trajectory: Trajectory, stopped: str | None, method: dict, started: float, *,
           setup_time: float = 0.0, iterations: int = 0, rounds: int = 0, message: str = "",
           timing: Timing | None = None, screening: Screening | None = None, path: PathStats | None = None,
           extra: dict | None = None, verification: Verification | None = None, found: bool = True,
           hints: Hints = SIMULTANEOUS_HINTS) -> Plan:
    """The Plan of `trajectory` for `problem`. `stopped` is the planner's word when it did not finish (then it is
    the status), None when it did (then the status is `verified` or `violated`, as the dense verification says;
    `verification` is computed here unless given). `started` is the time.perf_counter() when planning began:
    the computation time runs until now, less `setup_time`. `timing`, `screening`, `path`, `extra`: see
    `PlanStats`; `found`: see `Plan`; `hints`: what this planner can change when the plan fails (`Hints`)."""
    verification = verification or verify(problem, trajectory)
    status = stopped or ("verified" if verification.ok else "violated")
    stats = PlanStats(time.perf_counter() - started - setup_time, setup_time, iterations, rounds, message,
                      timing or Timing(), screening=screening, path=path, extra=extra or {})
    return Plan(trajectory, status, verification, stats, method, found, hints)
