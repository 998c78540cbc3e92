"""`ompl-topp3`: the decomposition baseline held to the simultaneous planner's limits and cost.

1. The OMPL path exactly as `ompl-toppra` finds it (ocpkit.planner.ompl_seed: same validity checker, planner,
   seed and shortcutting).
2. Made smooth to its third derivative: the natural quintic spline in the chord length (`PathSpline`), re-checked
   densely and repaired by the seed's `smooth_path` (half the margin every resolution/4 rad, and the joint
   position limits, which the timing cannot change). Its parameter is normalised: q = p(s), s ∈ [0, 1].
3. The timing along that fixed path as an optimal control problem in s (`PathTimingOCP`): s(t) from rest at 0 to
   rest at 1, q̇ = p′ṡ, q̈ = p′s̈ + p″ṡ², q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³, τ = RNEA(q, q̇, q̈) + friction; the
   velocity, torque and torque-rate limits and the cost t_f + μ∫q⃛ᵀQq⃛ dt of the simultaneous planner. It is
   transcribed and solved by ocpkit's own transcriptions and solvers (the same arguments as
   `plan_simultaneous`: transcription, knots, dynamics, solver, ...), solved with the same refinement rounds,
   warm-started from the TOPP-RA profile of the same path (`time_optimal`; where TOPP-RA cannot time it, from
   s moving at constant speed over time.guess, `PathTimingOCP.guess`). The path enters the NLP as
   parameters, its pieces split up to a multiple of PIECES_STEP, so paths share one build (the build cache's,
   like the simultaneous planner's shapes) and its one-time set-up is not computation.
   Collision is not a constraint of the timing: the path is fixed and was checked; `verify` checks it again.

The motion returned is q(t) = p(s(t)) at every sample, so it stays on the checked path by construction.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any, NamedTuple

import numpy as np

from ocpkit.baselines.ompl_toppra import CONTACT_HINT, NO_PATH_HINT
from ocpkit.dynamics import Dynamics
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.path_spline import PathSpline
from ocpkit.planner.build_cache import build
from ocpkit.planner.ompl_seed import (MAX_STEP, OMPL_PLANNER, check_ompl_planner, hold, import_backends,
                                      no_path_message, ompl_path, planning_space, smooth_path, time_optimal)
from ocpkit.planner.refinement import DEFAULT_ROUNDS, Refined, solve_refined
from ocpkit.problem import Problem
from ocpkit.result import Hints, PathStats, Plan, Timing, finish
from ocpkit.solvers import SolverStatus
from ocpkit.transcription.ocp import PathTimingOCP
from ocpkit.verify import GEOMETRY_CHECKS, SCALED_LIMITS

TOPP3_HINTS = Hints(
    stopped={"no_path": NO_PATH_HINT,
             "infeasible": "the timing is locally infeasible along this path: give it more segments "
                           "(transcription_options segments; the ladder's nets use 4 segments of 8 intervals) or try "
                           "another seed (another path)",
             "iteration_limit": "the timing solve reached its iteration limit: raise max_iterations "
                                "(solver_options) or try another seed (another path)",
             "time_limit": "the timing solve reached max_wall_time: raise it"},
    violated=((("motion_time",), "the timing solve diverged: try another solver"),
              (("dynamics", "qd_consistency", "qdd_consistency"),
               "the interpolant does not resolve the dynamics between knots: use more knots or segments"),
              (GEOMETRY_CHECKS, CONTACT_HINT),
              (("position", *SCALED_LIMITS), "a limit is exceeded between the timing's check times: use more knots "
                                            "or refinements"),
              (("boundary",), "the motion does not start and end at rest: check the timing's boundary conditions")),
    failed="try another solver or seed")
"""What `ompl-topp3` can change: its path search and smoothing, and its timing OCP's grid and solver."""

PIECES_STEP = 4  # the path's polynomial pieces are rounded up to a multiple of this: one NLP per multiple
TIMING_CONSTRAINTS = ("state-limits", "torque", "torque-rate")
"""The simultaneous planner's limits; collision is left to the path (fixed and checked) and to `verify`."""


class ToppraPath:
    """A PathSpline as toppra's geometric path on s ∈ [0, 1] (orders 0 to 2; the interface of toppra's
    AbstractGeometricPath, which toppra reads by duck typing)."""

    def __init__(self, spline: PathSpline) -> None:
        self.spline = spline

    def __call__(self, s: Any, order: int = 0) -> np.ndarray:
        values = self.spline.values(np.atleast_1d(np.asarray(s, dtype=float)))[order]
        return values[0] if np.isscalar(s) else values

    @property
    def dof(self) -> int:
        return self.spline.n

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([0.0, 1.0])

    @property
    def waypoints(self) -> tuple[np.ndarray, np.ndarray]:
        return self.spline.breaks, self.spline.values(self.spline.breaks)[0]


def toppra_profile(motion: Any) -> Trajectory:
    """TOPP-RA's s(t) (toppra's ParametrizeConstAccel `motion`: constant s̈ between its grid points) as a chain
    trajectory: s, ṡ, s̈ in the Samples' q, qd, qdd (m, 1); torques unset (zero)."""
    times = motion._ts  # the grid points' times; toppra keeps them on the parametrizer

    def profile(t: np.ndarray) -> Samples:
        t = np.clip(np.asarray(t, dtype=float), times[0], times[-1])
        s, sd, sdd = motion._eval_params(t)
        zeros = np.zeros((len(t), 1))
        return Samples(t, s[:, None], sd[:, None], sdd[:, None], zeros, zeros)

    return Trajectory(profile(times), profile)


