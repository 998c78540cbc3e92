"""Checks every Problem gets before planning, however it was made (a scenario file or Python)."""

from __future__ import annotations

import numpy as np

from ocpkit.errors import ScenarioError
from ocpkit.geometry import collision_report
from ocpkit.problem import Problem

LIMIT_SLACK = 1e-9  # rad: a start or goal exactly at a limit, given in degrees, must not fail on round-off


def validate(problem: Problem) -> None:
    """Raise ScenarioError if a number is malformed, start or goal is outside the joint limits or in collision,
    or t_f is impossible."""
    robot = problem.robot
    for label in ("start", "goal"):
        q = np.asarray(getattr(problem, label))
        if q.shape != (robot.n,) or not np.all(np.isfinite(q)):
            raise ScenarioError(f"{label} needs {robot.n} finite joint values, got {q.tolist()}")
    if not (np.isfinite(problem.mu) and problem.mu >= 0):
        raise ScenarioError(f"cost.mu must be a finite number ≥ 0, got {problem.mu}")
    t = problem.time
    if not (np.isfinite(t.max) and 0 < t.min <= t.guess <= t.max):
        raise ScenarioError(f"time bounds need 0 < min ≤ guess ≤ max, finite; got min={t.min}, guess={t.guess}, "
                            f"max={t.max}")
    for label, q in (("start", problem.start), ("goal", problem.goal)):
        outside = (q < robot.q_lower - LIMIT_SLACK) | (q > robot.q_upper + LIMIT_SLACK)
        for i in np.nonzero(outside)[0]:
            raise ScenarioError(
                f"{label}: joint {i + 1} ({robot.joint_names[i]}) = {np.degrees(q[i]):.2f} deg is outside "
                f"[{np.degrees(robot.q_lower[i]):.2f}, {np.degrees(robot.q_upper[i]):.2f}] deg")
        contacts = collision_report(robot, problem.scene, q)
        if contacts:
            raise ScenarioError(f"{label} configuration is in collision: " + "; ".join(contacts))
    lower_bound = problem.velocity_lower_bound()
    if problem.time.max < lower_bound:
        raise ScenarioError(f"time.max = {problem.time.max} s is below the velocity-limited minimum "
                            f"{lower_bound:.3f} s (max_i |goal_i - start_i| / qd_max_i)")
