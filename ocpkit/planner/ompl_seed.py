"""The OMPL seed: an OMPL joint-space path, made smooth, then timed by TOPP-RA: a timed motion, not verified.

The path–velocity decomposition baseline (ocpkit.baselines.ompl_toppra) verifies this motion as its plan, the
simultaneous planner's "ompl" guess (ocpkit.planner.guesses) starts from it, and ompl-topp3 takes its path. Each
step is one function below, `ompl_seed` runs them in turn:

1. `FreeSpace`: OMPL's validity test is the verifier's own collision model (`geometry.clearances`: robot
   spheres against each other, the obstacles and the workspace box), asked in compiled C
   (`planner.sphere_check`; coal's test in C++, `geometry.coal_check`, where nothing compiles): a configuration
   is valid iff every clearance is ≥ `margin` (m, 0.01 like the transcriptions' default).
   The joint limits are the state-space bounds.
2. `ompl_path`: RRTConnect (or RRT*, BIT*, PRM, LBKPIECE1, or RRTConnect then LBKPIECE1) in joint space, its slow
   joints' coordinates scaled by their velocity limits (`JointSpace`, `time_scale`): OMPL's distances, and so its
   nearest neighbours and shortcuts, count a slow joint's move by the time it takes, not its radians. A straight
   segment is checked, batched, at configurations at most `resolution` rad apart (Euclidean over the joints). An RRT
   extends at most `max_step` (MAX_STEP) at a time, in OMPL's coordinates: rad of a typical joint. OMPL's own
   default, a fifth of the box's diagonal, is several radians on a 6- or 7-joint arm, and such long extensions into
   a cage or a shelf mostly fail. "rrtconnect-lbkpiece" keeps RRTConnect's paths, the shortest of these before
   simplification, where it finds one within STAGE_CHECKS configurations checked, and otherwise goes on with
   LBKPIECE1. That one is lazy: it grows its trees without checking and checks only the edges of a candidate path,
   so in narrow passages (a shelf, a cage), where most of RRTConnect's extensions collide, it needs far fewer
   checks. OMPL's PathSimplifier then shortens the path until it stops improving. The last FOUND_PATHS paths found
   are kept: a search of the same problem object with the same options, budgeted in checks, returns its path again
   without searching (the simultaneous planner's ladder times the path of its OMPL rung with ompl-topp3:
   ocpkit.planner.ladder).
3. `smooth_path`: a cubic spline through the waypoints, parametrised by chord length (rad), with zero
   tangent at both ends, re-checked every resolution/4 rad against half the margin. Where it cuts into an
   obstacle, the midpoints of the straight segments there become waypoints (at most `REPAIR_ROUNDS` rounds).
4. `time_optimal`: TOPP-RA on `grid_points` path points, with joint velocity limits and joint torque limits
   tau = rnea(q, qd, qdd) + friction(qd).
5. `PathMotion`: the resulting trajectory q(t) = path(s(t)), and the torque it takes.

Choices and what they cost, stated plainly:

- Zero end tangents ('clamped'). Along a path, qdd = q'(s) s̈ + q''(s) ṡ². The problem asks for rest at both
  ends, qd = qdd = 0, and a time-optimal s̈ is not zero at the ends. So only a path with q'(0) = q'(1) = 0
  starts and stops with qdd = 0. A 'natural' spline gives qdd(0) = q'(0) s̈(0) ≠ 0 and fails the boundary check.
- Constant s̈ between grid points (toppra's ParametrizeConstAccel, not its default spline refit). The motion
  stays exactly on the collision-checked path, and the limits hold where TOPP-RA imposed them. The default
  refits a spline in time through the grid points: it leaves the path between them and does not stop with
  qdd = 0, failing the boundary check.
- Friction. TOPP-RA's constraints are linear in (s̈, ṡ²). The friction law viscous·qd + coulomb·tanh(qd/ε)
  depends on ṡ, so it enters as toppra's path-dependent term, evaluated at an assumed speed profile. The
  first pass assumes every moving joint is at its velocity limit (the largest friction). The second pass
  uses the speed the first pass found (`FRICTION_PASSES`). The friction is then right at the grid points to
  the extent the profile stopped changing. `verify` checks the exact model.
- Limits hold on TOPP-RA's grid: at both ends of every grid interval, for the velocity at the grid points.
  Between grid points the path's curvature changes slightly, so `grid_points` must be large enough.
- TOPP-RA cannot bound torque rate or jerk. The time-optimal s̈ is bang–bang and piecewise constant on the
  grid, so the torque jumps. The torque rate reported is the mean rate over a `TORQUE_RATE_WINDOW` (1 ms)
  window centred at t: the derivative where the torque is smooth, and J / 1 ms across a jump J, which is
  what a 1 kHz servo loop would have to follow.

OMPL and toppra are optional dependencies, imported on first use (toppra is slow to import).
"""

