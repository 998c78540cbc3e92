"""The path–velocity decomposition baseline: an OMPL joint-space path, made smooth, then timed by TOPP-RA.

The classic alternative to planning path and timing together, on the same problems and checked by the same
dense `verify`: the OMPL seed's motion (ocpkit.planner.ompl_seed, where each step and its costs are described),
verified as a plan. TOPP-RA cannot bound the torque rate, so the baseline normally fails the torque-rate check;
the plan says so in its status ("violated").
"""

from __future__ import annotations

import time

import numpy as np

from ocpkit.planner.ompl_seed import (MAX_STEP, OMPL_PLANNER, SeedOptions, hold, ompl_path, ompl_seed,
                                      planning_space)
from ocpkit.problem import Problem
from ocpkit.result import Hints, Plan, finish
from ocpkit.verify import GEOMETRY_CHECKS

NO_PATH_HINT = "OMPL found no path within its budget, so there is no trajectory: raise planning_time or max_checks"
CONTACT_HINT = ("the smoothed path comes into contact between its collision checks: lower resolution or raise "
                "margin")
TOPPRA_HINTS = Hints(
    stopped={"no_path": NO_PATH_HINT,
             "infeasible": "TOPP-RA cannot time this path within the velocity and torque limits: try another seed "
                           "(another path)"},
    violated=((("motion_time",), "the timed motion lies outside the time bounds: check time.min and time.max"),
              (GEOMETRY_CHECKS, CONTACT_HINT),
              (("torque_rate",), "TOPP-RA does not bound the torque rate: plan with ompl-topp3, which times the same "
                                 "path under every limit"),
              (("position", "velocity", "torque", "dynamics", "qd_consistency", "qdd_consistency"),
               "TOPP-RA holds the limits at its grid points only: raise grid_points"),
              (("boundary",), "the motion does not start and end at rest: the path's end tangents are not zero")),
    failed="try another seed (another path)")
"""What `ompl-toppra` can change: its path search, smoothing and TOPP-RA grid; the torque rate it cannot bound."""


def plan_ompl_toppra(problem: Problem, planner_name: str = OMPL_PLANNER, planning_time: float = 1.0, seed: int = 0,
                     resolution: float = 0.01, grid_points: int = 1000, margin: float = 0.01,
                     max_checks: int | None = None, max_step: float | None = MAX_STEP) -> Plan:
    """Plan `problem` by path–velocity decomposition: OMPL path, smoothing, TOPP-RA (the options of
    ocpkit.planner.ompl_seed.SeedOptions: `planner_name` one of OMPL_PLANNERS (by default OMPL_PLANNER, the ladder's
    OMPL rungs' search: RRTConnect, then LBKPIECE1), `planning_time` s, `seed`,
    `resolution` rad, `grid_points`, `margin` m, `max_checks`, `max_step` rad).

    Status: "verified" or "violated" (dense `verify`), "no_path" (OMPL found no exact path in its budget) or
    "infeasible" (TOPP-RA cannot time the path); without a trajectory the plan holds the start (`Plan.found`
    False). When the goal is the start, the path has length zero: the plan is to hold still at the start for
    time.min seconds, verified like any other motion, without calling OMPL or TOPP-RA."""
    began = time.perf_counter()
    method = {"planner": "ompl-toppra", "path_planner": planner_name, "grid_points": grid_points}
    seeded = ompl_seed(problem, SeedOptions(planner_name, planning_time, seed, resolution, grid_points, margin,
                                            max_checks, max_step))
    if seeded.trajectory is None:
        return finish(problem, hold(problem), seeded.stopped, method, began, setup_time=seeded.setup_time,
                      message=f"{seeded.message}; no trajectory: the plan holds the start", timing=seeded.timing,
                      path=seeded.path, found=False, hints=TOPPRA_HINTS)
    return finish(problem, seeded.trajectory, None, method, began, setup_time=seeded.setup_time,
                  message=seeded.message, timing=seeded.timing, path=seeded.path, hints=TOPPRA_HINTS)


def joint_path(problem: Problem, planner_name: str = OMPL_PLANNER, planning_time: float = 1.0, seed: int = 0,
               resolution: float = 0.01, margin: float = 0.01, max_checks: int | None = None,
               max_step: float | None = MAX_STEP) -> np.ndarray | None:
    """The baseline's simplified collision-free joint-space path (waypoints (k, n), rad) from start to goal, or None
    if the OMPL planner found none within `planning_time` s and `max_checks` configurations checked (options as for
    `plan_ompl_toppra`)."""
    free = planning_space(problem, margin)
    return ompl_path(problem, free, planner_name, planning_time, seed, resolution, max_checks, max_step).waypoints
