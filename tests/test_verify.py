"""verify on hand-made trajectories: each kind of violation is caught, a clean motion passes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers import REPO, quintic

from ocpkit import load_scenario, verify
from ocpkit.verify import SCALED_LIMITS, Check, Verification
from ocpkit.formats.trajectory import Samples, Trajectory

PROBLEM = load_scenario(REPO / "scenarios/paper/case2.yaml")


def by_name(verification):
    return {c.name: c for c in verification.checks}


def test_slow_motion_is_clean_except_through_the_obstacle():
    checks = by_name(verify(PROBLEM, quintic(PROBLEM, 4.0)))
    assert all(checks[k].ok for k in ("position", "velocity", "torque", "torque_rate", "dynamics", "boundary"))
    assert not checks["obstacle"].ok  # case 2's obstacle sits on the straight joint-space path
    assert checks["obstacle"].worst > 0.01


def test_without_obstacles_a_slow_motion_verifies():
    free = dataclasses.replace(PROBLEM, scene=dataclasses.replace(PROBLEM.scene, obstacle_centers=np.zeros((0, 3)),
                                                                  obstacle_radii=np.zeros(0)))
    result = verify(free, quintic(free, 4.0))
    assert result.ok, result.summary()
    assert len(result.violation_times) == 0


def test_too_fast_motion_breaks_velocity_and_torque_limits():
    result = verify(PROBLEM, quintic(PROBLEM, 0.3))
    checks = by_name(result)
    assert not checks["velocity"].ok and not checks["torque"].ok
    assert 0 < checks["velocity"].time < 0.3
    assert len(result.violation_times) > 0


def test_torque_that_does_not_match_the_motion_fails_dynamics():
    checks = by_name(verify(PROBLEM, quintic(PROBLEM, 4.0, tau_offset=30.0)))
    assert not checks["dynamics"].ok
    assert checks["dynamics"].worst == pytest.approx(30.0 / (2 * PROBLEM.robot.tau_max).min(), rel=1e-6)


def test_only_path_constraint_violations_are_fixable_by_a_refinement_round():
    free = dataclasses.replace(PROBLEM, scene=dataclasses.replace(PROBLEM.scene, obstacle_centers=np.zeros((0, 3)),
                                                                  obstacle_radii=np.zeros(0)))
    mismatched = verify(free, quintic(free, 4.0, tau_offset=30.0))
    assert not mismatched.ok and not mismatched.fixable  # the dynamics alone: only a finer grid helps
    assert verify(PROBLEM, quintic(PROBLEM, 4.0)).fixable  # through the obstacle
    assert verify(free, quintic(free, 0.3)).fixable  # over the velocity limit


def test_wrong_goal_fails_boundary():
    moved = dataclasses.replace(PROBLEM, goal=PROBLEM.goal + 0.01)
    assert not by_name(verify(moved, quintic(PROBLEM, 4.0)))["boundary"].ok


@pytest.mark.parametrize("tf", [3e11, 0.05])
def test_motion_time_outside_the_time_bounds_fails_without_sampling(tf):
    verification = verify(PROBLEM, quintic(PROBLEM, tf))  # 3e11 s at 1 ms would be 2 PiB of samples
    assert [c.name for c in verification.checks] == ["motion_time"] and not verification.ok


def scaled(trajectory: Trajectory, field: str, factor: float) -> Trajectory:
    """`trajectory` with one sampled field multiplied by `factor` (an inconsistent set of samples)."""
    def at(t: np.ndarray) -> Samples:
        samples = trajectory.interpolant(t)
        return dataclasses.replace(samples, **{field: factor * getattr(samples, field)})

    return Trajectory(at(trajectory.knots.t), at)


def test_a_consistent_motion_passes_both_consistency_checks():
    checks = by_name(verify(PROBLEM, quintic(PROBLEM, 4.0)))
    assert checks["qd_consistency"].worst < 1e-4 and checks["qdd_consistency"].worst < 1e-4


@pytest.mark.parametrize("field, check", [("qd", "qd_consistency"), ("qdd", "qdd_consistency")])
def test_a_derivative_that_is_not_the_derivative_fails_consistency(field, check):
    checks = by_name(verify(PROBLEM, scaled(quintic(PROBLEM, 4.0), field, 1.1)))
    assert not checks[check].ok
    other = {"qd_consistency", "qdd_consistency"} - {check}
    assert field == "qd" or checks[other.pop()].ok  # scaling qdd leaves q against qd consistent


def test_a_jump_in_acceleration_is_consistent():
    """Bang-bang in one joint (q̈ = ±a, switching at a time between samples), as TOPP-RA's timing makes."""
    tf, a = 2.0005, 0.2  # the switch at 1.00025 s lies between samples

    def at(t: np.ndarray) -> Samples:
        t = np.asarray(t, dtype=float)
        first = t <= tf / 2
        late = tf - t
        q1 = np.where(first, a * t**2 / 2, a * tf**2 / 4 - a * late**2 / 2)
        q = np.tile(PROBLEM.start, (len(t), 1))
        q[:, 0] += q1
        qd, qdd = np.zeros_like(q), np.zeros_like(q)
        qd[:, 0] = np.where(first, a * t, a * late)
        qdd[:, 0] = np.where(first, a, -a)
        return Samples(t, q, qd, qdd, np.zeros_like(q), np.zeros_like(q))

    checks = by_name(verify(PROBLEM, Trajectory(at(np.array([0.0, 1.0005, tf])), at)))
    assert checks["qd_consistency"].ok and checks["qdd_consistency"].worst < 1e-9