from __future__ import annotations

import dataclasses
import time
from collections import OrderedDict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from ocpkit.errors import OptionError, RegistryError
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.geometry.clearances import clearances, sphere_centers
from ocpkit.planner.sphere_check import collision_check
from ocpkit.problem import Problem
from ocpkit.result import PathStats, Timing
from ocpkit.robots import Robot, rigid_torque

OMPL_PLANNERS = {"rrtconnect": ("RRTConnect",), "rrtstar": ("RRTstar",), "bitstar": ("BITstar",), "prm": ("PRM",),
                 "lbkpiece": ("LBKPIECE1",), "rrtconnect-lbkpiece": ("RRTConnect", "LBKPIECE1")}
"""OMPL's planners by name. A name with two runs the first until it has checked STAGE_CHECKS configurations
without a path, then the second with what is left of the budget (`ompl_path`)."""
OMPL_PLANNER = "rrtconnect-lbkpiece"
"""The search by default: the ladder's OMPL rungs', the `ompl` guess's and the baselines'."""
STAGE_CHECKS = 50_000
REPAIR_ROUNDS = 8
FRICTION_PASSES = 2
TORQUE_RATE_WINDOW = 1e-3  # s
MAX_STEP = 1.0  # rad: an RRT's longest extension (OMPL's `range`; module docstring)
SEGMENT_BATCH = 16  # configurations counted for a segment's first batch; later batches double (`segment_free`)
FOUND_PATHS = 4  # paths kept for a repeated search (`ompl_path`)
SLOW_PATH = 0.6  # of the problem's longest motion time: a path whose `time_floor` is longer is searched again
SEARCHES = 3  # searches at most for one path, the first included (`ompl_path`)
SEED_STRIDE = 1000  # a repeated search's seed is seed + k SEED_STRIDE: clear of the seeds callers pass (0, 1, 2, ...)


