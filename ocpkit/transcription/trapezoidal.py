"""Trapezoidal collocation, as in Kelly, *An Introduction to Trajectory Optimization*, SIAM Review 59 (2017), §3.

State x = [q, q̇], its derivative f = [q̇, q̈]; q̈ at a knot is tied to the torque by the dynamic defect, so
f_k is a knot's own variables. On every interval [t_k, t_k + h] (h = t_f/N, σ = (t − t_k)/h):

    collocation   x_k+1 − x_k = (h/2)(f_k + f_k+1):   q_k+1 − q_k = (h/2)(q̇_k + q̇_k+1)
                                                       q̇_k+1 − q̇_k = (h/2)(q̈_k + q̈_k+1)
    dynamics      residual(q_k, q̇_k, q̈_k, τ_max u_k) = 0 at every knot
    controls      u(σ) = u_k + σ (u_k+1 − u_k)                          (piecewise linear)
    states        x(σ) = x_k + σ (x_k+1 − x_k) − (h/2) σ(1 − σ)(f_k+1 − f_k)   (piecewise quadratic)
    torque rate   dτ/dσ = τ_max (u_k+1 − u_k) + friction'(q̇) h q̈          (u's finite difference)
    jerk          q⃛ = (q̈_k+1 − q̈_k)/h on the interval                     (q̈'s finite difference)
    cost          t_f + μ Σ_k h q⃛_kᵀ Q q⃛_k = t_f + μ (1/h) Σ_k Δq̈_kᵀ Q Δq̈_k      (exact for constant q⃛)

The state formula is Kelly's x(τ) = x_k + f_k τ + (τ²/2h)(f_k+1 − f_k), rewritten with its own
collocation defect so that it passes through *both* knots whatever the defect's residual (IPOPT meets it
only to ~1e-8, while the boundary check wants the goal to 1e-6); the two agree wherever the defect vanishes.
What is then exact, per interval and at any point satisfying the collocation constraints:
  - q, q̇, q̈, u, τ pass through their knot values (q̈, u: linear interpolation of the knot values);
  - d q̇/dt = q̈ exactly: q̇ is the integral of the piecewise-linear q̈ (a quadratic);
  - d q/dt is the linear interpolation of the knot velocities, so it equals q̇ at the knots only and differs
    from the quadratic q̇ by at most (h/8)|q̈_k+1 − q̈_k| mid-interval: trapezoidal collocation makes each state
    the integral of its own derivative's linear interpolant, not a kinematic chain;
  - the dynamics hold at the knots; in between τ − rnea(q, q̇, q̈) − friction is O(h²).
The method is exact (all equality rows vanish) for motions of constant acceleration, q quadratic in t.
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from ocpkit.transcription.assembly import Assembly
from ocpkit.transcription.mesh import Local, MeshNLP, MeshTranscription, Node


def quadratic_state(x0: Any, x1: Any, f0: Any, f1: Any, h: Any, s: Any) -> Any:
    """x(σ) = x_k + σ (x_k+1 − x_k) − (h/2) σ(1 − σ)(f_k+1 − f_k): through both knots, dx/dt linear in σ."""
    return x0 + s * (x1 - x0) - h / 2 * s * (1 - s) * (f1 - f0)


class TrapezoidalNLP(MeshNLP):
    """Trapezoidal collocation on N intervals (module docstring); no midpoint variables."""

    midpoints = False

    @staticmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: None) -> None:
        a.defect(x1.q - x0.q - h / 2 * (x0.qd + x1.qd))  # x_k+1 − x_k = (h/2)(f_k + f_k+1)
        a.defect(x1.qd - x0.qd - h / 2 * (x0.qdd + x1.qdd))

    @staticmethod
    def interpolate(x0: Node, x1: Node, xm: None, h: Any, s: Any) -> Local:
        return Local(q=quadratic_state(x0.q, x1.q, x0.qd, x1.qd, h, s),
                     qd=quadratic_state(x0.qd, x1.qd, x0.qdd, x1.qdd, h, s),
                     qdd=x0.qdd + s * (x1.qdd - x0.qdd), u=x0.u + s * (x1.u - x0.u), du_ds=x1.u - x0.u)

    @staticmethod
    def jerk_integral(x0: Node, x1: Node, xm: None, weights: ca.DM) -> ca.SX:
        change = x1.qdd - x0.qdd  # dq̈/dσ, constant on the interval
        return ca.dot(weights * change, change)


class Trapezoidal(MeshTranscription):
    """Trapezoidal collocation (Kelly 2017) with N = `knots` intervals, N + 1 knots."""

    name = "trapezoidal"
    nlp = TrapezoidalNLP


