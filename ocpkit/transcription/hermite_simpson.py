"""Hermite–Simpson collocation (`hermite-simpson`), separated form, as in Kelly, *An Introduction to Trajectory
Optimization*, SIAM Review 59 (2017), §4: a method for mesh.py.

    x_{k+1} − x_k = (h/6)(f_k + 4 f_m + f_{k+1}),   x_m = (x_k + x_{k+1})/2 + (h/8)(f_k − f_{k+1})

Separated: every interval midpoint has its own variables [x, u]_m (why not the compressed form: see the doc).
Interpolant: the states a cubic Hermite (`hermite`), the controls (for a robot q̈ and u) the quadratic through
knot, midpoint, knot (`quadratic`); the default check of each interval is its midpoint.

Equations: docs/transcription.md, section "Mesh methods", "Hermite–Simpson collocation".
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from ocpkit.transcription.assembly import Assembly, Node
from ocpkit.transcription.mesh import Local, MeshDiscretization, MeshTranscription, Rate


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
    cost_rule = ((0.0, 0.5, 1.0), (1 / 6, 4 / 6, 1 / 6))  # Simpson: exact for the robot OCP's (dq̈/dσ)²

    @staticmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: Node, f: Rate, t0: ca.SX) -> None:
        f0, f1 = f(x0, t0), f(x1, t0 + h)
        a.defect(xm.x - ((x0.x + x1.x) / 2 + h / 8 * (f0 - f1)))  # x_m = (x_k + x_k+1)/2 + (h/8)(f_k − f_k+1)
        a.defect(x1.x - x0.x - h / 6 * (f0 + 4 * f(xm, t0 + h / 2) + f1))  # x_k+1 − x_k = (h/6)(f_k + 4f_m + f_k+1)

    @staticmethod
    def interpolate(x0: Node, x1: Node, xm: Node, f: Rate, h: Any, s: Any, t0: Any) -> Local:
        return Local(x=hermite(x0.x, x1.x, f(x0, t0), f(x1, t0 + h), h, s), u=quadratic(x0.u, xm.u, x1.u, s),
                     du_ds=quadratic_slope(x0.u, xm.u, x1.u, s))


class HermiteSimpson(MeshTranscription):
    """Hermite–Simpson collocation (Kelly 2017, separated form) on a uniform mesh, with interval midpoints.

    N = `knots` intervals, N + 1 knots and N midpoints."""

    name = "hermite-simpson"
    discretization = HermiteSimpsonDiscretization


