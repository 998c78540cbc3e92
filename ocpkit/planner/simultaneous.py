"""The simultaneous planner (the paper's method): path and timing together as one optimal control problem.

A build of the problem's shape (ocpkit.planner.build_cache: transcription + dynamics + constraints + prepared
solver, reused across queries), an initial guess, the solve with refinement rounds (ocpkit.planner.refinement),
and `finish`.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable, Sequence

import numpy as np

from ocpkit.constraints import DEFAULT_CONSTRAINTS, Constraint, make_constraints
from ocpkit.dynamics import Dynamics
from ocpkit.errors import NoGuess, OptionError
from ocpkit.formats.trajectory import Trajectory
from ocpkit.geometry.clearances import buried, sphere_centers_batch
from ocpkit.nlp import Refinement
from ocpkit.planner import GUESSES, PLANNERS, screening
from ocpkit.planner.build_cache import Build, Shaped, layout, prepare, shape
from ocpkit.planner.guesses import STRAIGHT_LINE_RULES
from ocpkit.planner.ladder import DEFAULT_LADDER, MAX_WALL_TIME, OMPL_CHECKS, OMPL_RESOLUTION, Rung, climb, ordered
from ocpkit.planner.ompl_seed import OMPL_PLANNER, hold
from ocpkit.planner.options import SimultaneousOptions
from ocpkit.planner.refinement import DEFAULT_ROUNDS, RELAXED, Refined, solve_refined
from ocpkit.problem import Problem
from ocpkit.registry import construct
from ocpkit.result import Plan, Screening, Timing, finish
from ocpkit.solvers import SolverStatus
from ocpkit.transcription import Discretization

END_CHECK_CLEARANCE = 0.05  # m: a start or goal this close to contact gets checks in every knot interval


def plan_simultaneous(problem: Problem, transcription: str = "chebyshev", knots: int = 12,
                      dynamics: str | Dynamics = "casadi-rnea", solver: str = "ipopt",
                      guess: str | np.ndarray = "paper",
                      refinements: int = DEFAULT_ROUNDS,
                      constraints: Sequence[str | type[Constraint]] = DEFAULT_CONSTRAINTS,
                      transcription_options: dict | None = None, solver_options: dict | None = None,
                      dynamics_options: dict | None = None, max_wall_time: float = MAX_WALL_TIME,
                      guess_options: dict | None = None, fallbacks: Sequence[Rung] = DEFAULT_LADDER,
                      screen: bool | None = None) -> Plan:
    """Plan `problem` with path and timing together.

    `knots` is N, the intervals per segment of a pseudospectral transcription (K N + 1 points on K `segments`) or
    the mesh intervals of a local one; `guess` names a registered initial-guess rule ("paper", the default: the
    paper's line over t_f = time.guess; "line": the straight joint-space line over an estimated motion time,
    ocpkit.planner.guesses; "motion": a Trajectory given as guess option "trajectory"; "ompl": an OMPL path timed
    by TOPP-RA, ocpkit.planner.ompl_seed) or is a decision vector for this shape, with `guess_options` for the rule
    (e.g. {"seed": 3, "planning_time": 2.0} for "ompl", the options of ocpkit.planner.ompl_seed.SeedOptions);
    `refinements` bounds the re-solve rounds. Components and options as for `ocpkit.build`. The guess is part of the
    computation time; the one-time set-up is not. `max_wall_time` (s; ocpkit.planner.ladder.MAX_WALL_TIME) bounds the
    computation (guess, every solve and refinement round, every rung): each solve gets the time left (a solver that
    cannot be interrupted, blocksqp or fatrop, can overrun it by one solve), and the plan ends as `time_limit` when
    it runs out. `fallbacks` is the ladder of rungs (ocpkit.planner.ladder), each overriding these options
    (Rung.apply), tried in order until one plan verifies (the first OMPL rung first when the straight line is
    buried in obstacles: ocpkit.planner.ladder.ordered); () plans once with these options (SINGLE_SHOT, the
    paper's setting). `screen`: whether the NLP carries only the collision rows near the motion
    (ocpkit.planner.screening; None: whenever the robot and scene have collision terms). The options travel as one
    ocpkit.planner.options.SimultaneousOptions."""
    options = SimultaneousOptions(
        transcription=transcription, knots=knots, dynamics=dynamics, solver=solver, guess=guess,
        refinements=refinements, constraints=constraints, transcription_options=transcription_options or {},
        solver_options=solver_options or {}, dynamics_options=dynamics_options, max_wall_time=max_wall_time,
        guess_options=guess_options or {}, fallbacks=fallbacks, screen=screen)

    def attempt(rung: Rung | None, left: float) -> Plan:
        applied = options if rung is None else rung.apply(options, left)
        if rung is not None and rung.safety_net:
            return _timed_path(problem, applied, rung.seed or 0, left)
        return _single_shot(problem, applied, left)

    return climb(attempt, ordered(options.fallbacks, _buried_line(problem, options)), options.max_wall_time)


def _buried_line(problem: Problem, options: SimultaneousOptions) -> bool:
    """Whether the call's guess starts from the straight line and some sample of that line
    (ocpkit.planner.screening.line_samples) has a sphere centre inside an obstacle box or cylinder."""
    if not (isinstance(options.guess, str) and options.guess in STRAIGHT_LINE_RULES):
        return False
    centers = sphere_centers_batch(problem.robot, screening.line_samples(problem))
    return bool(buried(problem.robot, problem.scene, centers).any())


def _single_shot(problem: Problem, options: SimultaneousOptions, max_wall_time: float) -> Plan:
    """One plan with `options`: build, guess, solve with refinement rounds, all within `max_wall_time` (s) of
    computation and set-up. A guess rule with no start to offer (NoGuess) ends the plan as `no_path` before any
    solve, holding the start (a dense check of a placeholder motion would only spend the budget: seconds on a
    robot with thousands of sphere pairs); one that ends past the deadline (a long path search after a long
    build) ends the plan as `time_limit` with the guess's motion, without the rebuild or solve that could only
    overrun. With screening (ocpkit.planner.screening) the guess is found on the shape without its constraints
    (ocpkit.planner.build_cache.layout, reused by the robot's later plans), and the build keeps the collision rows
    near the straight line, and near the guess too where the guess comes near rows the line's screening leaves
    out: the rows are built once, for the guess; an unverified solution that comes near rows left out is solved
    again on a rebuild, unless its solve was stopped by time: at the deadline, or by its pace, which hands the
    rung's time on (ocpkit.planner.ladder), and a rebuild with more rows would only iterate more slowly.
    The builds before the first solve are the plan's set-up, a rebuild after it is computation."""
    started = time.perf_counter()
    near = _screening_start(problem, options)
    options = _checked_near_the_ends(problem, options)
    deadline = started + max_wall_time  # the set-up counts against the budget too
    if near is None:
        shaped = _shape(problem, options, None)
        encoding, graph_time = shaped.discretization, shaped.graph_time
    else:  # the collision rows wait for the guess, encoded meanwhile on the shape without constraints
        encoding, graph_time = _layout(problem, options)
    dynamics = options.dynamics
    method = {"planner": "simultaneous", "transcription": options.transcription, "knots": options.knots,
              "dynamics": dynamics if isinstance(dynamics, str) else dynamics.name, "solver": options.solver}
    guess, guess_options = options.starting_guess()
    guessing = time.perf_counter()
    if "planning_time" in guess_options:  # a path search ends by the plan's deadline, after this rung's build
        guess_options["planning_time"] = min(guess_options["planning_time"], max(deadline - guessing, 0.0))
    try:
        w = _guess(problem, encoding, guess, guess_options)
    except NoGuess as exc:  # no motion to report: the robot holds its start, as in the baselines' no_path plans
        return finish(problem, hold(problem), "no_path", method, started, setup_time=graph_time,
                      message=f"guess {guess!r}: {exc}; not solved, the plan holds the start")
    guess_time = time.perf_counter() - guessing
    if time.perf_counter() >= deadline:  # the build and the guess took all the time: no rebuild, no solve
        return finish(problem, encoding.decode(w), "time_limit", method, started,
                      setup_time=graph_time, message="the time ran out in the guess, before the first solve",
                      timing=Timing(guess=guess_time, setup={"graph": graph_time}))
    if near is not None:  # w stays: the rows screened leave the variables as they are
        lined = screening.screened(problem, options.constraints, near)
        wider = _widened(problem, options, lined, near, encoding.decode(w))
        shaped, near = wider or (_shape(problem, options, near), near)
        graph_time += shaped.graph_time
    made = prepare(shaped, graph_time)
    first_setup = made.setup_time or graph_time  # a cached build: the graphs built on the way
    budget = options.iteration_budget
    refined = solve_refined(made.discretization, made.solver, problem, w, options.refinements, deadline,
                            RELAXED if options.relaxed else None, budget, _lacking(problem, made, near),
                            options.pace)
    rebuilds = 0
    while near is not None and not refined.verification.ok and rebuilds < screening.MAX_REBUILDS \
            and time.perf_counter() < deadline and refined.result.status != SolverStatus.TIME_LIMIT \
            and refined.iterations < budget \
            and (wider := _widened(problem, options.capped(budget - refined.iterations),
                                   made.discretization.constraints, near, refined.trajectory)):
        (shaped, near), rebuilds = wider, rebuilds + 1
        made = prepare(shaped)
        restart = made.discretization.relifted(refined.result.w, Refinement())  # the checks back at their defaults
        refined = _continued(refined, solve_refined(made.discretization, made.solver, problem, restart,
                                                    options.refinements, deadline,
                                                    iteration_budget=budget - refined.iterations,
                                                    lacking=_lacking(problem, made, near)))
    result = refined.result
    stopped = None if result.status == SolverStatus.CONVERGED else result.status.value
    timing = Timing(guess=guess_time, setup=made.setup_parts, rounds=refined.timing)
    screened = None if near is None else \
        Screening(screening.screenable_rows(made.discretization.constraints), rebuilds)
    return finish(problem, refined.trajectory, stopped, method, started, setup_time=first_setup,
                  iterations=refined.iterations, rounds=refined.rounds, message=result.message,
                  verification=refined.verification, timing=timing, screening=screened)


def _timed_path(problem: Problem, options: SimultaneousOptions, seed: int, max_wall_time: float) -> Plan:
    """The ompl-topp3 planner's plan (registry PLANNERS) on the path an OMPL rung of `seed` searched for (the same
    search options, so the path found is reused: ocpkit.planner.ompl_seed.ompl_path), its timing solved with the
    transcription, grid, dynamics and solver of `options` (the call's with the net rung's grid) within
    `max_wall_time` (s)."""
    return PLANNERS.get("ompl-topp3")(
        problem, transcription=options.transcription, knots=options.knots, dynamics=options.dynamics,
        solver=options.solver, refinements=options.refinements, transcription_options=options.transcription_options,
        solver_options=options.solver_options, dynamics_options=options.dynamics_options,
        max_wall_time=max_wall_time, planner_name=OMPL_PLANNER, planning_time=max_wall_time, seed=seed,
        resolution=OMPL_RESOLUTION, max_checks=OMPL_CHECKS)


def _screening_start(problem: Problem, options: SimultaneousOptions) -> np.ndarray | None:
    """The configurations the first build screens the collision rows by (the straight line), or None when the
    plan does not screen (`screen` False, or None and no collision terms to screen: ocpkit.planner.screening)."""
    screen = options.screen
    if screen is None:
        screen = screening.worth_screening(make_constraints(problem, options.constraints))
    return screening.line_samples(problem) if screen else None


def _checked_near_the_ends(problem: Problem, options: SimultaneousOptions) -> SimultaneousOptions:
    """`options` with `end_checks` for a pseudospectral transcription (unless given) when the start or the goal is
    within END_CHECK_CLEARANCE of contact: the arm still moves fast in the short knot intervals near an end, and can
    dip between two knots into whatever it starts or stops beside (ocpkit.transcription.pseudospectral)."""
    if not options.pseudospectral() or "end_checks" in options.transcription_options:
        return options
    if problem.end_clearances.smallest() >= END_CHECK_CLEARANCE:
        return options
    return dataclasses.replace(options, transcription_options={**options.transcription_options, "end_checks": True})


def _layout(problem: Problem, options: SimultaneousOptions) -> tuple[Discretization, float]:
    """The shape of `options` without its constraints (ocpkit.planner.build_cache.layout: kept for the robot's
    later plans), and the seconds its graph took (0 when reused)."""
    return layout(problem, options.transcription, options.knots, options.dynamics, options.solver,
                  dict(options.transcription_options), dict(options.solver_options), options.dynamics_options)


def _shape(problem: Problem, options: SimultaneousOptions, near: np.ndarray | None) -> Shaped:
    """The shape of `options` (its solver not prepared: ocpkit.planner.build_cache), its collision rows screened by
    `near`."""
    return shape(problem, options.transcription, options.knots, options.dynamics, options.solver,
                 options.constraints, dict(options.transcription_options), dict(options.solver_options),
                 options.dynamics_options, near=near)


def _lacking(problem: Problem, made: Build, near: np.ndarray | None) -> Callable[[Trajectory], bool] | None:
    """With screening (`near` given): whether a motion comes near rows `made` left out, which ends its refinement
    rounds so the plan rebuilds with them instead; None without screening."""
    if near is None:
        return None
    return lambda motion: _near_left_out(problem, made.discretization.constraints, motion) is not None


def _near_left_out(problem: Problem, constraints: Sequence[Constraint], motion: Trajectory) -> np.ndarray | None:
    """Samples (K, n) of `motion` when it comes near rows the screened `constraints` left out
    (ocpkit.planner.screening), else None."""
    samples = screening.motion_samples(motion)
    return samples if screening.missing(problem, constraints, samples) else None


def _widened(problem: Problem, options: SimultaneousOptions, constraints: Sequence[Constraint], near: np.ndarray,
             motion: Trajectory) -> tuple[Shaped, np.ndarray] | None:
    """The shape screened by `near` and samples of `motion` when `motion` comes near rows the `constraints`
    (screened by `near`) left out, with those configurations (K, n); None when it does not. Its solver is not
    prepared yet (`prepare`)."""
    samples = _near_left_out(problem, constraints, motion)
    if samples is None:
        return None
    near = np.vstack([near, samples])
    return _shape(problem, options, near), near


def _continued(before: Refined, after: Refined) -> Refined:
    """`after`, a solve that continued from `before`'s solution, with both solves' iterations, rounds and timing."""
    return dataclasses.replace(after, iterations=before.iterations + after.iterations,
                               rounds=before.rounds + after.rounds, timing=before.timing + after.timing)


def _guess(problem: Problem, discretization: Discretization, guess: str | np.ndarray,
           options: dict) -> np.ndarray:
    """The decision vector w₀ (n_w,) of the named guess rule (with `options`), or `guess` itself; OptionError if its
    length is not n_w."""
    if isinstance(guess, str):
        return construct(functools.partial(GUESSES.get(guess), problem, discretization), f"guess {guess!r}", options)
    w = np.asarray(guess, dtype=float)
    expected = discretization.nlp.variables.size
    if w.shape != (expected,):
        raise OptionError(f"the guess vector has shape {w.shape}, this NLP needs {expected} values (n_w)")
    return w
