"""The fallback ladder of the simultaneous planner: the rungs tried in order until one plan verifies.

A `Rung` is a small set of option overrides (initial guess and OMPL seed, knots, segments, an iteration cap per
solve), and `Rung.apply` is how it changes the options of the call (ocpkit.planner.options.SimultaneousOptions).
`climb` plans rung after rung within one wall-time budget and returns the first verified plan, else the best one
(`rank`), with every rung's name, status, time and iterations in `stats.rungs`. A rung that only lifts the
iteration cap of an earlier one is skipped (listed in `stats.skipped`) unless that one stopped at its cap or its
share of the time: it would repeat the same solve. An empty ladder plans once with the call's options (the
paper's single shot).

Why these rungs: the straight line verifies most problems within a hundred IPOPT iterations, and one that has not
converged by then mostly ends infeasible or at the iteration limit after many seconds, so the first rung is capped
(FIRST_ITERATIONS, per solve and for the rung's refinement rounds together): that cap is how the ladder leaves a
local infeasibility, a restoration phase, a t_f pinned at its upper bound, or a motion that keeps tunnelling
through a thin obstacle between check points round after round (MBM's cage) early. The other capped rungs keep
MAX_ITERATIONS_CAPPED. The OMPL +
TOPP-RA motion (collision-free by construction) is the better start in clutter, and another seed gives another
homotopy class when the first one is poor. The first two OMPL rungs solve on three pseudospectral segments of 6
intervals (19 points instead of 12 knots' 13): piecewise polynomials follow a path with corners, where one
polynomial of degree 12 leaves it between knots. Their path search is budgeted in configurations checked
(OMPL_CHECKS, the budget the random suite certifies room to pass with), so whether it finds a path does not depend
on the machine's speed; its edges are checked every OMPL_RESOLUTION rad, twice the seed's default spacing: the
path is only a start, which the solve and the dense verification make exact, and in MBM's cages the search with
the finer spacing took most of the budget. The search is RRTConnect, and LBKPIECE1 where RRTConnect has found no
path within a few seconds' checks (OMPL_PLANNER: ocpkit.planner.ompl_seed): in MBM's cages and shelves, and on the
Fetch, RRTConnect often took hundreds of thousands of checks or the whole budget. More knots resolve what a coarse
grid leaves violated. The
continuation rung solves the problem relaxed first (a softened margin, wider limits) and the real one from there.
The last rung is the uncapped single shot with whatever time is left, so the ladder never loses a plan the single
shot finds in time.

A straight line that runs with some sphere centre inside an obstacle box or cylinder starts the capped first rung
where some of its collision rows are flat (no gradient there): IPOPT then often spends the rung's
iterations and ends infeasible or at its cap. For such a problem `ordered` moves the rungs that start from the
line after the first OMPL rung, whose path starts clear of the obstacles.

The default budget, MAX_WALL_TIME, leaves room for the capped first rung and an OMPL rung on a hard problem
(MotionBenchMaker's shelves and cages: each 5-15 s with its set-up). A verified plan returns at once; the budget
is what a failure costs. A rung's last solve is verified after the rung's time is up, so each rung is given the
time left less the longest verification seen so far in the climb and less RESERVE_SHARE of the budget: the budget
bounds the verifications too, and the reserve covers what else runs past a rung's time (its last iteration, which
ends after the deadline it checks, a verification of a longer motion than any before it, a safety net's smoothing
and TOPP-RA timing before its first solve). A capped rung (one with an iteration cap) also gets at most RUNG_SHARE
of the budget: a solve that creeps towards its cap (a few hundred slow iterations on a large NLP) then ends by
time, not after the whole budget, so the safety net and another rung still get their turn. A ladder
that verifies nothing, where every OMPL rung found no path, ends `no_path`, with the configurations the last
search checked: where the obstacles leave no way through, that is the evidence, and no failed solve says more.

The safety nets (`Rung.safety_net`, one after each OMPL rung): where that rung found a path but its solve did not
verify, ompl-topp3 times the same path (reused, not searched again: ocpkit.planner.ompl_seed) along its fixed
geometry under every limit, a motion that usually verifies, slower than an optimal one. A verified net ends the
climb like any verified rung, its rung named in the plan: the rungs after it seldom verify where the OMPL rung
before them did not, and waiting for them costs the rest of the budget for a plan already certified. A net times
its path on NET_SEGMENTS pseudospectral segments of NET_KNOTS intervals, not on the call's grid: along a path
with several sharp turns the time-optimal s(t) slows down before each, which one polynomial over the whole
motion (the default 12 knots) cannot follow: on that grid such a timing can end infeasible with t_f at its upper
bound where TOPP-RA times the same path well within it.

An OMPL rung's first solve keeps a pace (PACE_ITERATIONS): it stops as soon as that many iterations, at the pace
of its iterations so far, would not end within the rung's time. That many is what a rung's solves may take in
all on a plan that verifies: its first solve up to the rung's cap, and refinement rounds after it nearly as many
again (most take far fewer; a large NLP, the Fetch's, can run the cap without verifying): a rung that could not do
that much work in its time would end at its time limit, most often unverified. Where an iteration is slow (a large
NLP: the Fetch's thousands of self-collision rows) it gives that time to the safety net, which times the same
path, instead (no screening rebuild follows a solve stopped by time: ocpkit.planner.simultaneous, and its motion
is not verified: ocpkit.planner.refinement.paced_out); a solve whose iterations are fast enough never notices the
pace.

A rung whose plan fails only checks that no refinement round can fix (the dynamics residual between knots, with
every path constraint met: `Verification.fixable` is False) is followed at once by its `finer` rung: the same
options on a finer grid (`finer_grid`: one more pseudospectral segment; half as many intervals again for a local
transcription), warm-started from that plan's motion. The residual is the interpolation error of the grid, and
a motion that already meets every path constraint often converges on the finer one within a few dozen iterations;
the size of the residual does not tell when, so the rung is capped at FINER_ITERATIONS to leave the later rungs
their time.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ocpkit.formats.trajectory import Trajectory
from ocpkit.planner.ompl_seed import OMPL_PLANNER
from ocpkit.result import Plan, RungRow

if TYPE_CHECKING:
    from ocpkit.planner.options import SimultaneousOptions

MAX_ITERATIONS_CAPPED = 300  # IPOPT iterations per solve of a capped rung
FIRST_ITERATIONS = 100  # IPOPT iterations per solve of the first rung, from the call's guess
MAX_WALL_TIME = 30.0  # s of computation and set-up for the whole ladder, the simultaneous planner's default
OMPL_CHECKS = 1_500_000  # configurations an OMPL rung may check for its path
OMPL_RESOLUTION = 0.02  # rad between the configurations an OMPL rung checks along an edge (the seed's default: 0.01)
FINER_ITERATIONS = 50  # IPOPT iterations per solve of a finer rung; no refinement round starts after that many
PACE_ITERATIONS = 550  # an OMPL rung's first solve stops once this many iterations at its pace would overrun it
RUNG_SHARE = 0.5  # of the budget: the most a capped rung may take
RESERVE_SHARE = 0.03  # of the budget: held back from every rung for what runs past its time (module docstring)
NET_KNOTS, NET_SEGMENTS = 8, 4  # a safety net's timing grid: 4 pseudospectral segments of 8 intervals (docstring)


@dataclass(frozen=True)
class Rung:
    """Option overrides of one attempt: `guess` ("line", "ompl" or None for the call's), OMPL `seed`, `knots`
    (None: the call's), pseudospectral `segments` of `knots` intervals each (None: the call's; a transcription
    without segments keeps the call's knots too), `max_iterations` per solve (None: the solver's; no
    refinement round starts once the rung's solves have used that many),
    `relaxed`: a continuation, solving the problem relaxed (ocpkit.planner.refinement.RELAXED) first to warm-start
    the real one, `refines`: a motion to re-solve on a finer grid than the rung's own (`finer`), its guess
    instead of `guess`, and `pace`: the rung's first solve stops as soon as that many iterations at its pace
    would not end within the rung's time (PreparedSolver.solve). An "ompl" rung's path search stops after
    OMPL_CHECKS configurations checked or when the rung's time is up. A `safety_net` rung (guess "ompl") plans
    with ompl-topp3 instead, on the OMPL path of its `seed` and on its own grid (`knots`, `segments`: module
    docstring); the simultaneous planner runs it with the options `apply` gives."""

    name: str
    guess: str | None = None
    seed: int | None = None
    knots: int | None = None
    segments: int | None = None
    max_iterations: int | None = None
    relaxed: bool = False
    refines: Trajectory | None = field(default=None, compare=False, repr=False)
    safety_net: bool = False
    pace: int | None = None

    def apply(self, options: SimultaneousOptions, left: float) -> SimultaneousOptions:
        """`options` with this rung's overrides. A rung's guess comes with its own options instead of the call's:
        its seed, and no fallback to the straight line (a rung without a start of its own ends `no_path` instead
        of repeating the line); an "ompl" rung's search stops after OMPL_CHECKS configurations or the `left`
        seconds the rung may take. `knots` and `segments` apply to a pseudospectral transcription; one without
        segments keeps the call's grid on a rung with segments. The call's own max_iterations wins over the
        rung's cap, which caps each solve and, as the iteration budget, the rung's refinement rounds and
        rebuilds. A rung that `refines` a motion starts from it on the finer grid (`finer_grid`)."""
        changes: dict = {}
        if self.guess is not None:
            guess_options: dict = {"fallback": False}
            if self.seed is not None:
                guess_options["seed"] = self.seed
            if self.guess == "ompl":
                guess_options.update(planner_name=OMPL_PLANNER, max_checks=OMPL_CHECKS, planning_time=left,
                                     resolution=OMPL_RESOLUTION)
            changes.update(guess=self.guess, guess_options=guess_options)
        if self.segments is None or options.pseudospectral():
            if self.knots is not None:
                changes["knots"] = self.knots
            if self.segments is not None:
                changes["transcription_options"] = {**options.transcription_options, "segments": self.segments}
        if self.max_iterations is not None and "max_iterations" not in options.solver_options:
            changes.update(solver_options={**options.solver_options, "max_iterations": self.max_iterations},
                           iteration_budget=self.max_iterations)
        if self.relaxed:
            changes["relaxed"] = True
        if self.pace is not None:
            changes["pace"] = self.pace
        changed = dataclasses.replace(options, **changes)
        if self.refines is not None:
            changed = dataclasses.replace(finer_grid(changed), refines=self.refines)
        return changed


def finer_grid(options: SimultaneousOptions) -> SimultaneousOptions:
    """`options` on a finer grid: one more segment of a pseudospectral transcription, else half as many intervals
    again (rounded up)."""
    if options.pseudospectral():
        segments = options.transcription_options.get("segments", 1) + 1
        return dataclasses.replace(options, transcription_options={**options.transcription_options,
                                                                   "segments": segments})
    return dataclasses.replace(options, knots=options.knots + (options.knots + 1) // 2)


DEFAULT_LADDER: tuple[Rung, ...] = (
    Rung("first", max_iterations=FIRST_ITERATIONS),
    Rung("ompl-0-segments-3", guess="ompl", seed=0, knots=6, segments=3, max_iterations=MAX_ITERATIONS_CAPPED,
         pace=PACE_ITERATIONS),
    Rung("ompl-0-topp3", guess="ompl", seed=0, knots=NET_KNOTS, segments=NET_SEGMENTS, safety_net=True),
    Rung("ompl-1-segments-3", guess="ompl", seed=1, knots=6, segments=3, max_iterations=MAX_ITERATIONS_CAPPED,
         pace=PACE_ITERATIONS),
    Rung("ompl-1-topp3", guess="ompl", seed=1, knots=NET_KNOTS, segments=NET_SEGMENTS, safety_net=True),
    Rung("ompl-2-knots-16", guess="ompl", seed=2, knots=16, max_iterations=MAX_ITERATIONS_CAPPED,
         pace=PACE_ITERATIONS),
    Rung("ompl-2-topp3", guess="ompl", seed=2, knots=NET_KNOTS, segments=NET_SEGMENTS, safety_net=True),
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


def ordered(ladder: Sequence[Rung], line_buried: bool) -> tuple[Rung, ...]:
    """`ladder` as it is, or, when the straight line has a sphere centre inside an obstacle box or cylinder somewhere
    (`line_buried`), with the rungs before the first OMPL rung that start from the call's guess (`guess` None, not
    relaxed) moved after that rung and the safety nets that follow it (module docstring)."""
    first = next((k for k, rung in enumerate(ladder) if rung.guess == "ompl"), None)
    if not line_buried or first is None:
        return tuple(ladder)
    end = first + 1  # the OMPL rung with the safety nets right after it
    while end < len(ladder) and ladder[end].safety_net:
        end += 1
    moved = [rung for rung in ladder[:first] if rung.guess is None and not rung.relaxed]
    kept = [rung for rung in ladder[:first] if rung not in moved]
    return (*kept, *ladder[first:end], *moved, *ladder[end:])


def rank(plan: Plan) -> tuple[int, float]:
    """Sort key of a plan, smaller is better: its status by STATUS_ORDER, then its largest failed check's worst
    value (the check's unit: relative for limits, m for contact; inf for a motion that was not verified)."""
    status = STATUS_ORDER.index(plan.status) if plan.status in STATUS_ORDER else len(STATUS_ORDER)
    return status, plan.verification.worst_failure


def climb(attempt: Callable[[Rung | None, float], Plan], ladder: Sequence[Rung], max_wall_time: float) -> Plan:
    """Plan with `attempt(rung, seconds it may take)` on each rung of `ladder` in turn, each followed by its `finer`
    rung when its plan calls for one (on None once if the ladder is empty), until one verifies or the
    `max_wall_time` (s) of computation and set-up is spent (no rung starts with less time left than
    the last rung's set-up took); that plan, else the best by `rank`, with the stats of all attempts (module
    docstring). A rung may take the time left, less the longest verification of the rungs before it (its last
    solve's verification runs after its time is up) and RESERVE_SHARE of `max_wall_time`, a capped one at most
    RUNG_SHARE of `max_wall_time`. A safety net runs only where an OMPL rung of its seed found a path."""
    if not ladder:
        return attempt(None, max_wall_time)
    tried: list[tuple[Rung, Plan]] = []
    skipped: list[str] = []
    share, reserve = RUNG_SHARE * max_wall_time, RESERVE_SHARE * max_wall_time

    def left() -> float:  # less the longest verification so far (a rung's last one runs after its time is up)
        spent = sum(p.stats.solve_time + p.stats.setup_time for _, p in tried)
        verifying = max((r.verify for _, p in tried for r in p.stats.timing.rounds), default=0.0)
        return max_wall_time - spent - verifying - reserve

    def room() -> bool:  # time for a build as long as the last one: a rung that cannot build only overruns
        return not tried or left() > tried[-1][1].stats.setup_time

    def allowed(rung: Rung) -> float:  # the seconds `rung` may take
        return max(min(left(), share) if rung.max_iterations is not None else left(), 0.0)

    for rung in ladder:
        if not room():
            break
        if _repeats(rung, tried) or (rung.safety_net and not _path_found(rung.seed, tried)):
            skipped.append(rung.name)
            continue
        tried.append((rung, attempt(rung, allowed(rung))))
        if (next_rung := finer(*tried[-1])) is not None and room():
            tried.append((next_rung, attempt(next_rung, allowed(next_rung))))
        if tried[-1][1].ok:
            break
    return _combined(tried, skipped)


def finer(rung: Rung, plan: Plan) -> Rung | None:
    """The rung re-solving `plan`'s motion on a finer grid (module docstring) when `plan`, planned on `rung`,
    is violated only where refinement rounds cannot help; None otherwise, and for a rung that was itself one."""
    if plan.status != "violated" or plan.verification.fixable or rung.refines is not None or rung.safety_net:
        return None
    cap = min(rung.max_iterations or FINER_ITERATIONS, FINER_ITERATIONS)
    return dataclasses.replace(rung, name=f"{rung.name}-finer", guess=None, seed=None, max_iterations=cap,
                               relaxed=False, refines=plan.trajectory)


def _repeats(rung: Rung, tried: list[tuple[Rung, Plan]]) -> bool:
    """Whether `rung` is an earlier rung with only another iteration cap, and that one stopped short of its cap
    and of its share of the time (any status but iteration_limit and time_limit): the solve would repeat itself."""
    def solve(r: Rung) -> Rung:
        return dataclasses.replace(r, name="", max_iterations=None)

    return any(solve(r) == solve(rung) and p.status not in ("iteration_limit", "time_limit") for r, p in tried)


def _path_found(seed: int | None, tried: list[tuple[Rung, Plan]]) -> bool:
    """Whether an OMPL rung of `seed` in `tried` found a path (its plan is not `no_path`)."""
    return any(r.guess == "ompl" and r.seed == seed and not r.safety_net and p.status != "no_path" for r, p in tried)


def _combined(tried: list[tuple[Rung, Plan]], skipped: list[str]) -> Plan:
    """The best plan of `tried` (rung, plan) pairs (by `rank`, a safety net's last among equals), its times and
    iterations summed over all of them, the rungs tried and the names of the `skipped` ones in its stats, and its
    method and message naming its rung. When none verified and every OMPL rung's search found no path, the last
    one's `no_path` plan instead (its message: the checks the search spent), with the hint NO_PATH_HINT."""
    rung, best = min(tried, key=lambda pair: (rank(pair[1]), pair[0].safety_net))
    plans = [p for _, p in tried]
    searched = [(r, p) for r, p in tried if r.guess == "ompl" and not r.safety_net]
    no_path = not best.ok and bool(searched) and all(p.status == "no_path" for _, p in searched)
    if no_path:  # the failed searches are the evidence a failed solve is not
        rung, best = searched[-1]
    stats = dataclasses.replace(
        best.stats, solve_time=sum(p.stats.solve_time for p in plans),
        setup_time=sum(p.stats.setup_time for p in plans), iterations=sum(p.stats.iterations for p in plans),
        solver_message=f"rung {rung.name}: {best.stats.solver_message}",
        rungs=tuple(_rung_row(r, p) for r, p in tried), skipped=tuple(skipped),
        hint=NO_PATH_HINT if no_path else best.stats.hint)
    return dataclasses.replace(best, stats=stats, method={**best.method, "rung": rung.name})


def _rung_row(rung: Rung, plan: Plan) -> RungRow:
    """One rung's row in stats.rungs: name, status, computation time (s, to the ms), iterations."""
    return RungRow(rung.name, plan.status, round(plan.stats.solve_time, 3), plan.stats.iterations)
