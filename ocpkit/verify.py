"""Dense numeric re-check of a trajectory against its problem, with pinocchio (independent of CasADi).

Every check reports its worst value over a dense time grid (1 ms by default) and passes when that is
within the stated tolerance:

  position    worst excess over a joint's position limit, rad (m for a prismatic joint);  tolerance 1e-4
              (a hard stop: ocpkit.tolerances)
  velocity, torque, torque_rate             worst excess over the limit, relative to it;  tolerance 1 %
  dynamics    |tau(t) − (rnea(q, qd, qdd) + friction)| relative to the torque range 2·tau_max;  tolerance 1 %
  self_collision, obstacle, workspace       worst sphere penetration, metres (negative: the smallest
                                             clearance);  tolerance 0 (no contact allowed)
  boundary    |q − q_start/goal|, |qd|, |qdd| at t = 0 and t_f (rad, rad/s, rad/s²);  tolerance 1e-6
  qd_consistency, qdd_consistency            whether the samples are self-consistent, as an outside checker
             sees them: by the mean value theorem the difference quotient of q (of qd) over one sample step
             lies between qd (qdd) at the step's ends; the worst distance outside, relative to the joint's
             velocity limit (qd) or to the motion's peak acceleration (qdd, over all joints);  tolerances 1 %
             and 5 % (exact up to O(dt²) for smooth motions, and a jump of qdd, as TOPP-RA's bang-bang timing
             has, stays inside the range; a non-converged iterate misses by tens of percent)

A trajectory whose t_f is not finite or lies outside the problem's time bounds by more than 1 % (a solver's
diverged iterate can have an absurd t_f) fails the single check `motion_time` (relative excess) instead and is
not sampled.

The torque limit is checked on the inverse-dynamics torque, i.e. the torque the motion really needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ocpkit.formats.trajectory import TIME_TOLERANCE, Samples, Trajectory, time_excess
from ocpkit.geometry.nearest import smallest_clearances
from ocpkit.problem import Problem
from ocpkit.robots import rigid_torque
from ocpkit.tolerances import (BOUNDARY_TOLERANCE, DYNAMICS_TOLERANCE, GEOMETRY_TOLERANCE, LIMIT_TOLERANCE,
                               POSITION_TOLERANCE, QD_CONSISTENCY_TOLERANCE, QDD_CONSISTENCY_TOLERANCE)

GEOMETRY_CHECKS = ("self_collision", "obstacle", "workspace")
SCALED_LIMITS = ("velocity", "torque", "torque_rate")


@dataclass(frozen=True)
class Check:
    """One verified quantity: its worst value, the tolerance it must not exceed, when it occurred (s) and, for a
    per-joint check, at which joint (`where`; "" otherwise)."""

    name: str
    worst: float
    tolerance: float
    time: float
    unit: str
    where: str = ""

    @property
    def ok(self) -> bool:
        return bool(self.worst <= self.tolerance)


@dataclass(frozen=True)
class Verification:
    """The result of `verify`: every check, and the sample times where fixable path violations occur; or, for a
    motion that was not verified (`not_run`), no checks and why not (`skipped`); or, for a motion that failed a
    limit where `verify` was asked to check the limits first, every check but contact (`contact_checked` False)."""

    checks: tuple[Check, ...]
    violation_times: np.ndarray  # (k,) seconds, worst first, of path-constraint violations
    skipped: str = ""  # why the motion was not verified; "" when it was
    contact_checked: bool = True  # False only where `verify` checked the limits first and found one exceeded

    @classmethod
    def not_run(cls, why: str) -> Verification:
        """The verification of a motion that was not verified, and `why`: never ok, nothing to refine."""
        return cls((), np.zeros(0), why)

    @property
    def ok(self) -> bool:
        return not self.skipped and self.contact_checked and all(c.ok for c in self.checks)

    @property
    def worst_failure(self) -> float:
        """The largest failed check's worst value (its unit: relative for limits, m for contact), 0 if none failed,
        inf for a motion that was not verified."""
        if self.skipped:
            return np.inf
        return max((c.worst for c in self.checks if not c.ok), default=0.0)

    @property
    def fixable(self) -> bool:
        """Whether a refinement round has something to fix: a path-constraint violation between check times
        (ocpkit.planner.refinement); a failed dynamics, boundary or consistency check alone is not."""
        return len(self.violation_times) > 0

    @property
    def limit_excess(self) -> float:
        """Largest relative excess over a velocity, torque or torque-rate limit beyond its tolerance, or 0."""
        return max([0.0] + [c.worst - c.tolerance for c in self.checks if c.name in SCALED_LIMITS])

    @property
    def penetration(self) -> float:
        """Deepest sphere contact of any kind (m), 0 if there is none."""
        return max([0.0] + [c.worst for c in self.checks if c.name in GEOMETRY_CHECKS])

    def summary(self) -> str:
        """One line: the failed checks with their times, or every check's worst value if all pass (or why the
        motion was not verified)."""
        if self.skipped:
            return f"not verified: {self.skipped}"
        failed = [c for c in self.checks if not c.ok]
        if failed:
            return "FAILED " + ", ".join(f"{c.name} {c.worst:+.3g} {c.unit} > {c.tolerance:g} at t={c.time:.3f} s"
                                         + (f" ({c.where})" if c.where else "") for c in failed) \
                + ("" if self.contact_checked else "; contact not checked")
        return "all pass: " + ", ".join(f"{c.name} {c.worst:+.3g} {c.unit}" for c in self.checks)


def verify(problem: Problem, trajectory: Trajectory, dt: float = 1e-3, limits_first: bool = False) -> Verification:
    """Re-check `trajectory` against every constraint of `problem` on a dense grid of step dt (s). With
    `limits_first`, a motion beyond a position, velocity, torque or torque-rate limit somewhere (a fault a
    refinement round fixes) is not checked for contact, the costly part for a robot with many spheres: its
    verification has every other check and `contact_checked` False."""
    outside = _motion_time_outside_bounds(problem, trajectory.tf)
    if outside is not None:
        return Verification((outside,), np.zeros(0))
    samples = trajectory.sample(dt)
    robot = problem.robot
    tau_needed = _inverse_dynamics(problem, samples)
    excess = {  # name: (values (m, n), tolerance, unit)
        "position": (np.maximum(samples.q - robot.q_upper, robot.q_lower - samples.q), POSITION_TOLERANCE, "rad"),
        "velocity": (np.abs(samples.qd) / robot.qd_max - 1.0, LIMIT_TOLERANCE, "rel"),
        "torque": (np.abs(tau_needed) / robot.tau_max - 1.0, LIMIT_TOLERANCE, "rel"),
        "torque_rate": (np.abs(samples.taud) / robot.taud_max - 1.0, LIMIT_TOLERANCE, "rel"),
    }
    consistency = np.abs(samples.tau - tau_needed) / (2.0 * robot.tau_max)
    limits = [_worst(name, v, tolerance, samples.t, unit, robot.joint_names)
              for name, (v, tolerance, unit) in excess.items()]
    dynamics = _worst("dynamics", consistency, DYNAMICS_TOLERANCE, samples.t, "rel")
    rest = [_boundary(problem, samples), *_consistency(problem, samples)]
    path_violation = np.max([_per_time(v) - tolerance for v, tolerance, _ in excess.values()], axis=0)
    if limits_first and path_violation.max() > 0:
        return Verification((*limits, dynamics, *rest), _peak_times(samples.t, path_violation),
                            contact_checked=False)
    nearest = smallest_clearances(robot, problem.scene, samples.q)
    penetration = dict(zip(GEOMETRY_CHECKS, (-nearest.self_pairs, -nearest.obstacles, -nearest.workspace)))
    contact = [_worst(name, v, GEOMETRY_TOLERANCE, samples.t, "m") for name, v in penetration.items()]
    path_violation = np.max([path_violation, *(_per_time(v) for v in penetration.values())], axis=0)
    return Verification((*limits, dynamics, *contact, *rest), _peak_times(samples.t, path_violation))


def _motion_time_outside_bounds(problem: Problem, tf: float) -> Check | None:
    """The failed `motion_time` check if t_f (s) is not finite or outside the time bounds beyond tolerance."""
    excess = time_excess(tf, problem.time.min, problem.time.max)
    if excess <= TIME_TOLERANCE:
        return None
    return Check("motion_time", float(excess), TIME_TOLERANCE, float(tf) if np.isfinite(tf) else 0.0, "rel")


def _inverse_dynamics(problem: Problem, samples: Samples) -> np.ndarray:
    """Joint torque (m, n), N m, the sampled motion needs: rnea(q, q̇, q̈) + friction(q̇)."""
    robot = problem.robot
    return rigid_torque(robot, samples.q, samples.qd, samples.qdd) + robot.friction(samples.qd)


def _per_time(values: np.ndarray) -> np.ndarray:
    """Worst value at each sample time, shape (m,); -inf where there is nothing to check."""
    flat = values.reshape(len(values), -1)
    return flat.max(axis=1) if flat.shape[1] else np.full(len(values), -np.inf)


def _worst(name: str, values: np.ndarray, tolerance: float, t: np.ndarray, unit: str,
           joints: tuple[str, ...] = ()) -> Check:
    """The check of `values` (m, ...) at times t (m,): its worst value and when; with `joints` (values (m, n),
    one column per joint), the joint where it occurred."""
    per_time = _per_time(values)
    k = int(np.argmax(per_time))
    where = joints[int(np.argmax(values[k]))] if joints and values.shape[1:] == (len(joints),) else ""
    return Check(name, float(per_time[k]), tolerance, float(t[k]), unit, where)


def _consistency(problem: Problem, samples: Samples) -> list[Check]:
    """The qd_consistency and qdd_consistency checks (module docstring) of the samples."""
    quotient = np.diff(samples.qd, axis=0) / np.diff(samples.t)[:, None]
    peak = max(np.abs(samples.qdd).max(), np.abs(quotient).max(), np.finfo(float).tiny)
    t = samples.t[:-1]
    return [_worst("qd_consistency", _mean_value_excess(samples.t, samples.q, samples.qd) / problem.robot.qd_max,
                   QD_CONSISTENCY_TOLERANCE, t, "rel"),
            _worst("qdd_consistency", _mean_value_excess(samples.t, samples.qd, samples.qdd) / peak,
                   QDD_CONSISTENCY_TOLERANCE, t, "rel")]


def _mean_value_excess(t: np.ndarray, x: np.ndarray, derivative: np.ndarray) -> np.ndarray:
    """How far the difference quotient of x (m, n) over each step of t (m,) lies outside the range of
    `derivative` (m, n) at the step's ends: shape (m − 1, n), in the units of `derivative`; ≤ 0 inside."""
    quotient = np.diff(x, axis=0) / np.diff(t)[:, None]
    ends = np.stack([derivative[:-1], derivative[1:]])
    return np.maximum(ends.min(axis=0) - quotient, quotient - ends.max(axis=0))


def _boundary(problem: Problem, samples: Samples) -> Check:
    errors = np.array([
        np.abs(samples.q[0] - problem.start).max(), np.abs(samples.q[-1] - problem.goal).max(),
        np.abs(samples.qd[[0, -1]]).max(), np.abs(samples.qdd[[0, -1]]).max()])
    k = int(np.argmax(errors))
    return Check("boundary", float(errors[k]), BOUNDARY_TOLERANCE, float(samples.t[-1] if k % 2 else 0.0), "abs")


def _peak_times(t: np.ndarray, violation: np.ndarray) -> np.ndarray:
    """Times of the local maxima of a violation signal where it is positive, worst first."""
    padded = np.concatenate([[-np.inf], violation, [-np.inf]])
    peaks = np.nonzero((violation > 0) & (violation >= padded[:-2]) & (violation >= padded[2:]))[0]
    return t[peaks[np.argsort(-violation[peaks])]]
