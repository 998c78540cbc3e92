"""The paper's experiment (Table II): four pick-and-place cases at 12 and 8 knots, μ = 0.3.

Computation time is the wall time of one plan whose NLP shape is already built (all refinement rounds
and the dense verification included), median over `repeats` runs; set-up is the first build of a shape.
"""

from __future__ import annotations

import csv
import platform
import statistics
from pathlib import Path

from ocpkit.errors import ScenarioError
from ocpkit.planner import plan
from ocpkit.report import RESULT_COLUMNS, result_row, trajectory_header
from ocpkit.scenario import load_scenario
from ocpkit.trajectory import write_json

PAPER_TF = {12: [1.65, 1.23, 1.05, 1.08], 8: [1.98, 1.23, 1.09, 1.11]}
PAPER_SOLVE = {12: [2.55, 2.37, 2.39, 2.57], 8: [1.28, 1.75, 0.84, 1.32]}
PAPER_SETUP = 5.9
KNOTS = (12, 8)


def run_paper_benchmark(scenarios: Path, out: Path, repeats: int = 5) -> list[dict]:
    """Solve every case at every knot count, print the table, write results.csv and trajectories/."""
    files = sorted(scenarios.glob("case*.yaml"))
    if not files:
        raise ScenarioError(f"no case*.yaml in {scenarios}")
    problems = [load_scenario(f) for f in files]
    rows, table = [], {}
    for knots in KNOTS:
        for problem in problems:
            plans = [plan(problem, knots=knots) for _ in range(max(repeats, 1))]
            setup = plans[0].stats.setup_time
            solve = statistics.median(p.stats.solve_time for p in plans)
            final = plans[-1]
            rows.append(result_row("paper", problem.name, final, solve, setup))
            table[problem.name, knots] = (final, solve, setup)
            name = f"{problem.name}-{final.method['planner']}-{final.method['transcription']}-{knots}.json"
            write_json(out / "trajectories" / name, final.trajectory, trajectory_header(problem, final))
    _write_csv(out / "results.csv", rows)
    print(_format_table(problems, table, repeats))
    return rows


def _write_csv(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=RESULT_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def _format_table(problems, table, repeats: int) -> str:
    names = [p.name for p in problems]
    width = 24
    head = f"{'time [s]':<20}{'knots':>6}  " + "".join(f"{n:>{width}}" for n in names)
    lines = ["Motion time and computation time (ours, paper in parentheses; [velocity lower bound])", head,
             "-" * len(head)]
    for label, knots in [("motion time t_f", k) for k in KNOTS] + [("computation time", k) for k in KNOTS]:
        cells = []
        for k, problem in enumerate(problems):
            result, solve, _ = table[problem.name, knots]
            if label.startswith("motion"):
                cell = f"{result.trajectory.tf:.2f} ({PAPER_TF[knots][k]:.2f}) [{problem.velocity_lower_bound():.2f}]"
            else:
                cell = f"{solve:.3f} ({PAPER_SOLVE[knots][k]:.2f})"
            cells.append(f"{cell:>{width}}")
        lines.append(f"{label:<20}{knots:>6}  " + "".join(cells))
    lines.append(f"{'status':<20}{'':>6}  " + "".join(
        f"{'/'.join(table[p.name, k][0].status for k in KNOTS):>{width}}" for p in problems))
    setups = ", ".join(f"{k} knots {max(table[p.name, k][2] for p in problems):.2f} s" for k in KNOTS)
    lines.append(f"one-time set-up: {setups} (paper {PAPER_SETUP} s)")
    all_solves = {k: statistics.median(table[p.name, k][1] for p in problems) for k in KNOTS}
    lines.append("median computation time: " + ", ".join(
        f"{k} knots {all_solves[k]:.3f} s ({statistics.median(PAPER_SOLVE[k]) / all_solves[k]:.0f}x faster than "
        f"the paper)" for k in KNOTS))
    lines.append(f"machine: {platform.processor() or platform.machine()}, {platform.python_implementation()} "
                 f"{platform.python_version()}; medians of {repeats} runs per plan")
    return "\n".join(lines)
