"""Trapezoidal collocation (`trapezoidal`), as in Kelly, *An Introduction to Trajectory Optimization*, SIAM
Review 59 (2017), §3: a method for mesh.py.

    x_{k+1} − x_k = (h/2)(f_k + f_{k+1}),   f = f(x, u) (for a robot x = [q, q̇], f = [q̇, q̈]), h = t_f/N

Interpolant: the controls (for a robot q̈ and u) piecewise linear, the states piecewise quadratic
(`quadratic_state`), written through
*both* knots whatever the defect's residual (why: docs/transcription.md, section "Trapezoidal collocation").

Equations: docs/transcription.md, section "Mesh methods", "Trapezoidal collocation".
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from ocpkit.transcription.assembly import Assembly, Node
from ocpkit.transcription.mesh import Local, MeshDiscretization, MeshTranscription, Rate


def quadratic_state(x0: Any, x1: Any, f0: Any, f1: Any, h: Any, s: Any) -> Any:
    """x(σ) = x_k + σ (x_k+1 − x_k) − (h/2) σ(1 − σ)(f_k+1 − f_k): through both knots, dx/dt linear in σ."""
    return x0 + s * (x1 - x0) - h / 2 * s * (1 - s) * (f1 - f0)


class TrapezoidalDiscretization(MeshDiscretization):
    """Trapezoidal collocation on N intervals (module docstring); no midpoint variables."""

    midpoints = False
    cost_rule = ((0.0, 1.0), (0.5, 0.5))  # the trapezoidal rule: exact for the robot OCP's constant (dq̈/dσ)²

    @staticmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: None, f: Rate, t0: ca.SX) -> None:
        a.defect(x1.x - x0.x - h / 2 * (f(x0, t0) + f(x1, t0 + h)))  # x_k+1 − x_k = (h/2)(f_k + f_k+1)

    @staticmethod
    def interpolate(x0: Node, x1: Node, xm: None, f: Rate, h: Any, s: Any, t0: Any) -> Local:
        return Local(x=quadratic_state(x0.x, x1.x, f(x0, t0), f(x1, t0 + h), h, s), u=x0.u + s * (x1.u - x0.u),
                     du_ds=x1.u - x0.u)


class Trapezoidal(MeshTranscription):
    """Trapezoidal collocation (Kelly 2017) on a uniform mesh.

    N = `knots` intervals, N + 1 knots."""

    name = "trapezoidal"
    discretization = TrapezoidalDiscretization