RISING = int(np.argmax(PROBLEM.goal - PROBLEM.start))  # a joint whose quintic motion rises to its goal


def limited_above(problem, joint: int, excess: float):
    """`problem` whose joint `joint` has its upper position limit `excess` rad below the goal, which the quintic
    motion reaches only at its end (it rises monotonically)."""
    robot = problem.robot
    upper = robot.q_upper.copy()
    upper[joint] = problem.goal[joint] - excess
    return dataclasses.replace(problem, robot=dataclasses.replace(robot, q_upper=upper))


def test_a_position_limit_is_hard_half_a_percent_past_is_violated_naming_joint_and_time():
    robot, joint = PROBLEM.robot, RISING
    excess = 0.005 * (robot.q_upper[joint] - robot.q_lower[joint])  # within the old 1 % of the range
    checks = by_name(verify(limited_above(PROBLEM, joint, excess), quintic(PROBLEM, 4.0)))
    position = checks["position"]
    assert not position.ok and position.unit == "rad"
    assert position.worst == pytest.approx(excess, rel=1e-6)
    assert position.where == robot.joint_names[joint] and position.time == pytest.approx(4.0, abs=2e-3)
    summary = verify(limited_above(PROBLEM, joint, excess), quintic(PROBLEM, 4.0)).summary()
    assert f"({robot.joint_names[joint]})" in summary and "t=4.000 s" in summary


def test_round_off_past_a_position_limit_passes():
    checks = by_name(verify(limited_above(PROBLEM, RISING, 5e-5), quintic(PROBLEM, 4.0)))
    assert checks["position"].ok and checks["position"].worst == pytest.approx(5e-5, rel=1e-6)


def test_a_motion_that_was_not_verified_is_never_ok_and_says_why():
    unverified = Verification.not_run("stopped by time")
    assert not unverified.ok and not unverified.fixable and unverified.checks == ()
    assert unverified.summary() == "not verified: stopped by time"


def test_the_worst_failure_is_the_largest_failed_checks_value_and_inf_when_not_verified():
    checks = (Check("torque", 0.3, 0.01, 0.1, "rel"), Check("obstacle", 0.02, 0.0, 0.2, "m"),
              Check("velocity", 0.005, 0.01, 0.3, "rel"))  # within its tolerance: not a failure
    assert Verification(checks, np.zeros(0)).worst_failure == 0.3
    assert Verification(checks[2:], np.zeros(0)).worst_failure == 0.0
    assert Verification.not_run("stopped").worst_failure == np.inf


def test_limits_first_leaves_contact_unchecked_only_where_a_limit_is_exceeded():
    """Too fast and through case 2's obstacle: limits first reports the limits, their violation times and every
    other check but contact, and is never ok; within the limits it is the full verification."""
    fast, slow = quintic(PROBLEM, 0.3), quintic(PROBLEM, 4.0)
    first, full = verify(PROBLEM, fast, limits_first=True), verify(PROBLEM, fast)
    assert not first.contact_checked and full.contact_checked and not first.ok
    assert set(by_name(full)) - set(by_name(first)) == {"self_collision", "obstacle", "workspace"}
    assert all(check == by_name(full)[check.name] for check in first.checks)
    assert first.fixable and first.penetration == 0.0 and first.limit_excess == full.limit_excess
    assert first.summary().endswith("; contact not checked")
    worst_limit = max((c for c in first.checks if c.name in ("position", *SCALED_LIMITS)),
                      key=lambda c: c.worst - c.tolerance)
    assert first.violation_times[0] == worst_limit.time  # worst first
    within = verify(PROBLEM, slow, limits_first=True)
    assert within.contact_checked and within.checks == verify(PROBLEM, slow).checks and not within.ok
