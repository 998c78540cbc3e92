"""Trajectories: knot values plus the transcription's own interpolant, dense sampling and JSON export."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

FORMAT = "ocpkit.trajectory/1"
TIME_TOLERANCE = 0.01  # relative excess of t_f over its time bounds that still counts as inside
MAX_SAMPLES = 100_000  # dense samples a trajectory file holds at most (100 s at 1 ms)


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


def time_excess(tf: float, lower: float, upper: float) -> float:
    """Relative excess of the motion time tf (s) over the bounds [lower, upper] (s): ≤ 0 inside, inf if not finite."""
    return max(tf / upper - 1.0, 1.0 - tf / lower) if np.isfinite(tf) else np.inf


def write_json(path: str | Path, trajectory: Trajectory, header: dict[str, Any], dt: float = 1e-3, *,
               time_bounds: tuple[float, float] | None = None, max_samples: int = MAX_SAMPLES) -> None:
    """Write the exchange format (docs/formats.md, 'Trajectory files'): header fields, knots and dt-spaced samples.

    `header` holds robot, joint_names, method, status, solve_time_s and iterations. The samples are left out
    (`"samples": null`, and `"samples_omitted"` says why) when t_f is not finite, lies outside `time_bounds`
    (min, max; s) by more than TIME_TOLERANCE, or would take more than `max_samples` samples: a diverged
    iterate's t_f must not fill the disk."""
    knots, omitted = trajectory.knots, _why_not_sampled(trajectory.tf, dt, time_bounds, max_samples)
    samples = None if omitted else trajectory.sample(dt)
    document = {
        "format": FORMAT, **header, "tf": trajectory.tf,
        "knots": {key: getattr(knots, key).tolist() for key in ("t", "q", "qd", "tau")},
        "samples": samples and {key: getattr(samples, key).tolist() for key in ("t", "q", "qd", "qdd", "tau")},
    }
    if omitted:
        document["samples_omitted"] = omitted
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(document))


def _why_not_sampled(tf: float, dt: float, time_bounds: tuple[float, float] | None, max_samples: int) -> str:
    """Why a trajectory of motion time tf (s) is not sampled at step dt (s), or "" if it is (see write_json)."""
    if time_bounds is not None and time_excess(tf, *time_bounds) > TIME_TOLERANCE:
        return f"t_f = {tf:.6g} s is outside the time bounds [{time_bounds[0]:g}, {time_bounds[1]:g}] s"
    if not np.isfinite(tf) or tf / dt + 1 > max_samples:
        return f"t_f = {tf:.6g} s would take more than {max_samples} samples at {dt:g} s"
    return ""
