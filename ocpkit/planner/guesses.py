"""The initial guesses of the simultaneous planner (registry GUESSES, ocpkit.planner).

`paper`: the paper's rule, the straight joint-space line at constant speed over t_f = time.guess (in the paper's
cases far slower than the optimum, so the first IPOPT iterations only shrink t_f).
`line`: the same line over an estimated motion time, `motion_time_estimate`: the time a smooth
(quintic) rest-to-rest motion along the line needs to keep within the velocity limits, lengthened until its
inverse-dynamics torque keeps within the torque limits.
`motion`: a given trajectory (any planner's, e.g. an earlier plan) sampled on the grid: a warm start.
`ompl`: the OMPL seed (ocpkit.planner.ompl_seed: an OMPL path timed by TOPP-RA, not verified), slowed down.

The simultaneous planner's default stays `paper`: `line` is faster on the paper cases, but it verified fewer of
the shipped MBM problems and no more of the hard random suite.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from ocpkit.errors import NoGuess, OptionError
from ocpkit.formats.trajectory import Trajectory
from ocpkit.planner.ompl_seed import SeedOptions, ompl_seed, slowed
from ocpkit.problem import Problem
from ocpkit.robots import rigid_torque
from ocpkit.transcription import Discretization

STRAIGHT_LINE_RULES = ("paper", "line")
"""The registered names of the rules here that start from the straight joint-space line."""
PEAK_SPEED = 1.875
"""Peak of ds/dτ of the quintic rest-to-rest profile s(τ) = 10τ³ − 15τ⁴ + 6τ⁵ (τ = t / t_f)."""
TORQUE_SAMPLES = 21
TORQUE_ROUNDS = 4  # lengthenings of t_f by the torque excess, at most
GUESS_SLOWDOWN = 1.5  # the OMPL guess's motion takes this many times TOPP-RA's time (`ompl_guess`)


def quintic(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """s, ds/dτ, d²s/dτ² of the quintic rest-to-rest profile at τ ∈ [0, 1], each of tau's shape."""
    return (10 * tau**3 - 15 * tau**4 + 6 * tau**5, 30 * tau**2 - 60 * tau**3 + 30 * tau**4,
            60 * tau - 180 * tau**2 + 120 * tau**3)


def torque_ratio(problem: Problem, tf: float) -> float:
    """max over joints and TORQUE_SAMPLES times of |rnea| / tau_max for the quintic motion along the line over tf s."""
    s, ds, dds = quintic(np.linspace(0.0, 1.0, TORQUE_SAMPLES))
    delta = problem.goal - problem.start
    tau = rigid_torque(problem.robot, problem.start + np.outer(s, delta), np.outer(ds / tf, delta),
                       np.outer(dds / tf**2, delta))
    return float(np.max(np.abs(tau) / problem.robot.tau_max))


def motion_time_estimate(problem: Problem) -> float:
    """t_f (s) of the timed line guess (module docstring), within the problem's time bounds."""
    tf = max(PEAK_SPEED * problem.velocity_lower_bound(), problem.time.min)
    for _ in range(TORQUE_ROUNDS):
        ratio = torque_ratio(problem, tf)
        if ratio <= 1.0:
            break
        tf *= np.sqrt(ratio)  # the inertial torque scales as 1 / t_f²: conservative for the rest
    return float(min(tf, problem.time.max))


def paper_guess(problem: Problem, discretization: Discretization, fallback: bool = True) -> np.ndarray:
    """The paper's guess: the straight joint-space line over t_f = time.guess; it always exists, so `fallback`
    (every guess rule takes it: see NoGuess) changes nothing."""
    return discretization.initial_guess(problem)


def line_guess(problem: Problem, discretization: Discretization, fallback: bool = True) -> np.ndarray:
    """The straight joint-space line over t_f = motion_time_estimate (the timed line); `fallback` as for
    `paper_guess`."""
    timed = dataclasses.replace(problem.time, guess=motion_time_estimate(problem))
    return discretization.initial_guess(dataclasses.replace(problem, time=timed))


def motion_guess(problem: Problem, discretization: Discretization, fallback: bool = True,
                 trajectory: Trajectory | None = None) -> np.ndarray:
    """`trajectory` (guess option: a Trajectory from start to goal, e.g. an earlier plan's) sampled on the grid;
    `fallback` as for `paper_guess`."""
    if not isinstance(trajectory, Trajectory):
        raise OptionError(f"guess 'motion' needs a Trajectory to start from, got {trajectory!r} (Python API: "
                          "plan(problem, guess='motion', guess_options={'trajectory': earlier_plan.trajectory}))")
    joints = trajectory.knots.q.shape[1]
    if joints != problem.robot.n:
        raise OptionError(f"guess 'motion': the trajectory moves {joints} joints, the robot has {problem.robot.n}")
    return discretization.encode(trajectory)


def ompl_guess(problem: Problem, discretization: Discretization, fallback: bool = True,
               slowdown: float = GUESS_SLOWDOWN, **seed_options: Any) -> np.ndarray:
    """A warm start: the OMPL seed's motion (`ompl_seed(problem, SeedOptions(**seed_options))`, never verified),
    slowed to `slowdown` times its time, sampled on the discretization's grid by `encode`. Slowed, because
    TOPP-RA's time-optimal timing rides the velocity and torque limits with bang-bang accelerations, leaving no
    room for the torque-rate limits and the jerk cost the NLP must meet. Without a seed motion: the paper's
    straight line (the default) with `fallback`, else NoGuess. A `planning_time` bounds the whole seed, its
    validity checker's construction included (SeedOptions.deadline): the guess is part of the plan's budget."""
    if not slowdown >= 1.0:
        raise OptionError(f"slowdown must be at least 1, got {slowdown!r}")
    if "planning_time" in seed_options and "deadline" not in seed_options:
        seed_options["deadline"] = time.perf_counter() + seed_options["planning_time"]
    seeded = ompl_seed(problem, SeedOptions(**seed_options))
    if seeded.trajectory is None:
        if fallback:
            return discretization.initial_guess(problem)
        raise NoGuess(f"OMPL + TOPP-RA gave no trajectory ({seeded.stopped}: {seeded.message})")
    return discretization.encode(slowed(seeded.trajectory, slowdown))
