"""How general the simultaneous planner is: seeded random industrial6 problems it was never tuned on.

Each problem has a random start and goal inside most of the joint range and one obstacle sphere near the
wrist's position halfway along the straight joint-space path (so it is in the way), in the paper cases'
workspace. Problems whose start or goal is invalid are redrawn.

Run from the repository root:  .venv/bin/python benchmarks/random_scenarios.py [--seed 1] [--count 30] [--knots 12]
Prints one line per problem and the status counts with the median computation time.
"""

from __future__ import annotations

import argparse
import statistics
from collections import Counter

import numpy as np

import ocpkit
from ocpkit.errors import ScenarioError
from ocpkit.geometry import sphere_centers
from ocpkit.scenario import validate
from ocpkit.scene import Scene, Workspace

LOWER_DEG = [-150, -60, -60, -170, -110, -170]
UPPER_DEG = [150, 80, 120, 170, 90, 170]
WORKSPACE = Workspace(np.array([-1.0, -1.6, -0.3]), np.array([1.8, 1.6, 2.0]))
WRIST_SPHERE = 12


def random_problems(seed: int, count: int):
    """`count` valid random problems for industrial6, deterministic in `seed`."""
    rng = np.random.default_rng(seed)
    robot = ocpkit.load_robot("industrial6")
    lower, upper = np.radians(LOWER_DEG), np.radians(UPPER_DEG)
    while count:
        start, goal = rng.uniform(lower, upper), rng.uniform(lower, upper)
        center = sphere_centers(robot, (start + goal) / 2)[WRIST_SPHERE] + rng.normal(0, 0.1, 3)
        scene = Scene(center[None], np.array([rng.uniform(0.1, 0.25)]), WORKSPACE)
        problem = ocpkit.Problem(robot, start, goal, scene, ocpkit.TimeBounds(0.1, 10.0, 10.0), 0.3, f"random{count}")
        try:
            validate(problem)
        except ScenarioError:
            continue
        count -= 1
        yield problem


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--count", type=int, default=30)
    parser.add_argument("--knots", type=int, default=12)
    args = parser.parse_args()
    statuses, times = Counter(), []
    for problem in random_problems(args.seed, args.count):
        result = ocpkit.plan(problem, knots=args.knots)
        statuses[result.status] += 1
        times.append(result.stats.solve_time)
        print(f"{problem.name:<10}{result.status:>10}  t_f {result.trajectory.tf:5.2f} s (bound "
              f"{problem.velocity_lower_bound():4.2f})  {result.stats.solve_time:5.2f} s  {result.stats.rounds} rounds"
              + ("" if result.ok else f"  {result.verification.summary()}"), flush=True)
    print(f"{dict(statuses)}; median computation time {statistics.median(times):.2f} s at {args.knots} knots")


if __name__ == "__main__":
    main()
