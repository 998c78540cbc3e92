"""How general the simultaneous planner is: seeded random industrial6 problems it was never tuned on
(`ocpkit bench random`).

Each problem has a random start and goal inside most of the joint range and one obstacle sphere near the
wrist's position halfway along the straight joint-space path (so it is in the way), in the paper cases'
workspace. Problems whose start or goal is invalid are redrawn. Prints one line per problem, then the status
counts and the median computation time.
"""

from __future__ import annotations

import statistics
from collections import Counter
from collections.abc import Iterator

import numpy as np

from ocpkit.bench.common import machine
from ocpkit.errors import ScenarioError
from ocpkit.geometry import sphere_centers
from ocpkit.planner import plan
from ocpkit.problem import Problem, TimeBounds
from ocpkit.robots import load_robot
from ocpkit.scene import Scene, Workspace
from ocpkit.validation import validate

LOWER_DEG = [-150, -60, -60, -170, -110, -170]
UPPER_DEG = [150, 80, 120, 170, 90, 170]
WORKSPACE = Workspace(np.array([-1.0, -1.6, -0.3]), np.array([1.8, 1.6, 2.0]))
WRIST_SPHERE = 12


def random_problems(seed: int, count: int) -> Iterator[Problem]:
    """`count` valid random problems for industrial6, deterministic in `seed`."""
    rng = np.random.default_rng(seed)
    robot = load_robot("industrial6")
    lower, upper = np.radians(LOWER_DEG), np.radians(UPPER_DEG)
    while count:
        start, goal = rng.uniform(lower, upper), rng.uniform(lower, upper)
        center = sphere_centers(robot, (start + goal) / 2)[WRIST_SPHERE] + rng.normal(0, 0.1, 3)
        scene = Scene(center[None], np.array([rng.uniform(0.1, 0.25)]), WORKSPACE)
        problem = Problem(robot, start, goal, scene, TimeBounds(0.1, 10.0, 10.0), 0.3, f"random{count}")
        try:
            validate(problem)
        except ScenarioError:
            continue
        count -= 1
        yield problem


def run_random(seed: int = 1, count: int = 30, knots: int = 12) -> Counter:
    """Plan `count` random problems of `seed` with the simultaneous planner's defaults at `knots`; print a line
    per problem and the summary; return the status counts."""
    statuses, times = Counter(), []
    for problem in random_problems(seed, count):
        result = plan(problem, knots=knots)
        statuses[result.status] += 1
        times.append(result.stats.solve_time)
        print(f"{problem.name:<10}{result.status:>10}  t_f {result.trajectory.tf:5.2f} s (bound "
              f"{problem.velocity_lower_bound():4.2f})  {result.stats.solve_time:5.2f} s  {result.stats.rounds} rounds"
              + ("" if result.ok else f"  {result.verification.summary()}"), flush=True)
    print(f"{dict(statuses)}; median computation time {statistics.median(times):.2f} s at {knots} knots; {machine()}")
    return statuses