class FreeSpace:
    """The verifier's collision model as a yes/no test: free iff every clearance is ≥ `margin` (m).

    `free`, `segment_free` and `keeps` ask the compiled test (ocpkit.planner.sphere_check: the same answers in C),
    `clearance` the NumPy reference. Counts the configurations it has tested (`checks`)."""

    def __init__(self, problem: Problem, margin: float) -> None:
        self.robot, self.scene, self.margin = problem.robot, problem.scene, margin
        self.data = problem.robot.model.createData()
        self.test = collision_check(problem.robot, problem.scene, margin)
        self._by_margin = {margin: self.test}  # a test per margin asked (`keeps`), made on first use
        self.checks = 0

    def clearance(self, q: np.ndarray) -> np.ndarray:
        """Smallest clearance (m) at each configuration of q (K, n): shape (K,); +inf if there is nothing to hit."""
        c = clearances(self.robot, self.scene, sphere_centers(self.robot, q, self.data))
        self.checks += len(q)
        flat = [values.reshape(len(q), -1) for values in (c.self_pairs, c.obstacles, c.workspace)]
        return np.concatenate(flat, axis=1).min(axis=1, initial=np.inf)

    def free(self, q: np.ndarray) -> np.ndarray:
        """Whether each configuration of q (K, n) keeps the margin: shape (K,), bool."""
        return self.keeps(q, self.margin)

    def keeps(self, q: np.ndarray, margin: float) -> np.ndarray:
        """Whether each configuration of q (K, n) keeps `margin` (m), the space's own or another: shape (K,), bool."""
        if margin not in self._by_margin:
            self._by_margin[margin] = collision_check(self.robot, self.scene, margin)
        self.checks += len(q)
        return self._by_margin[margin].free(q)

    def segment_free(self, a: np.ndarray, b: np.ndarray, resolution: float) -> bool:
        """Whether the straight segment a → b (n,) is free at configurations at most `resolution` rad apart.

        b is checked, a is not (OMPL has already checked it). The configurations are checked coarse to fine in
        one call that stops at the first collision, which a coarse configuration usually finds. They are counted
        in batches of SEGMENT_BATCH, then twice as many, and so on, up to the batch holding the collision: the
        unit every check budget (and so the random suite's certificate of room to pass) has been counted in."""
        count = max(int(np.ceil(np.linalg.norm(b - a) / resolution)), 1)
        hit = self.test.first_collision(a + np.outer(_coarse_to_fine(count) / count, b - a))
        if hit is None:
            self.checks += count
        else:
            batches = (hit // SEGMENT_BATCH + 1).bit_length()  # batch j covers [16 (2^j − 1), 16 (2^(j+1) − 1))
            self.checks += min(SEGMENT_BATCH * (2**batches - 1), count)
        return hit is None


def _coarse_to_fine(count: int) -> np.ndarray:
    """The indices 1..count: count first, then the others by decreasing power of two dividing them."""
    inner = np.arange(1, count)
    return np.concatenate([[count], inner[np.argsort(-(inner & -inner), kind="stable")]])


def check_ompl_planner(planner_name: str) -> None:
    """RegistryError unless `planner_name` is one of OMPL_PLANNERS."""
    if planner_name not in OMPL_PLANNERS:
        raise RegistryError(f"unknown OMPL planner {planner_name!r}; known: {', '.join(OMPL_PLANNERS)}")


def planning_space(problem: Problem, margin: float) -> FreeSpace:
    """The FreeSpace OMPL plans in: `margin` (m), lowered to half the start's or goal's clearance if that is
    smaller, as the transcriptions lower theirs (a margin as wide as an end's clearance would leave no room to
    leave it)."""
    return FreeSpace(problem, min(margin, 0.5 * problem.end_clearances.smallest()))


# -- OMPL ---------------------------------------------------------------------------------------------


@contextmanager
def _ompl_log_level(util: Any, level: Any) -> Iterator[None]:
    """Run a block at OMPL log `level`, then restore the previous level."""
    previous = util.getLogLevel()
    util.setLogLevel(level)
    try:
        yield
    finally:
        util.setLogLevel(previous)


def _seed_ompl(util: Any, seed: int) -> None:
    """Seed OMPL's RNG with seed + 1 (OMPL rejects 0). Every RNG created afterwards (planner, sampler,
    simplifier) then draws from it, so a run repeats exactly. OMPL logs an error when it is re-seeded after
    first use, although the new seed does take effect; that message is silenced."""
    with _ompl_log_level(util, util.LOG_NONE):
        util.RNG.setSeed(seed + 1)


def _configuration(state: Any, scale: np.ndarray) -> np.ndarray:
    """The configuration (n,) rad of an OMPL state whose coordinates are q × `scale` (n,) (`time_scale`)."""
    return np.array(state[0:len(scale)]) / scale


class JointSpace:
    """OMPL's space information over the joints, in time-scaled coordinates: OMPL's coordinate i is q_i × `scale`_i
    (`time_scale`). The joint limits are its bounds, `free` its state validity checker, and a straight segment is
    checked by `free.segment_free` at configurations at most `resolution` rad apart (in joint space)."""

    def __init__(self, problem: Problem, free: FreeSpace, resolution: float) -> None:
        import ompl.base as ob

        robot, self.scale = problem.robot, time_scale(problem.robot)
        space = ob.RealVectorStateSpace(robot.n)
        bounds = ob.RealVectorBounds(robot.n)
        bounds.low, bounds.high = (robot.q_lower * self.scale).tolist(), (robot.q_upper * self.scale).tolist()
        space.setBounds(bounds)
        self.si = ob.SpaceInformation(space)
        self.lower, self.upper = robot.q_lower, robot.q_upper
        scale = self.scale  # not self.q: a bound method would close a cycle through OMPL's objects, never freed

        class SegmentValidator(ob.MotionValidator):
            def checkMotion(self, a: Any, b: Any) -> bool:  # OMPL's name
                return free.segment_free(_configuration(a, scale), _configuration(b, scale), resolution)

        self.si.setStateValidityChecker(lambda state: bool(free.free(_configuration(state, scale)[None])[0]))
        self.si.setMotionValidator(SegmentValidator(self.si))
        self.si.setup()

    def q(self, state: Any) -> np.ndarray:
        """The configuration (n,) rad of an OMPL state."""
        return _configuration(state, self.scale)

    def state(self, q: np.ndarray) -> Any:
        """A new OMPL state holding q (n,), clipped into the joint limits (scenario files allow 1e-9 rad of
        round-off)."""
        state = self.si.allocState()
        state[0:len(q)] = (np.clip(q, self.lower, self.upper) * self.scale).tolist()
        return state


def time_scale(robot: Robot) -> np.ndarray:
    """Per-joint factor (n,) from radians (or metres) to OMPL's coordinates: a joint slower than the robot's median
    velocity limit is scaled by the median over its own limit, the others by 1. A distance in OMPL's space then
    counts a slow joint's move by the time it takes, in radians of a typical joint, so RRT's nearest neighbours,
    its steps and the simplifier's shortcuts do not move a slow joint (the Fetch's torso lift, 0.1 m/s against
    1.3–2.3 rad/s for its arm) back and forth for nothing. A faster joint is not made cheaper: moving it still
    sweeps the arm through the scene (docs/design-notes.md, 2026-12-03)."""
    return np.maximum(np.median(robot.qd_max) / robot.qd_max, 1.0)


def _termination(ob: Any, free: FreeSpace, planning_time: float, max_checks: int | None) -> Any:
    """OMPL's termination condition: `planning_time` s passed (not with inf, which OMPL's timer cannot take) or
    more than `max_checks` configurations checked by `free` (not with None)."""
    if max_checks is None:
        return ob.timedPlannerTerminationCondition(planning_time)
    budget = ob.PlannerTerminationCondition(lambda: free.checks > max_checks)
    if np.isinf(planning_time):
        return budget
    return ob.plannerOrTerminationCondition(ob.timedPlannerTerminationCondition(planning_time), budget)


@dataclass(frozen=True)
class OmplPath:
    """Simplified waypoints (k, n) from start to goal, or None without an exact path; times in seconds and
    `search_checks` (the configurations the searches checked, not the simplifications) summed over the `searches`
    made (`ompl_path`)."""

    waypoints: np.ndarray | None
    path_time: float
    simplify_time: float
    searches: int = 1
    search_checks: int = 0


def time_floor(robot: Robot, waypoints: np.ndarray) -> float:
    """The time (s) a robot needs to follow `waypoints` (k, n) at its joint velocity limits, without accelerating:
    each straight segment takes its slowest joint's |Δq| / qd_max. No timing of the path is faster (a smoothed
    path cuts corners by little); it is the cheap score a path search compares paths by (`ompl_path`)."""
    return float((np.abs(np.diff(waypoints, axis=0)) / robot.qd_max).max(axis=1, initial=0.0).sum())


_found: OrderedDict[tuple, tuple[Problem, np.ndarray, int, int]] = OrderedDict()
"""The last FOUND_PATHS paths found: (problem, waypoints, configurations checked, searches) by (id(problem), the
search's options but its budgets); the problem is held so that its id is not reused while the entry lives."""


def ompl_path(problem: Problem, free: FreeSpace, planner_name: str, planning_time: float, seed: int,
               resolution: float, max_checks: int | None = None, max_step: float | None = MAX_STEP) -> OmplPath:
    """Plan start → goal with the named OMPL planner (RRTs extending at most `max_step` rad) until it stops with an
    exact path, `planning_time` seconds have passed or (if given) `free` has checked more than `max_checks`
    configurations, then simplify the path to convergence. A budget in checks repeats on any machine; one in seconds
    does not. So a search budgeted in checks that stays within a search before it (the same `problem` object and
    options, a `max_checks` at least the checks that search took) gets the path found then, without searching
    again (no time; `free` counts the checks it took), if it is among the last FOUND_PATHS found.

    A path whose `time_floor` exceeds SLOW_PATH times the problem's longest motion time (time.max) leaves its
    timing little room: the torque, torque-rate and jerk terms make a motion far slower than that floor. Such a
    path is searched again with other seeds (seed + k SEED_STRIDE), up to SEARCHES searches in all, within the same
    budgets (the seconds from the call, the checks counted by `free`), and the fastest path by `time_floor` is kept.
    RRTConnect's paths between the same start and goal differ several-fold in that time from seed to seed.

    The time budget is OMPL's own timer. A check budget is a Python condition, safe only for planners that plan in
    the calling thread (RRTConnect, RRT*, BIT*, LBKPIECE1): PRM checks for a solution in a second thread, which
    would deadlock waiting for the interpreter lock that the planning thread holds. A planner of two stages
    (OMPL_PLANNERS) always budgets its first in checks."""
    if max_step is not None and not (np.isfinite(max_step) and max_step > 0):
        raise OptionError(f"max_step must be a finite number of radians > 0, got {max_step}")
    if max_checks is not None and planner_name == "prm":
        raise OptionError("max_checks cannot stop prm (it plans in a second thread); give it a planning_time")
    key = (id(problem), free.margin, planner_name, seed, resolution, max_step)
    if key in _found and _found[key][0] is problem:
        _, waypoints, checks, searches = _found[key]
        if max_checks is not None and checks <= max_checks:
            free.checks += checks
            return OmplPath(waypoints, 0.0, 0.0, searches)
    before, began = free.checks, time.perf_counter()
    found = _search(problem, free, planner_name, planning_time, seed, resolution, max_checks, max_step)
    while found.waypoints is not None and found.searches < SEARCHES and _slow(problem, found.waypoints):
        left = planning_time - (time.perf_counter() - began)
        if left <= 0 or (max_checks is not None and free.checks >= max_checks):
            break
        again = _search(problem, free, planner_name, left, seed + found.searches * SEED_STRIDE, resolution,
                        max_checks, max_step)
        found = _faster(problem.robot, found, again)
    if found.waypoints is not None:
        _found[key] = problem, found.waypoints, free.checks - before, found.searches
        while len(_found) > FOUND_PATHS:
            _found.popitem(last=False)
    return found


def _slow(problem: Problem, waypoints: np.ndarray) -> bool:
    """Whether the path `waypoints` (k, n) takes longer than SLOW_PATH × time.max (s) at the velocity limits."""
    return time_floor(problem.robot, waypoints) > SLOW_PATH * problem.time.max


def _faster(robot: Robot, first: OmplPath, then: OmplPath) -> OmplPath:
    """Of two searches' paths, the one with the smaller `time_floor` (the first when the second found none), with
    both searches' times and counts."""
    kept = first if then.waypoints is None or time_floor(robot, first.waypoints) <= time_floor(robot, then.waypoints) \
        else then
    return OmplPath(kept.waypoints, first.path_time + then.path_time, first.simplify_time + then.simplify_time,
                    first.searches + then.searches, first.search_checks + then.search_checks)


def _search(problem: Problem, free: FreeSpace, planner_name: str, planning_time: float, seed: int,
            resolution: float, max_checks: int | None, max_step: float | None) -> OmplPath:
    """`ompl_path`'s search and simplification."""
    import ompl.base as ob
    import ompl.geometric as og
    import ompl.util as ou

    with _ompl_log_level(ou, ou.LOG_ERROR):
        _seed_ompl(ou, seed)
        space = JointSpace(problem, free, resolution)
        setup = og.SimpleSetup(space.si)
        setup.setStartAndGoalStates(space.state(problem.start), space.state(problem.goal))
        start, before = time.perf_counter(), free.checks
        stages = OMPL_PLANNERS[planner_name]
        for stage, name in enumerate(stages):
            budget = max_checks
            if stage < len(stages) - 1:
                budget = min(free.checks + STAGE_CHECKS, np.inf if max_checks is None else max_checks)
            if stage:
                setup.clear()  # the planner before this one found no path: start afresh
            setup.setPlanner(_planner(space.si, name, max_step))
            setup.solve(_termination(ob, free, max(planning_time - (time.perf_counter() - start), 0.0), budget))
            if setup.haveExactSolutionPath():
                break
        path_time, searched = time.perf_counter() - start, free.checks - before
        if not setup.haveExactSolutionPath():
            return OmplPath(None, path_time, 0.0, search_checks=searched)
        path = og.PathGeometric(setup.getSolutionPath())
        og.PathSimplifier(space.si).simplifyMax(path)
        waypoints = np.array([space.q(state) for state in path.getStates()])
        waypoints[[0, -1]] = np.clip([problem.start, problem.goal], space.lower, space.upper)  # not rounded by scale
        return OmplPath(waypoints, path_time, time.perf_counter() - start - path_time, search_checks=searched)


def _planner(si: Any, name: str, max_step: float | None) -> Any:
    """OMPL's planner class `name` on `si`; RRTConnect, RRT* and LBKPIECE1 extend at most `max_step` rad at a time
    (None: OMPL's default step)."""
    import ompl.geometric as og

    planner = getattr(og, name)(si)
    if max_step is not None and hasattr(planner, "setRange"):
        planner.setRange(max_step)
    return planner


def no_path_message(planner_name: str, planning_time: float, free: FreeSpace) -> str:
    """What a search that found no exact path spent: its seconds (unless unlimited) and its validity checks."""
    spent = f"{free.checks} validity checks" if np.isinf(planning_time) else \
        f"{planning_time:g} s and {free.checks} validity checks"
    return f"{planner_name}: no exact path within {spent}"


# -- smooth path --------------------------------------------------------------------------------------


def _clamped_cubic(chord: np.ndarray, waypoints: np.ndarray) -> Any:
    """toppra's clamped cubic spline through `waypoints` (k, n) at chord lengths `chord` (k,), rad."""
    from toppra.interpolator import SplineInterpolator

    return SplineInterpolator(chord, waypoints, bc_type="clamped")


def smooth_path(waypoints: np.ndarray, free: FreeSpace, resolution: float,
                 fit: Callable[[np.ndarray, np.ndarray], Any] = _clamped_cubic,
                 within_limits: bool = False) -> tuple[Any, int]:
    """A spline `fit(chord, waypoints)` (a clamped cubic by default) through `waypoints` (k, n), parametrised by
    chord length (rad), that keeps half the margin (and, `within_limits`, the joint position limits) at checks
    every resolution/4 rad (the spline called with chord lengths); returns (the spline, repair rounds used).

    After the last round the spline is returned as it is; `verify` then reports any contact."""
    waypoints = waypoints[np.concatenate([[True], np.linalg.norm(np.diff(waypoints, axis=0), axis=1) > 0])]
    for rounds in range(REPAIR_ROUNDS + 1):
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))])
        path = fit(chord, waypoints)
        checks = np.linspace(0.0, chord[-1], int(np.ceil(4 * chord[-1] / resolution)) + 1)
        q = path(checks)
        outside = ((q < free.robot.q_lower) | (q > free.robot.q_upper)).any(axis=1) if within_limits else False
        bad = checks[~free.keeps(q, free.margin / 2) | outside]
        if not len(bad) or rounds == REPAIR_ROUNDS:
            break
        segments = np.unique(np.clip(np.searchsorted(chord, bad) - 1, 0, len(chord) - 2))
        waypoints = np.insert(waypoints, segments + 1, (waypoints[segments] + waypoints[segments + 1]) / 2, axis=0)
    return path, rounds


