"""The fallback ladder of the simultaneous planner: the rungs tried in order until one plan verifies.

A `Rung` is a small set of option overrides (initial guess and OMPL seed, knots, segments, an iteration cap per
solve) applied to the options of the call. `climb` plans rung after rung within one wall-time budget and
returns the first verified plan, else the best one (`rank`), with every rung's name, status, time and
iterations in `stats.extra["rungs"]`. A rung that only lifts the iteration cap of an earlier one is skipped
(listed in `stats.extra["skipped"]`) unless that one stopped at its cap: it would repeat the same solve. An
empty ladder plans once with the call's options (the paper's single shot).

Why these rungs (tuned on `ocpkit bench random --seed 200 --count 40 --obstacles 1 3` and seed 300; measured
on seed 500 in README.md): the straight line verifies most problems within a few hundred IPOPT iterations, and
one that has not converged by then usually ends infeasible or at the iteration limit after many seconds, so the
first rung is capped (MAX_ITERATIONS_CAPPED, per solve and for the rung's refinement rounds together): that cap is
how the ladder leaves a local infeasibility, a restoration phase, a t_f pinned at its upper bound, or a motion that
keeps tunnelling through a thin obstacle between check points round after round (MBM's cage) early. The OMPL +
TOPP-RA motion (collision-free by construction) is the better start in clutter, and another seed gives another
homotopy class when the first one is poor. The first two OMPL rungs solve on three pseudospectral segments of 6
intervals (19 points instead of 12 knots' 13): piecewise polynomials follow a path with corners, where one
polynomial of degree 12 leaves it between knots (figures: docs/design-notes.md). Their path search is budgeted in
configurations checked (OMPL_CHECKS, the budget the random suite certifies room to pass with), so whether it
finds a path does not depend on the machine's speed. More knots resolve what a coarse grid leaves violated. The
continuation rung solves the problem relaxed first (a softened margin, wider limits) and the real one from there.
The last rung is the uncapped single shot with whatever time is left, so the ladder never loses a plan the single
shot finds in time.

The default budget, MAX_WALL_TIME, leaves room for the first three rungs on a hard problem (MotionBenchMaker's
shelves and cages: the capped first rung and two OMPL rungs, each a path search and its solves; figures:
docs/design-notes.md). A verified plan returns at once; the budget is what a failure costs.

A rung whose plan fails only checks that no refinement round can fix (the dynamics residual between knots, with
every path constraint met: `Verification.fixable` is False) is followed at once by its `finer` rung: the same
options on a finer grid (one more pseudospectral segment; half as many intervals again for a local
transcription), warm-started from that plan's motion. The residual is the interpolation error of the grid, and
a motion that already meets every path constraint often converges on the finer one within a few dozen iterations;
the size of the residual does not tell when, so the rung is capped at FINER_ITERATIONS to leave the later rungs
their time (figures: docs/design-notes.md).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from ocpkit.formats.trajectory import Trajectory
from ocpkit.result import Plan, PlanStats

MAX_ITERATIONS_CAPPED = 300  # IPOPT iterations per solve of a capped rung
MAX_WALL_TIME = 90.0  # s of computation for the whole ladder, the simultaneous planner's default (docstring)
OMPL_CHECKS = 1_500_000  # configurations an OMPL rung may check for its path (about 20 s on one core)
FINER_ITERATIONS = 50  # IPOPT iterations per solve of a finer rung; no refinement round starts after that many


@dataclass(frozen=True)
class Rung:
    """Option overrides of one attempt: `guess` ("line", "ompl" or None for the call's), OMPL `seed`, `knots`
    (None: the call's), pseudospectral `segments` of `knots` intervals each (None: the call's; a transcription
    without segments keeps the call's knots too), `max_iterations` per solve (None: the solver's; no
    refinement round starts once the rung's solves have used that many),
    `relaxed`: a continuation, solving the problem relaxed (ocpkit.planner.refinement.RELAXED) first to warm-start the real
    one, and `refines`: a motion to re-solve on a finer grid than the rung's own (`finer`), its guess instead of
    `guess`. An "ompl" rung's path search stops after OMPL_CHECKS configurations checked or when the ladder's
    time is up."""

    name: str
    guess: str | None = None
    seed: int | None = None
    knots: int | None = None
    segments: int | None = None
    max_iterations: int | None = None
    relaxed: bool = False
    refines: Trajectory | None = field(default=None, compare=False, repr=False)


DEFAULT_LADDER: tuple[Rung, ...] = (
    Rung("first", max_iterations=MAX_ITERATIONS_CAPPED),
    Rung("ompl-0-segments-3", guess="ompl", seed=0, knots=6, segments=3, max_iterations=MAX_ITERATIONS_CAPPED),
    Rung("ompl-1-segments-3", guess="ompl", seed=1, knots=6, segments=3, max_iterations=MAX_ITERATIONS_CAPPED),
    Rung("ompl-2-knots-16", guess="ompl", seed=2, knots=16, max_iterations=MAX_ITERATIONS_CAPPED),
    Rung("relaxed-first", relaxed=True, max_iterations=MAX_ITERATIONS_CAPPED),
    Rung("first-uncapped"),
)
"""The default ladder (module docstring says why each rung is there)."""

SINGLE_SHOT: tuple[Rung, ...] = ()
"""No fallbacks: one plan with the call's options (the paper's setting)."""

NO_PATH_HINT = ("no rung verified, and OMPL found no collision-free path within its budget either: the obstacles "
                "may block every way from start to goal (the ompl-toppra planner with a larger planning_time tells)")
"""The hint of a ladder that failed where an OMPL rung found no path."""

STATUS_ORDER = ("verified", "violated", "infeasible", "iteration_limit", "time_limit", "failed", "no_path")
"""Plan statuses from best to worst, for `rank`."""


def rank(plan: Plan) -> tuple[int, float]:
    """Sort key of a plan, smaller is better: its status by STATUS_ORDER, then its largest failed check's worst
    value (the check's unit: relative for limits, m for contact)."""
    worst = max((c.worst for c in plan.verification.checks if not c.ok), default=0.0)
    return STATUS_ORDER.index(plan.status) if plan.status in STATUS_ORDER else len(STATUS_ORDER), worst


def climb(attempt: Callable[[Rung | None, float], Plan], ladder: Sequence[Rung], max_wall_time: float) -> Plan:
    """Plan with `attempt(rung, seconds left)` on each rung of `ladder` in turn, each followed by its `finer` rung
    when its plan calls for one (on None once if the ladder is empty), until one verifies or the `max_wall_time` (s)
    of computation is spent; the first verified plan, else the best by `rank`, with the stats of all attempts
    (module docstring)."""
    if not ladder:
        return attempt(None, max_wall_time)
    tried: list[tuple[Rung, Plan]] = []
    skipped: list[str] = []

    def left() -> float:
        return max_wall_time - sum(p.stats.solve_time for _, p in tried)

    for rung in ladder:
        if tried and left() <= 0:
            break
        if _repeats(rung, tried):
            skipped.append(rung.name)
            continue
        tried.append((rung, attempt(rung, max(left(), 0.0))))
        if (next_rung := finer(*tried[-1])) is not None and left() > 0:
            tried.append((next_rung, attempt(next_rung, left())))
        if tried[-1][1].ok:
            break
    return _combined(tried, skipped)


def finer(rung: Rung, plan: Plan) -> Rung | None:
    """The rung re-solving `plan`'s motion on a finer grid (module docstring) when `plan`, planned on `rung`,
    is violated only where refinement rounds cannot help; None otherwise, and for a rung that was itself one."""
    if plan.status != "violated" or plan.verification.fixable or rung.refines is not None:
        return None
    cap = min(rung.max_iterations or FINER_ITERATIONS, FINER_ITERATIONS)
    return dataclasses.replace(rung, name=f"{rung.name}-finer", guess=None, seed=None, max_iterations=cap,
                               relaxed=False, refines=plan.trajectory)


def _repeats(rung: Rung, tried: list[tuple[Rung, Plan]]) -> bool:
    """Whether `rung` is an earlier rung with only another iteration cap, and that one stopped short of its cap
    (any status but iteration_limit): the solve would repeat itself."""
    def solve(r: Rung) -> Rung:
        return dataclasses.replace(r, name="", max_iterations=None)

    return any(solve(r) == solve(rung) and p.status != "iteration_limit" for r, p in tried)


def _combined(tried: list[tuple[Rung, Plan]], skipped: list[str]) -> Plan:
    """The best plan of `tried` (rung, plan) pairs, its stats summed over all of them (with the names of the
    `skipped` rungs) and its method and message naming its rung; its hint NO_PATH_HINT (through
    stats.extra["hint"]) if it failed and OMPL found no path."""
    rung, best = min(tried, key=lambda pair: rank(pair[1]))
    plans = [p for _, p in tried]
    stats = PlanStats(sum(p.stats.solve_time for p in plans), sum(p.stats.setup_time for p in plans),
                      sum(p.stats.iterations for p in plans), best.stats.rounds,
                      f"rung {rung.name}: {best.stats.solver_message}",
                      {**best.stats.extra, "rungs": [_rung_row(r, p) for r, p in tried], "skipped": skipped})
    if not best.ok and any(p.status == "no_path" for p in plans):
        stats.extra["hint"] = NO_PATH_HINT
    return dataclasses.replace(best, stats=stats, method={**best.method, "rung": rung.name})


def _rung_row(rung: Rung, plan: Plan) -> dict:
    """One rung's entry in stats.extra["rungs"]: name, status, computation time (s), iterations."""
    return {"rung": rung.name, "status": plan.status, "time_s": round(plan.stats.solve_time, 3),
            "iterations": plan.stats.iterations}