class TimedPath(NamedTuple):
    """The timing of one path: the refined solve, the set-up of its build (s), how it started, TOPP-RA's t_f (s;
    NaN without a TOPP-RA profile)."""

    refined: Refined
    setup_time: float
    start: str
    toppra_tf: float


def time_path(problem: Problem, smooth: PathSpline, transcription: str = "chebyshev", knots: int = 12,
              dynamics: str | Dynamics = "casadi-rnea", solver: str = "ipopt", refinements: int = DEFAULT_ROUNDS,
              transcription_options: dict | None = None, solver_options: dict | None = None,
              dynamics_options: dict | None = None, max_wall_time: float = 60.0, grid_points: int = 1000
              ) -> TimedPath:
    """The optimal timing of the fixed path `smooth` (from problem.start to problem.goal) under `problem`'s limits
    and cost (the module docstring's step 3; options as for `plan_ompl_topp3`), within `max_wall_time` (s) from
    the call: the TOPP-RA warm start, the build and the solves."""
    deadline = time.perf_counter() + max_wall_time
    path = smooth.split(-(-smooth.intervals // PIECES_STEP) * PIECES_STEP)
    timed = time_optimal(problem, ToppraPath(path), grid_points)
    ocp = PathTimingOCP(problem.robot, path)
    made = build(problem, transcription, knots, dynamics, solver, TIMING_CONSTRAINTS, transcription_options,
                 solver_options, dynamics_options, ocp=ocp)
    discretization = made.discretization.with_ocp(ocp)
    if timed is None:
        w, start, toppra_tf = discretization.initial_guess(problem), "from s at constant speed (no TOPP-RA profile)", \
            np.nan
    else:
        w, start, toppra_tf = discretization.encode(toppra_profile(timed[0])), "from TOPP-RA's profile", \
            float(timed[1][-1])
    refined = solve_refined(discretization, made.solver, problem, w, refinements, deadline, limits_first=True)
    return TimedPath(refined, made.setup_time, start, toppra_tf)


def plan_ompl_topp3(problem: Problem, transcription: str = "chebyshev", knots: int = 12,
                    dynamics: str | Dynamics = "casadi-rnea", solver: str = "ipopt",
                    refinements: int = DEFAULT_ROUNDS, transcription_options: dict | None = None,
                    solver_options: dict | None = None, dynamics_options: dict | None = None,
                    max_wall_time: float = 60.0, planner_name: str = OMPL_PLANNER, planning_time: float = 1.0,
                    seed: int = 0, resolution: float = 0.01, grid_points: int = 1000, margin: float = 0.01,
                    max_checks: int | None = None, max_step: float | None = MAX_STEP) -> Plan:
    """Plan `problem` by OMPL path, quintic smoothing and optimal timing along the path (module docstring).

    The timing OCP's options are `plan_simultaneous`'s (`transcription`, `knots`, `dynamics`, `solver`,
    `refinements`, their option dicts; `max_wall_time` (s) bounds the whole plan from the call, set-up
    included, the search by `planning_time` too); the path's are `plan_ompl_toppra`'s
    (`planner_name`, `planning_time`, `seed`, `resolution`, `margin`, `max_checks`, `max_step`; `grid_points` for the
    TOPP-RA warm start).

    Status: the solver's when it did not converge, else "verified" or "violated"; "no_path" (OMPL found no exact
    path) holds the start."""
    check_ompl_planner(planner_name)
    began = time.perf_counter()
    method = {"planner": "ompl-topp3", "path_planner": planner_name, "transcription": transcription, "knots": knots,
              "dynamics": dynamics if isinstance(dynamics, str) else dynamics.name, "solver": solver}
    if np.array_equal(problem.start, problem.goal):
        return finish(problem, hold(problem), None, method, began, message="the goal is the start: hold still",
                      hints=TOPP3_HINTS)
    setup = import_backends()
    free = planning_space(problem, margin)
    found = ompl_path(problem, free, planner_name, planning_time, seed, resolution, max_checks, max_step)
    searched = Timing(path_search=found.path_time, simplify=found.simplify_time)
    if found.waypoints is None:
        return finish(problem, hold(problem), "no_path", method, began, setup_time=setup, timing=searched,
                      path=PathStats(free.checks, 0, 0, free.margin), found=False,
                      message=f"{no_path_message(planner_name, planning_time, free)}; the plan holds the start",
                      hints=TOPP3_HINTS)
    smoothing = time.perf_counter()
    smooth, rounds = smooth_path(found.waypoints, free, resolution, fit=PathSpline.fit, within_limits=True)
    smoothed = time.perf_counter()
    timing = time_path(problem, smooth, transcription, knots, dynamics, solver, refinements, transcription_options,
                       solver_options, dynamics_options, max_wall_time - (time.perf_counter() - began), grid_points)
    refined, result = timing.refined, timing.refined.result
    spent = dataclasses.replace(searched, smooth=smoothed - smoothing, rounds=refined.timing)
    stopped = None if result.status == SolverStatus.CONVERGED else result.status.value
    message = (f"{planner_name}: {len(found.waypoints)} waypoints, {rounds} repair rounds; timing {timing.start}: "
               f"{result.message}")
    return finish(problem, refined.trajectory, stopped, method, began, setup_time=setup + timing.setup_time,
                  iterations=refined.iterations, rounds=refined.rounds, message=message, timing=spent,
                  path=PathStats(free.checks, len(found.waypoints), rounds, free.margin, timing.toppra_tf,
                                 found.searches),
                  verification=refined.verification, hints=TOPP3_HINTS)
