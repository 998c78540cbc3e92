"""Trajectories: knot values plus the transcription's own interpolant, dense sampling and JSON export."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from collections.abc import Callable

import numpy as np

FORMAT = "ocpkit.trajectory/1"


@dataclass(frozen=True)
class Samples:
    """Values at times t (m,): q, qd, qdd, tau, taud are (m, n) in rad, rad/s, rad/s², N m, N m/s."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    taud: np.ndarray


@dataclass(frozen=True)
class Trajectory:
    """A planned motion on [0, tf]: knot values (increasing time) and an interpolant for any time."""

    knots: Samples
    interpolant: Callable[[np.ndarray], Samples]

    @property
    def tf(self) -> float:
        """Motion time, seconds."""
        return float(self.knots.t[-1])

    def sample(self, dt: float = 1e-3) -> Samples:
        """The interpolant at t = 0, dt, 2 dt, ... and at tf (the last step may be shorter), seconds."""
        grid = dt * np.arange(int(np.ceil(self.tf / dt - 1e-9)))
        return self.interpolant(np.append(grid, self.tf))


def write_json(path: str | Path, trajectory: Trajectory, header: dict[str, Any], dt: float = 1e-3) -> None:
    """Write the exchange format (README, 'Trajectory files'): header fields, knots and dt-spaced samples.

    `header` holds robot, joint_names, method, status, solve_time_s and iterations."""
    knots, samples = trajectory.knots, trajectory.sample(dt)
    document = {
        "format": FORMAT, **header, "tf": trajectory.tf,
        "knots": {key: getattr(knots, key).tolist() for key in ("t", "q", "qd", "tau")},
        "samples": {key: getattr(samples, key).tolist() for key in ("t", "q", "qd", "qdd", "tau")},
    }
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(document))
