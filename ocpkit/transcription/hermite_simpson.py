"""Hermite–Simpson collocation, separated form, as in Kelly, *An Introduction to Trajectory Optimization*,
SIAM Review 59 (2017), §4.

Separated, not compressed: every interval midpoint carries its own variables x_m = [q, q̇, q̈, u]_m, tied to
the knots by the Hermite interpolation defect. That doubles the collocation points but keeps every row
small and local (the compressed form substitutes x_m, which nests the knots' dynamics inside the midpoint's
and makes the Hessian blocks denser).

State x = [q, q̇], f = [q̇, q̈]; on every interval [t_k, t_k + h] (h = t_f/N, σ = (t − t_k)/h):

    interpolation  x_m = (x_k + x_k+1)/2 + (h/8)(f_k − f_k+1)
    collocation    x_k+1 − x_k = (h/6)(f_k + 4 f_m + f_k+1)              (Simpson's rule)
    dynamics       residual(q, q̇, q̈, τ_max u) = 0 at every knot and midpoint
    controls       u(σ): the quadratic through u_k, u_m, u_k+1
    states         x(σ): the cubic Hermite through x_k, x_k+1 with slopes h f_k, h f_k+1
    acceleration   q̈(σ): the quadratic through q̈_k, q̈_m, q̈_k+1
    torque rate    dτ/dσ = τ_max du/dσ + friction'(q̇) h q̈,  du/dσ = u_k (4σ − 3) + u_m (4 − 8σ) + u_k+1 (4σ − 1)
    jerk           q⃛ = (dq̈/dσ)/h, linear in σ: (−3q̈_k + 4q̈_m − q̈_k+1)/h at σ = 0, (q̈_k+1 − q̈_k)/h at ½,
                   (q̈_k − 4q̈_m + 3q̈_k+1)/h at 1
    cost           t_f + μ Σ_k (h/6)(q⃛_0ᵀQq⃛_0 + 4 q⃛_½ᵀQq⃛_½ + q⃛_1ᵀQq⃛_1): Simpson, exact for the quadratic q⃛ᵀQq⃛

What is exact, at any point satisfying the constraints: the cubic x(σ) passes through x_k and x_k+1 by
construction and through x_m by the interpolation defect, and its derivative is the quadratic through f_k,
f_m, f_k+1 (Simpson's defect fixes the one slope the Hermite cubic leaves free), which is Kelly's
interpolant. Hence d q̇/dt = q̈ exactly (q̈'s quadratic *is* the derivative of q̇'s cubic), while d q/dt is the
quadratic through the three velocities and equals the cubic q̇ at σ = 0, ½, 1 only (an O(h³) gap). q̈ and u
pass through their knot and midpoint values; the dynamics hold at knots and midpoints, O(h³)-close between.
The method is exact (all equality rows vanish) for motions with q cubic in t.

Path constraints sit at the knots and at one check per interval whose default is the midpoint (there its
values equal the midpoint variables: path constraints at knots and midpoints); a refinement may move it
(mesh.py).
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from ocpkit.transcription.assembly import Assembly
from ocpkit.transcription.mesh import Local, MeshNLP, MeshTranscription, Node


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


class HermiteSimpsonNLP(MeshNLP):
    """Separated Hermite–Simpson collocation on N intervals (module docstring); midpoint variables."""

    midpoints = True

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
                     du_ds=quadratic_slope(x0.u, xm.u, x1.u, s))

    @staticmethod
    def jerk_integral(x0: Node, x1: Node, xm: Node, weights: ca.DM) -> ca.SX:
        slopes = [quadratic_slope(x0.qdd, xm.qdd, x1.qdd, s) for s in (0.0, 0.5, 1.0)]  # dq̈/dσ
        return sum(c / 6 * ca.dot(weights * j, j) for c, j in zip((1, 4, 1), slopes))  # Simpson on [0, 1]


class HermiteSimpson(MeshTranscription):
    """Hermite–Simpson collocation (Kelly 2017, separated form) with N = `knots` intervals, N + 1 knots and
    N midpoints."""

    name = "hermite-simpson"
    nlp = HermiteSimpsonNLP


