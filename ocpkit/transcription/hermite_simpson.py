"""Hermite–Simpson collocation (`hermite-simpson`), separated form, as in Kelly, *An Introduction to Trajectory
Optimization*, SIAM Review 59 (2017), §4: a method for mesh.py.

    x_{k+1} − x_k = (h/6)(f_k + 4 f_m + f_{k+1}),   x_m = (x_k + x_{k+1})/2 + (h/8)(f_k − f_{k+1})

Separated: every interval midpoint has its own variables [q, q̇, q̈, u]_m (why not the compressed form: see
the doc). Interpolant: the states a cubic Hermite (`hermite`), q̈ and u the quadratic through knot, midpoint,
knot (`quadratic`); the default check of each interval is its midpoint.

Equations: docs/transcription.md, section "Mesh methods", "Hermite–Simpson collocation".
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from ocpkit.transcription.assembly import Assembly, Node
from ocpkit.transcription.mesh import Local, MeshDiscretization, MeshTranscription


def hermite(x0: Any, x1: Any, f0: Any, f1: Any, h: Any, s: Any) -> Any:
    """The cubic through x0 (σ = 0) and x1 (σ = 1) with dx/dt = f0, f1 there (dx/dσ = h f)."""
    return ((2 * s - 3) * s * s + 1) * x0 + ((s - 2) * s + 1) * s * h * f0 \
        + (3 - 2 * s) * s * s * x1 + (s - 1) * s * s * h * f1


def quadratic(v0: Any, vm: Any, v1: Any, s: Any) -> Any:
    """The quadratic through v0, vm, v1 at σ = 0, ½, 1 (Lagrange form)."""
    return (2 * s - 1) * (s - 1) * v0 + 4 * s * (1 - s) * vm + s * (2 * s - 1) * v1


def quadratic_slope(v0: Any, vm: Any, v1: Any, s: Any) -> Any:
    """d/dσ of `quadratic`."""
    return (4 * s - 3) * v0 + (4 - 8 * s) * vm + (4 * s - 1) * v1


class HermiteSimpsonDiscretization(MeshDiscretization):
    """Separated Hermite–Simpson collocation on N intervals (module docstring); midpoint variables."""

    midpoints = True
    jerk_rule = ((0.0, 0.5, 1.0), (1 / 6, 4 / 6, 1 / 6))  # Simpson: exact for the robot OCP's quadratic (dq̈/dσ)²

    @staticmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: Node) -> None:
        a.defect(xm.q - ((x0.q + x1.q) / 2 + h / 8 * (x0.qd - x1.qd)))  # x_m = (x_k + x_k+1)/2 + (h/8)(f_k − f_k+1)
        a.defect(xm.qd - ((x0.qd + x1.qd) / 2 + h / 8 * (x0.qdd - x1.qdd)))
        a.defect(x1.q - x0.q - h / 6 * (x0.qd + 4 * xm.qd + x1.qd))  # x_k+1 − x_k = (h/6)(f_k + 4 f_m + f_k+1)
        a.defect(x1.qd - x0.qd - h / 6 * (x0.qdd + 4 * xm.qdd + x1.qdd))

    @staticmethod
    def interpolate(x0: Node, x1: Node, xm: Node, h: Any, s: Any) -> Local:
        return Local(q=hermite(x0.q, x1.q, x0.qd, x1.qd, h, s), qd=hermite(x0.qd, x1.qd, x0.qdd, x1.qdd, h, s),
                     qdd=quadratic(x0.qdd, xm.qdd, x1.qdd, s), u=quadratic(x0.u, xm.u, x1.u, s),
                     du_ds=quadratic_slope(x0.u, xm.u, x1.u, s), dqdd_ds=quadratic_slope(x0.qdd, xm.qdd, x1.qdd, s))


class HermiteSimpson(MeshTranscription):
    """Hermite–Simpson collocation (Kelly 2017, separated form) on a uniform mesh, with interval midpoints.

    N = `knots` intervals, N + 1 knots and N midpoints."""

    name = "hermite-simpson"
    discretization = HermiteSimpsonDiscretization


