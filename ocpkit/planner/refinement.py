"""Refinement: re-solve where the dense verification found a path constraint violated between check times.

After a converged solve whose trajectory fails `verify`, the next round moves the adaptive check slots to the
violation times (newest first), grows the clearance margin by PENETRATION_FACTOR times the deepest contact (at
least MIN_MARGIN_STEP), shrinks the velocity, torque and torque-rate limits the NLP uses by the excess found plus
LIMIT_BACKOFF (to no less than MIN_SHRINK of them in one round), and re-solves warm-started from the last
solution, all through NLP parameters (no rebuild). A check at the worst time alone rarely suffices: with the
constraint active, the interpolant then dips just beside the new check.

An NLP without contact rows (the timing of a fixed path: ocpkit.baselines.ompl_topp3) has its rounds' motions
verified limits first (`limits_first`): no round can change what they touch, so the contact check, the costly
part on a robot with many spheres, waits for a motion within the limits, and a contact found then ends the
rounds. Where the NLP has contact rows every motion is verified in full, so that one round fixes a limit and a
contact found together. The motion returned always has its complete verification.

Every solve's w is checked against its variable bounds (slack: `solvers.bound_slack`): an
iterate outside them (a diverged solver) ends the plan as `failed`, the message naming the variable. All solves
share one wall-time `deadline`: each gets the time that is left, and no round starts after it.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ocpkit.formats.trajectory import Trajectory
from ocpkit.nlp import Layout, Refinement
from ocpkit.problem import Problem
from ocpkit.result import SolveTiming
from ocpkit.solvers import PreparedSolver, SolverResult, SolverStatus, bound_slack
from ocpkit.transcription import Discretization
from ocpkit.verify import Verification, verify

DEFAULT_ROUNDS = 5  # refinement rounds after the first solve, at most
MIN_MARGIN_STEP = 0.005  # m
PENETRATION_FACTOR = 2.0
LIMIT_BACKOFF = 0.005  # fraction of each limit
MIN_SHRINK = 0.5  # one round never takes more than half of a limit away
RELAXED = Refinement(extra_margin=-0.02, limit_scale=1.5)  # a continuation's first problem: the clearance
# margin 2 cm smaller (spheres may touch) and half as much again of every velocity, torque and torque-rate limit
NAMED_PARTS = ("tf", "q", "qd", "qdd", "u", "s", "sd", "sdd")  # parts of w named in out-of-bounds messages


STOPPED_BY_PACE = "its solve stopped by time, at the pace its rung keeps (ocpkit.planner.ladder)"
"""Why a motion is not verified (`paced_out`)."""

CALLBACKS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l", "callback_fun", "total")
"""What a CasADi solver's stats time (t_wall_<kind>): the NLP function and derivative evaluations by kind, the
iteration callback (Python), and the whole solver call."""


@dataclass(frozen=True)
class Refined:
    """The last solve's result, its trajectory and verification, the iterations of all solves, the
    refinement rounds taken, and per solve (first, then each round) where its time went (`round_timing`)."""

    result: SolverResult
    trajectory: Trajectory
    verification: Verification
    iterations: int
    rounds: int
    timing: tuple[SolveTiming, ...] = ()


def round_timing(result: SolverResult, verify_time: float) -> SolveTiming:
    """Where one solve's time went: the solver call's wall time, the verification's `verify_time` (s), the
    iterations, and the solver's own wall time (s) per NLP evaluation kind (CALLBACKS, from its stats, where it
    reports them)."""
    stats = result.stats or {}
    callbacks = {kind: float(stats[f"t_wall_{kind}"]) for kind in CALLBACKS if f"t_wall_{kind}" in stats}
    return SolveTiming(result.wall_time, verify_time, result.iterations, callbacks)


def next_refinement(previous: Refinement, verification: Verification, tf: float) -> Refinement | None:
    """The refinement after a converged solve with motion time tf (s) verified as `verification`; None when there
    is nothing to fix by one (verified, or no violation between check times)."""
    if verification.ok or not verification.fixable:
        return None
    fresh = verification.violation_times / tf
    excess = verification.limit_excess
    shrink = max(1.0 - excess - LIMIT_BACKOFF, MIN_SHRINK) if excess > 0 else 1.0
    return Refinement(np.concatenate([fresh, previous.check_fractions]),  # the newest take the slots
                      previous.extra_margin + margin_step(verification.penetration), previous.limit_scale * shrink)


def margin_step(penetration: float) -> float:
    """Extra clearance margin (m) after a round that found spheres `penetration` m deep in contact."""
    return max(PENETRATION_FACTOR * penetration, MIN_MARGIN_STEP) if penetration > 0 else 0.0


def paced_out(result: SolverResult, pace: int | None, taken: int) -> bool:
    """Whether `result`, a solve after `taken` refinement rounds, is a first solve with a `pace` that stopped by
    time. Its motion is not verified: a solve stopped by time is never `verified` whatever its checks say, its
    rung hands the rest of its time on (ocpkit.planner.ladder: the safety net times the same path), and on a large
    NLP, where the pace stops a solve, a dense verification takes as long as a few of its iterations."""
    return pace is not None and taken == 0 and result.status == SolverStatus.TIME_LIMIT


def solve_refined(discretization: Discretization, solver: PreparedSolver, problem: Problem, guess: np.ndarray,
                  rounds: int = DEFAULT_ROUNDS, deadline: float = np.inf, relaxed: Refinement | None = None,
                  iteration_budget: float = np.inf,
                  lacking: Callable[[Trajectory], bool] | None = None, pace: int | None = None,
                  limits_first: bool = False) -> Refined:
    """Solve `problem` on `discretization` from `guess`, verify, and refine for at most `rounds` rounds, all
    before `deadline` (time.perf_counter s); no round starts once the solves have used `iteration_budget`
    iterations, nor once `lacking` says an unverified trajectory needs rows this NLP does not have (screening:
    the caller rebuilds instead). With `relaxed` (continuation), a first solve of the problem
    relaxed so (e.g. RELAXED: wider limits, a softened margin) warm-starts the real one, whatever its status.
    `pace` is the first solve's (PreparedSolver.solve): the rounds after it start near a solution. A first solve
    stopped by time under a pace is not verified (`paced_out`). `limits_first`: the NLP has no contact rows
    (module docstring)."""
    refinement, iterations, taken, timing = Refinement(), 0, 0, []
    if relaxed is not None:
        bounds = discretization.bounds(problem, relaxed)
        easier = solver.solve(guess, discretization.parameters(problem, relaxed), bounds,
                              max_wall_time=max(deadline - time.perf_counter(), 0.0))
        guess, iterations = np.clip(easier.w, *discretization.bounds(problem, refinement)), easier.iterations
        timing.append(round_timing(easier, 0.0))
    while True:
        bounds = discretization.bounds(problem, refinement)
        result = solver.solve(guess, discretization.parameters(problem, refinement), bounds,
                              max_wall_time=max(deadline - time.perf_counter(), 0.0),
                              pace=pace if taken == 0 else None)
        result = checked(result, discretization.nlp.variables, bounds)
        iterations += result.iterations
        trajectory = discretization.decode(result.w)
        verified = time.perf_counter()
        verification = Verification.not_run(STOPPED_BY_PACE) if paced_out(result, pace, taken) \
            else verify(problem, trajectory, limits_first=limits_first)
        # without contact rows, a motion verified in full is within the limits: what else fails, no round fixes
        following = None if limits_first and verification.contact_checked \
            else next_refinement(refinement, verification, trajectory.tf)
        if following is not None and result.status == SolverStatus.CONVERGED and time.perf_counter() > deadline:
            result = dataclasses.replace(result, status=SolverStatus.TIME_LIMIT,
                                         message=f"wall-time limit reached before refinement round {taken + 1}")
        last = following is None or result.status != SolverStatus.CONVERGED or taken >= rounds \
            or iterations >= iteration_budget or (lacking is not None and lacking(trajectory))
        if last and not verification.contact_checked:  # the answer's verification is complete
            verification = verify(problem, trajectory)
        timing.append(round_timing(result, time.perf_counter() - verified))
        if last:
            return Refined(result, trajectory, verification, iterations, taken, tuple(timing))
        refinement, guess, taken = following, discretization.relifted(result.w, following), taken + 1


def checked(result: SolverResult, layout: Layout, bounds: tuple[np.ndarray, np.ndarray]) -> SolverResult:
    """`result`, or a `failed` one naming the worst variable of its w outside `bounds` (lbx, ubx) (n_w,)."""
    lbx, ubx = bounds
    outside = np.nan_to_num(np.maximum(lbx - result.w, result.w - ubx) / bound_slack(lbx, ubx), nan=np.inf)
    worst = int(np.argmax(outside))
    if outside[worst] <= 1.0:
        return result
    name = _variable_name(layout, worst)
    unit = " s" if name == "t_f" else ""
    where = f"{name} = {result.w[worst]:.6g}{unit} outside [{lbx[worst]:.6g}, {ubx[worst]:.6g}]{unit}"
    return dataclasses.replace(result, status=SolverStatus.FAILED,
                               message=f"iterate outside its bounds, {where}; solver: {result.message}")


def _variable_name(layout: Layout, position: int) -> str:
    """The name of entry `position` of w: t_f, or e.g. "qd[knot 3, joint 2]" (1-based joint), else "w[i]"."""
    for name in NAMED_PARTS:
        if name in layout and position in layout.index(name):
            index = np.argwhere(layout.index(name) == position)[0]
            if name == "tf":
                return "t_f"
            return f"{name}[knot {index[0]}, joint {index[-1] + 1}]" if len(index) == 2 else f"{name}[{index[0]}]"
    return f"w[{position}]"
