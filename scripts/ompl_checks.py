"""OMPL path search speed on MotionBenchMaker problems: collision checks per second and RRTConnect's time to its
first path, with the planner's own validity test (ocpkit.planner.ompl_seed.planning_space) at its defaults.

Run from the repository root:  .venv/bin/python scripts/ompl_checks.py DIR [--robot panda] [--problems 1 10]
[--planner rrtconnect-lbkpiece] (another of ocpkit.planner.ompl_seed.OMPL_PLANNERS: the ladder's OMPL rungs search
with rrtconnect-lbkpiece). DIR is the folder `ocpkit data mbm --dir DIR` filled. Prints, per scene and over all
problems, the median configurations checked per second during the search, the median search time and how many
searches found a path within --planning-time seconds; all measured in this one run.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

import ocpkit
from ocpkit.formats.mbm import SCENES
from ocpkit.planner.ompl_seed import OMPL_PLANNERS, SeedOptions, ompl_path, planning_space


def search(path: Path, planning_time: float, planner_name: str) -> tuple[float, float, bool]:
    """(configurations checked per second, search seconds, path found) of one search."""
    problem = ocpkit.load_scenario(path)
    options = SeedOptions(planner_name=planner_name, planning_time=planning_time)
    free = planning_space(problem, options.margin)
    found = ompl_path(problem, free, options.planner_name, planning_time, options.seed, options.resolution,
                      max_step=options.max_step)
    return free.checks / found.path_time, found.path_time, found.waypoints is not None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("directory", type=Path)
    parser.add_argument("--robot", default="panda")
    parser.add_argument("--problems", type=int, nargs=2, default=(1, 10), metavar=("FIRST", "LAST"))
    parser.add_argument("--planning-time", type=float, default=10.0)
    parser.add_argument("--planner", default="rrtconnect", choices=sorted(OMPL_PLANNERS))
    args = parser.parse_args()
    rates, times, found = [], [], 0
    print(f"{'scene':18} {'checks/s':>10} {'search s':>9} {'found':>6}")
    for scene in SCENES:
        rows = [search(args.directory / args.robot / scene / f"{k:04d}.yaml", args.planning_time, args.planner)
                for k in range(args.problems[0], args.problems[1] + 1)]
        rates += [r for r, _, _ in rows]
        times += [t for _, t, _ in rows]
        found += sum(f for _, _, f in rows)
        print(f"{scene:18} {statistics.median(r for r, _, _ in rows):10.0f} "
              f"{statistics.median(t for _, t, _ in rows):9.3f} {sum(f for _, _, f in rows):3d}/{len(rows)}")
    print(f"{'all':18} {statistics.median(rates):10.0f} {statistics.median(times):9.3f} {found:3d}/{len(rates)}")


if __name__ == "__main__":
    main()
