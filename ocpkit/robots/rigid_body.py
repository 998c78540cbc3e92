"""Numeric rigid-body torque over samples (pinocchio RNEA), friction excluded."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from ocpkit.robots.robot import Robot


def rigid_torque(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                 data: pin.Data | None = None) -> np.ndarray:
    """rnea(q, q̇, q̈) (N m) at every row of q, qd, qdd (m, n) (rad, rad/s, rad/s²): shape (m, n).

    One pinocchio Data serves all rows; pass `data` (robot.model.createData()) to reuse one across calls."""
    data = data or robot.model.createData()
    rows = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
    tau = np.empty(np.shape(q))
    for k, (qk, qdk, qddk) in enumerate(zip(*rows)):
        tau[k] = pin.rnea(robot.model, data, qk, qdk, qddk)
    return tau
