"""OMPL path search speed on MotionBenchMaker problems: collision checks per second and RRTConnect's time to its
first path, with the planner's own validity test (ocpkit.planner.ompl_seed.planning_space) at its defaults.

Run from the repository root:  .venv/bin/python scripts/ompl_checks.py DIR [--robot panda] [--problems 1 10]
[--planner rrtconnect-lbkpiece] (another of ocpkit.planner.ompl_seed.OMPL_PLANNERS: the ladder's OMPL rungs search
with rrtconnect-lbkpiece). DIR is the folder `ocpkit data mbm --dir DIR` filled. Prints, per scene and over all
problems, the median configurations checked per second during the search (its checks over its time: the path's
simplification, which checks its shortcuts, is timed and counted apart), the median search time, the median
simplification time and how many searches found a path within --planning-time seconds; all measured in this one run.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

import ocpkit
from ocpkit.errors import ScenarioError
from ocpkit.formats.mbm import SCENES
from ocpkit.planner.ompl_seed import OMPL_PLANNERS, SeedOptions, ompl_path, planning_space


def search(path: Path, planning_time: float, planner_name: str) -> tuple[float, float, float, bool] | None:
    """(configurations checked per second by the search, search seconds, simplification seconds, path found) of one
    search; None for a problem the scenario checks reject (a start or goal in collision: a few MBM problems of the
    UR5), which is left out, as `ocpkit bench run` leaves it out."""
    try:
        problem = ocpkit.load_scenario(path)
    except ScenarioError as exc:
        print(f"left out: {exc}")
        return None
    options = SeedOptions(planner_name=planner_name, planning_time=planning_time)
    free = planning_space(problem, options.margin)
    found = ompl_path(problem, free, options.planner_name, planning_time, options.seed, options.resolution,
                      max_step=options.max_step)
    return found.search_checks / found.path_time, found.path_time, found.simplify_time, found.waypoints is not None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("directory", type=Path)
    parser.add_argument("--robot", default="panda")
    parser.add_argument("--problems", type=int, nargs=2, default=(1, 10), metavar=("FIRST", "LAST"))
    parser.add_argument("--planning-time", type=float, default=10.0)
    parser.add_argument("--planner", default="rrtconnect", choices=sorted(OMPL_PLANNERS))
    args = parser.parse_args()
    print(f"{'scene':18} {'checks/s':>10} {'search s':>9} {'simplify s':>11} {'found':>6}")
    every = []
    for scene in SCENES:
        searched = [search(args.directory / args.robot / scene / f"{k:04d}.yaml", args.planning_time, args.planner)
                    for k in range(args.problems[0], args.problems[1] + 1)]
        rows = [row for row in searched if row is not None]
        every += rows
        print(_row(scene, rows))
    print(_row("all", every))


def _row(name: str, rows: list[tuple[float, float, float, bool]]) -> str:
    """A table row: the medians of the rates and times of `rows` (`search`) and how many found a path."""
    rate, search_time, simplify_time = (statistics.median(column) for column in list(zip(*rows))[:3])
    return f"{name:18} {rate:10.0f} {search_time:9.3f} {simplify_time:11.3f} {sum(r[3] for r in rows):3d}/{len(rows)}"


if __name__ == "__main__":
    main()
