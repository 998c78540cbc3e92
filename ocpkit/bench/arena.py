"""Export a `bench run` results.csv as OMPL benchmark logs, which OMPL's `ompl_benchmark_statistics.py` (shipped in
the ompl wheel as `ompl/ompl_benchmark_statistics.py`, its reader `ompl.tools.readBenchmarkLog`) loads into the
SQLite database that Planner Arena (plannerarena.org) plots.

One log per scene (an OMPL "experiment"); each method is a "planner", each (case, repeat) one of its runs, with
the properties RUN_PROPERTIES. The layout is OMPL's log format (ompl.kavrakilab.org/benchmark.html)."""

from __future__ import annotations

import re
from datetime import datetime, timezone
from pathlib import Path

from ocpkit.bench.common import cpu_name
from ocpkit.bench.metrics import PLAN_METRICS

RUN_PROPERTIES = (("time", "REAL", "solve_time_s"), ("solved", "BOOLEAN", None), ("status", "ENUM", "status"),
                  ("motion time", "REAL", "tf"), ("setup time", "REAL", "setup_time_s"),
                  ("iterations", "INTEGER", "iterations"), ("max violation", "REAL", "max_violation"),
                  *((name.replace("_", " "), "REAL", name) for name in PLAN_METRICS))
"""(OMPL property name, type, results.csv column) of each run; `solved` is status == verified."""
STATUSES = ("verified", "violated", "infeasible", "iteration_limit", "time_limit", "failed", "no_path")
"""The plan statuses (ocpkit.plan.Plan), in the order of the `status` enum."""


def write_arena_logs(rows: list[dict], folder: Path, suite: str) -> list[Path]:
    """One OMPL benchmark log per scene of `rows` in `folder`, scenes, methods and runs sorted (not in the order the
    plans finished); returns their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = sorted(rows, key=lambda r: (r["scene"], r["method"], r["case"], int(r["repeat"])))
    paths = []
    for scene in dict.fromkeys(r["scene"] for r in rows):
        path = folder / f"{re.sub(r'[^A-Za-z0-9_.-]+', '_', scene)}.log"
        path.write_text(_log(f"{suite}-{scene}", [r for r in rows if r["scene"] == scene]))
        paths.append(path)
    return paths


def _log(experiment: str, rows: list[dict]) -> str:
    methods = list(dict.fromkeys(r["method"] for r in rows))
    runs = max(sum(r["method"] == m for r in rows) for m in methods)
    lines = ["ocpkit version 0.1.0", f"Experiment {experiment.replace(' ', '_')}", "Running on ocpkit",
             f"Starting at {datetime.now(timezone.utc):%Y-%m-%d %H:%M:%S}",
             "<<<|", f"ocpkit bench run, scene {experiment}", "|>>>", "<<<|", cpu_name(), "|>>>",
             "0 is the random seed", f"{max(float(r['solve_time_s']) for r in rows):.6f} seconds per run",
             "0 MB per run", f"{runs} runs per planner",
             f"{sum(float(r['wall_time_s']) for r in rows):.6f} seconds spent to collect the data",
             "1 enum types", "|".join(("status", *STATUSES)), f"{len(methods)} planners"]
    for method in methods:
        lines += [method.replace(" ", "_"), "0 common properties", f"{len(RUN_PROPERTIES)} properties for each run"]
        lines += [f"{name} {kind}" for name, kind, _ in RUN_PROPERTIES]
        mine = [r for r in rows if r["method"] == method]
        lines.append(f"{len(mine)} runs")
        lines += ["".join(f"{_value(row, kind, column)}; " for _, kind, column in RUN_PROPERTIES) for row in mine]
        lines.append(".")
    return "\n".join(lines) + "\n"


def _value(row: dict, kind: str, column: str | None) -> str:
    """A run's property value as OMPL writes it ('nan' for none)."""
    if column is None:
        return str(int(row["status"] == "verified"))
    if kind == "ENUM":
        return str(STATUSES.index(row[column]) if row[column] in STATUSES else len(STATUSES))
    return str(row[column]) if row[column] != "" else "nan"
