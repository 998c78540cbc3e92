"""The motion-planning problem: robot, scene, boundary conditions, time bounds and cost. Nothing symbolic."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ocpkit.geometry.clearances import Clearances, clearances, sphere_centers_batch
from ocpkit.geometry.scene import Scene
from ocpkit.robots import Robot


@dataclass(frozen=True)
class TimeBounds:
    """Bounds on the final time t_f and its initial guess, seconds."""

    min: float = 0.1
    max: float = 10.0
    guess: float = 10.0


@dataclass(frozen=True)
class Problem:
    """Move `robot` from rest at `start` to rest at `goal` (rad, shape (n,)) minimizing
    J = t_f + mu ∫ jerkᵀ Q jerk dt with Q = diag(1 / gear_ratio²)."""

    robot: Robot
    start: np.ndarray
    goal: np.ndarray
    scene: Scene
    time: TimeBounds = TimeBounds()
    mu: float = 0.3
    name: str = "problem"

    @property
    def jerk_weights(self) -> np.ndarray:
        """Diagonal of Q, shape (n,): 1 / R_ii²."""
        return 1.0 / self.robot.gear_ratios**2

    @functools.cached_property
    def end_clearances(self) -> Clearances:
        """The robot's clearances (m) at the start and the goal: each kind with a leading axis of 2 (computed once)."""
        return clearances(self.robot, self.scene, sphere_centers_batch(self.robot, np.stack([self.start, self.goal])))

    def velocity_lower_bound(self) -> float:
        """max_i |goal_i - start_i| / qd_max_i, seconds: no plan can be faster than this."""
        return float(np.max(np.abs(self.goal - self.start) / self.robot.qd_max))