# -- TOPP-RA ------------------------------------------------------------------------------------------


def time_optimal(problem: Problem, path: Any, grid_points: int) -> tuple[Any, np.ndarray] | None:
    """TOPP-RA's time-optimal rest-to-rest timing of `path` under joint velocity and torque limits (with the
    friction passes described in the module docstring): toppra's ParametrizeConstAccel trajectory and the
    times (s) of its grid points, or None if the path cannot be timed within the limits."""
    import toppra.algorithm
    import toppra.constraint

    robot = problem.robot
    data = robot.model.createData()
    grid = np.linspace(*path.path_interval, grid_points)
    tangent = path(grid, 1)
    velocity = toppra.constraint.JointVelocityConstraint(robot.qd_max)
    bounds = (np.vstack([np.eye(robot.n), -np.eye(robot.n)]), np.concatenate([robot.tau_max, robot.tau_max]))
    qd = robot.qd_max * np.sign(tangent)  # first pass: every moving joint at its velocity limit
    for _ in range(FRICTION_PASSES):
        friction = robot.friction(qd)
        torque = toppra.constraint.SecondOrderConstraint(
            lambda q, v, a: pin.rnea(robot.model, data, q, v, a).copy(), lambda _q: bounds[0], lambda _q: bounds[1],
            robot.n, custom_term=lambda _path, s, friction=friction: friction[np.searchsorted(grid, s)],
            discretization_scheme=toppra.constraint.DiscretizationType.Interpolation)
        algorithm = toppra.algorithm.TOPPRA([velocity, torque], path, gridpoints=grid, solver_wrapper="seidel",
                                            parametrizer="ParametrizeConstAccel")
        motion = algorithm.compute_trajectory(0.0, 0.0)
        if motion is None:
            return None
        speed = algorithm.problem_data.sd_vec
        qd = tangent * speed[:, None]
    return motion, _grid_times(grid, speed)


