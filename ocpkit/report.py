"""What a plan reports outside: the JSON header and the results-table row."""

from __future__ import annotations

from ocpkit.plan import Plan
from ocpkit.problem import Problem

RESULT_COLUMNS = ("suite", "case", "planner", "transcription", "knots", "solver", "dynamics", "status", "tf",
                  "solve_time_s", "setup_time_s", "iterations", "max_violation")


def trajectory_header(problem: Problem, plan: Plan) -> dict:
    """Header fields of the trajectory JSON for `plan`."""
    return {"robot": problem.robot.name, "joint_names": list(problem.robot.joint_names), "method": plan.method,
            "status": plan.status, "solve_time_s": plan.stats.solve_time, "iterations": plan.stats.iterations}


def result_row(suite: str, case: str, plan: Plan, solve_time: float, setup_time: float) -> dict:
    """One results.csv row (max_violation: see `max_violation`)."""
    return {"suite": suite, "case": case, **{k: plan.method.get(k, "") for k in
            ("planner", "transcription", "knots", "solver", "dynamics")}, "status": plan.status,
            "tf": f"{plan.trajectory.tf:.4f}", "solve_time_s": f"{solve_time:.4f}", "setup_time_s": f"{setup_time:.3f}",
            "iterations": plan.stats.iterations, "max_violation": f"{max_violation(plan):.3g}"}


def max_violation(plan: Plan) -> float:
    """The largest excess of any checked quantity over its limit (relative for limits and dynamics, metres for
    sphere contact, rad for boundary errors), 0 if none."""
    return max([0.0] + [c.worst for c in plan.verification.checks])
