"""What a plan reports outside: the JSON header and the results-table row."""

from __future__ import annotations

import json
from dataclasses import dataclass

from ocpkit.problem import Problem
from ocpkit.result import Plan

METHOD_COLUMNS = ("planner", "transcription", "knots", "solver", "dynamics")
KEY_COLUMNS = ("suite", "case", *METHOD_COLUMNS)
"""The columns that name a row: one row per suite, case and method in a results.csv."""
RESULT_COLUMNS = (*KEY_COLUMNS, "status", "tf", "solve_time_s", "setup_time_s", "iterations", "max_violation",
                  "checks", "extra")


def trajectory_header(problem: Problem, plan: Plan) -> dict:
    """Header fields of the trajectory JSON for `plan`, its verification's checks with their tolerances
    included."""
    return {"robot": problem.robot.name, "joint_names": list(problem.robot.joint_names), "method": plan.method,
            "status": plan.status, "found": plan.found, "solve_time_s": plan.stats.solve_time,
            "setup_time_s": plan.stats.setup_time, "iterations": plan.stats.iterations,
            "checks": [{"name": c.name, "worst": c.worst, "tolerance": c.tolerance, "unit": c.unit, "time_s": c.time,
                        "where": c.where} for c in plan.verification.checks]}


def result_row(suite: str, case: str, plan: Plan, solve_time: float, setup_time: float) -> dict:
    """One results.csv row: times in s at full precision (so tables read back from the file are the same),
    max_violation (see `max_violation`), the verification summary as `checks` and the planner's own figures
    (PlanStats.figures) as JSON in `extra`."""
    return {"suite": suite, "case": case, **{k: plan.method.get(k, "") for k in METHOD_COLUMNS},
            "status": plan.status, "tf": plan.trajectory.tf, "solve_time_s": solve_time, "setup_time_s": setup_time,
            "iterations": plan.stats.iterations, "max_violation": max_violation(plan),
            "checks": plan.verification.summary(), "extra": json.dumps(plan.stats.figures())}


def row_key(row: dict, columns: tuple[str, ...] = KEY_COLUMNS) -> tuple[str, ...]:
    """The key `columns` (default KEY_COLUMNS) of `row` as strings (as read back from a CSV file)."""
    return tuple(str(row.get(c, "")) for c in columns)


@dataclass(frozen=True)
class Recorded:
    """A results row's figures as numbers: status, t_f (s), computation and set-up time (s), iterations, the
    verification summary, the planner's own figures (`extra`: the JSON object of PlanStats.figures, as written)
    and the largest violation (`max_violation`)."""

    status: str
    tf: float
    solve_time: float
    setup_time: float
    iterations: int
    checks: str
    extra: dict
    max_violation: float = 0.0

    @property
    def ok(self) -> bool:
        return self.status == "verified"

    @classmethod
    def of(cls, row: dict) -> Recorded:
        """The figures of `row`, fresh from `result_row` or read back from results.csv (of any version: `extra`
        keeps whatever keys the file has; an empty or missing one reads as {})."""
        return cls(row["status"], float(row["tf"]), float(row["solve_time_s"]), float(row["setup_time_s"]),
                   int(row["iterations"]), row["checks"], json.loads(row.get("extra") or "{}"),
                   float(row["max_violation"]))


def max_violation(plan: Plan) -> float:
    """The largest excess of any checked quantity over its limit (relative for limits and dynamics, metres for
    sphere contact, rad for boundary errors), 0 if none, nan for a motion that was not verified."""
    if plan.verification.skipped:
        return float("nan")
    return max([0.0] + [c.worst for c in plan.verification.checks])