def _grid_times(grid: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """Times (s) at the path points `grid` passed at path speeds `speed` under constant s̈ in between."""
    return np.concatenate([[0.0], np.cumsum(2.0 * np.diff(grid) / (speed[:-1] + speed[1:]))])


@dataclass(frozen=True)
class PathMotion:
    """q(t) = path(s(t)) from toppra's trajectory (eval/evald/evaldd), tau = rnea + friction, and the torque
    rate as the mean over TORQUE_RATE_WINDOW (see the module docstring). Before 0 and after t_f the robot rests."""

    motion: Any
    robot: Robot
    data: pin.Data
    slowdown: float = 1.0  # the motion at t is toppra's at t / slowdown

    def __call__(self, t: np.ndarray) -> Samples:
        t = np.asarray(t, dtype=float)
        q, qd, qdd, tau = self._state(t)
        half = TORQUE_RATE_WINDOW / 2
        taud = (self._state(t + half)[3] - self._state(t - half)[3]) / TORQUE_RATE_WINDOW
        return Samples(t, q, qd, qdd, tau, taud)

    def _state(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """q, qd, qdd, tau at times t (m,), each (m, n)."""
        c = self.slowdown
        t = np.clip(t / c, *self.motion.path_interval)
        q, qd, qdd = self.motion.eval(t), self.motion.evald(t) / c, self.motion.evaldd(t) / c**2
        return q, qd, qdd, rigid_torque(self.robot, q, qd, qdd, self.data) + self.robot.friction(qd)


def hold(problem: Problem) -> Trajectory:
    """Standing still at the start for time.min seconds: what a plan without a trajectory leaves the robot doing."""
    robot = problem.robot
    rest = np.zeros((1, robot.n))
    gravity = rigid_torque(robot, problem.start[None, :], rest, rest)  # (1, n)

    def still(t: np.ndarray) -> Samples:
        t = np.asarray(t, dtype=float)
        zeros = np.zeros((len(t), robot.n))
        return Samples(t, np.tile(problem.start, (len(t), 1)), zeros, zeros, np.tile(gravity, (len(t), 1)), zeros)

    return Trajectory(still(np.array([0.0, problem.time.min])), still)


def import_backends() -> float:
    """Import OMPL and toppra; the seconds it took: the one-time set-up (slow the first time, then nearly 0)."""
    start = time.perf_counter()
    import ompl.geometric  # noqa: F401
    import toppra.algorithm  # noqa: F401

    return time.perf_counter() - start


# -- the seed -----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SeedOptions:
    """How the seed finds and times its path. `planner_name`: one of OMPL_PLANNERS. `planning_time` (s): OMPL's
    budget. RRTConnect stops at its first path, so with the same `seed` it repeats exactly; RRT* and BIT* improve
    until the budget ends and PRM watches for a solution in a second thread, so their paths may depend on machine
    speed. `resolution` (rad): spacing of collision checks along straight joint-space segments. `grid_points`:
    TOPP-RA's path points. `margin` (m): clearance kept while planning, lowered to half the start's or goal's
    clearance if that is smaller (`planning_space`). `max_checks`: OMPL stops after checking this many
    configurations too (a budget that repeats on any machine; planning_time may then be inf; only for the
    planners that plan in the calling thread, not PRM). `max_step` (rad): the longest extension of RRTConnect,
    RRT* and LBKPIECE1 (OMPL's `range`; BIT* and PRM have none); None: OMPL's. `deadline` (a time.perf_counter() value):
    the search also ends then, whatever `planning_time` is left: a planner's budget, which counts the validity
    checker's construction (a second or more on a robot with thousands of sphere pairs) too."""

    planner_name: str = OMPL_PLANNER
    planning_time: float = 1.0
    seed: int = 0
    resolution: float = 0.01
    grid_points: int = 1000
    margin: float = 0.01
    max_checks: int | None = None
    max_step: float | None = MAX_STEP
    deadline: float | None = None

    def search_time(self) -> float:
        """The search's time budget (s) from now: `planning_time`, cut to what is left before `deadline`."""
        if self.deadline is None:
            return self.planning_time
        return min(self.planning_time, max(self.deadline - time.perf_counter(), 0.0))


@dataclass(frozen=True)
class Seed:
    """A timed motion from start to goal (`trajectory`), or None with the reason in `stopped` ("no_path": OMPL
    found no exact path within its budget; "infeasible": TOPP-RA cannot time the path within the limits);
    `message` says what was done; `setup_time` (s): importing OMPL and toppra (the one-time set-up); `timing`:
    the search, shortening, smoothing and TOPP-RA times; `path`: the path's figures (None when the goal is the
    start and the motion holds still)."""

    trajectory: Trajectory | None
    stopped: str | None
    message: str
    setup_time: float = 0.0
    timing: Timing = field(default_factory=Timing)
    path: PathStats | None = None


def ompl_seed(problem: Problem, options: SeedOptions = SeedOptions()) -> Seed:
    """Find, smooth and time a path from start to goal with `options` (module docstring); no verification. When
    the goal is the start, the motion holds still at the start for time.min seconds, without OMPL or TOPP-RA."""
    check_ompl_planner(options.planner_name)
    if np.array_equal(problem.start, problem.goal):
        return Seed(hold(problem), None, "the goal is the start: hold still")
    setup = import_backends()
    free = planning_space(problem, options.margin)
    planning_time = options.search_time()
    found = ompl_path(problem, free, options.planner_name, planning_time, options.seed, options.resolution,
                      options.max_checks, options.max_step)
    searched = Timing(path_search=found.path_time, simplify=found.simplify_time, smooth=0.0, path_timing=0.0)
    if found.waypoints is None:
        return Seed(None, "no_path", no_path_message(options.planner_name, planning_time, free), setup,
                    searched, PathStats(free.checks, 0, 0, free.margin))
    smoothing = time.perf_counter()
    path, rounds = smooth_path(found.waypoints, free, options.resolution)
    timing = time.perf_counter()
    timed = time_optimal(problem, path, options.grid_points)
    spent = dataclasses.replace(searched, smooth=timing - smoothing, path_timing=time.perf_counter() - timing)
    figures = PathStats(free.checks, len(path.ss_waypoints), rounds, free.margin, searches=found.searches)
    if timed is None:
        return Seed(None, "infeasible", "TOPP-RA: the path cannot be timed within the limits", setup, spent, figures)
    motion, knot_times = timed
    interpolant = PathMotion(motion, problem.robot, problem.robot.model.createData())
    message = (f"{options.planner_name}: {len(found.waypoints)} waypoints, {rounds} repair rounds; "
               f"TOPP-RA: {options.grid_points} grid points")
    return Seed(Trajectory(interpolant(knot_times), interpolant), None, message, setup, spent, figures)


def slowed(trajectory: Trajectory, slowdown: float) -> Trajectory:
    """A seed's motion taking `slowdown` times as long along the same path (q(t) = q₀(t / slowdown)); a motion that
    is not a PathMotion (a hold) as it is."""
    if not isinstance(trajectory.interpolant, PathMotion):
        return trajectory
    interpolant = dataclasses.replace(trajectory.interpolant, slowdown=slowdown)
    return Trajectory(interpolant(slowdown * trajectory.knots.t), interpolant)
