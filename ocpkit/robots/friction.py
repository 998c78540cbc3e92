"""The joint friction law, written once for numpy arrays and CasADi SX/MX/DM alike.

τ_f(q̇) = viscous·q̇ + coulomb·tanh(q̇ / ε), ε the smoothing velocity. The caller passes coefficients and `tanh`
of its own array type (np.tanh with numpy arrays, ca.tanh with CasADi DM coefficients); every operation is
elementwise, so shapes broadcast as that type does.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

A = TypeVar("A")


def friction_torque(qd: A, viscous: A, coulomb: A, smoothing: float, tanh: Callable[[A], A]) -> A:
    """Friction torque (N m) at joint velocity qd (rad/s): viscous·qd + coulomb·tanh(qd / smoothing)."""
    return viscous * qd + coulomb * tanh(qd / smoothing)


def friction_slope(qd: A, viscous: A, coulomb: A, smoothing: float, tanh: Callable[[A], A]) -> A:
    """d friction / d qd (N m s / rad) at joint velocity qd (rad/s): viscous + coulomb/ε·(1 − tanh²(qd/ε))."""
    t = tanh(qd / smoothing)
    return viscous + coulomb / smoothing * (1 - t * t)
