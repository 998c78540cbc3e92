"""The paper's experiment (Table II): four pick-and-place cases at 12 and 8 knots, μ = 0.3.

Computation time is the wall time of one plan whose NLP shape is already built (all refinement rounds
and the dense verification included), median over `repeats` runs; set-up is the first build of a shape.
Every dynamics form given is run in the same process, so their times compare on the same machine state.
"""

from __future__ import annotations

import csv
import os
import platform
import statistics
from dataclasses import dataclass
from pathlib import Path

from ocpkit.errors import ScenarioError
from ocpkit.planner import Plan, plan
from ocpkit.problem import Problem
from ocpkit.report import RESULT_COLUMNS, result_row, trajectory_header
from ocpkit.scenario import load_scenario
from ocpkit.trajectory import write_json

PAPER_TF = {12: [1.65, 1.23, 1.05, 1.08], 8: [1.98, 1.23, 1.09, 1.11]}
PAPER_SOLVE = {12: [2.55, 2.37, 2.39, 2.57], 8: [1.28, 1.75, 0.84, 1.32]}
PAPER_SETUP = 5.9
KNOTS = (12, 8)
WIDTH = 24


@dataclass(frozen=True)
class Measured:
    """One case at one knot count: the last plan, median computation time and set-up time (s)."""

    plan: Plan
    solve_time: float
    setup_time: float


def run_paper_benchmark(scenarios: Path, out: Path, repeats: int = 5,
                        dynamics: tuple[str, ...] = ("casadi-rnea", "casadi")) -> list[dict]:
    """Solve every case at every knot count with every dynamics form; print the table (the first form in the
    paper's layout, the others summarized), write results.csv and trajectories/."""
    files = sorted(Path(scenarios).glob("case*.yaml"))
    if not files:
        raise ScenarioError(f"no case*.yaml in {scenarios}")
    problems = [load_scenario(f) for f in files]
    rows, measured = [], {}
    for form in dynamics:
        for knots in KNOTS:
            for problem in problems:
                m = _measure(problem, knots, form, repeats)
                measured[form, problem.name, knots] = m
                rows.append(result_row("paper", problem.name, m.plan, m.solve_time, m.setup_time))
                if form == dynamics[0]:
                    name = f"{problem.name}-{m.plan.method['planner']}-{m.plan.method['transcription']}-{knots}.json"
                    write_json(out / "trajectories" / name, m.plan.trajectory, trajectory_header(problem, m.plan))
    _write_csv(out / "results.csv", rows)
    print(_paper_table(problems, {(c, k): m for (f, c, k), m in measured.items() if f == dynamics[0]}, dynamics[0]))
    print(_comparison(problems, measured, dynamics))
    print(f"machine: {_cpu_name()}, {os.cpu_count()} cores, Python {platform.python_version()}; "
          f"computation times are medians of {repeats} runs per plan")
    return rows


def _measure(problem: Problem, knots: int, dynamics: str, repeats: int) -> Measured:
    plans = [plan(problem, knots=knots, dynamics=dynamics) for _ in range(max(repeats, 1))]
    return Measured(plans[-1], statistics.median(p.stats.solve_time for p in plans), plans[0].stats.setup_time)


def _write_csv(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=RESULT_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)


def _paper_table(problems: list[Problem], measured: dict, dynamics: str) -> str:
    head = f"{'time [s]':<20}{'knots':>6}" + "".join(f"{p.name:>{WIDTH}}" for p in problems)
    lines = [f"Table II, simultaneous planner (chebyshev + ipopt, dynamics {dynamics}): ours (paper) "
             "[velocity lower bound]", head, "-" * len(head)]
    for knots in KNOTS:
        cells = [f"{measured[p.name, knots].plan.trajectory.tf:.2f} ({PAPER_TF[knots][k]:.2f}) "
                 f"[{p.velocity_lower_bound():.2f}]" for k, p in enumerate(problems)]
        lines.append(_row("motion time t_f", knots, cells))
    for knots in KNOTS:
        cells = [f"{measured[p.name, knots].solve_time:.3f} ({PAPER_SOLVE[knots][k]:.2f})" for k, p in enumerate(problems)]
        lines.append(_row("computation time", knots, cells))
    for knots in KNOTS:
        lines.append(_row("status", knots, [measured[p.name, knots].plan.status for p in problems]))
    return "\n".join(lines)


def _comparison(problems: list[Problem], measured: dict, dynamics: tuple[str, ...]) -> str:
    lines = [f"{'dynamics':<14}{'knots':>6}{'median computation':>20}{'vs paper':>10}{'set-up':>9}"
             f"{'paper set-up':>14}{'verified':>10}"]
    for form in dynamics:
        for knots in KNOTS:
            cases = [measured[form, p.name, knots] for p in problems]
            median = statistics.median(m.solve_time for m in cases)
            setup = max(m.setup_time for m in cases)
            speedup = statistics.median(PAPER_SOLVE[knots]) / median
            verified = sum(m.plan.ok for m in cases)
            lines.append(f"{form:<14}{knots:>6}{median:>19.3f}s{speedup:>9.1f}x{setup:>8.2f}s{PAPER_SETUP:>13.1f}s"
                         f"{verified:>8}/{len(cases)}")
    return "\n".join(lines)


def _row(label: str, knots: int, cells: list[str]) -> str:
    return f"{label:<20}{knots:>6}" + "".join(f"{c:>{WIDTH}}" for c in cells)


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()
