"""What every benchmark shares: measuring plans, loading a folder of scenarios, writing CSV, naming the machine."""

from __future__ import annotations

import csv
import os
import platform
import statistics
from dataclasses import dataclass
from pathlib import Path

from ocpkit.errors import ScenarioError
from ocpkit.plan import Plan
from ocpkit.planner import plan
from ocpkit.problem import Problem
from ocpkit.report import RESULT_COLUMNS
from ocpkit.scenario import load_scenario


@dataclass(frozen=True)
class Measured:
    """One method on one case: the last plan, median computation time and set-up time (s)."""

    plan: Plan
    solve_time: float
    setup_time: float


def measure(problem: Problem, repeats: int, **options) -> Measured:
    """Plan `problem` `repeats` times with `options` (as for `ocpkit.plan`)."""
    plans = [plan(problem, **options) for _ in range(max(repeats, 1))]
    return Measured(plans[-1], statistics.median(p.stats.solve_time for p in plans), plans[0].stats.setup_time)


def load_all(folder: Path) -> list[Problem]:
    """Every scenario (*.yaml) in `folder`, sorted by file name; ScenarioError if there is none."""
    files = sorted(folder.glob("*.yaml"))
    if not files:
        raise ScenarioError(f"no scenario files (*.yaml) in {folder}")
    return [load_scenario(f) for f in files]


def write_csv(path: Path, rows: list[dict], columns: tuple[str, ...] = RESULT_COLUMNS) -> None:
    """`rows` as CSV with `columns`, creating the folder."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)


def cpu_name() -> str:
    """The CPU model name (for the machine line under a benchmark table)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine() -> str:
    """One line naming this machine, for under a benchmark table."""
    return f"machine: {cpu_name()}, {os.cpu_count()} cores, Python {platform.python_version()}"
