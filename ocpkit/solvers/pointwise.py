"""The constraint Jacobian and the Lagrangian's Hessian of an NLP built point by point, for IPOPT's `jac_g` and
`hess_lag` options, from the NLP's point calls (`NLP.point_calls`, `NLP.objective_call`: rows, or the objective,
that are one point function's value).

CasADi differentiates a whole graph at once, sweeping all of it once per colour of the Jacobian's columns; a
Chebyshev row reads every knot of a joint, so there are several colours per knot, and those sweeps were most of
the set-up. Here each distinct point function F(z) is differentiated once, on its own few inputs z,
and the chain rule joins the calls (Z stacks every call's z; λ_k weighs call k: its rows' multipliers, or λ_f):

    ∂g/∂x = blockdiag(∂F/∂z(z_k)) A,    A = ∂Z/∂x
    ∇²ₓ(λ_f f + λᵀg) = Aᵀ blockdiag(∇²_z(λ_kᵀF)(z_k)) A + Σᵢ vᵢ ∇²ₓZᵢ,    v = blockdiag(∂F/∂z(z_k))ᵀ λ

The last term appears only where Z is not linear in x (a torque with friction, a path-timing OCP's state). Inputs
shared by several calls (the values at one point) are differentiated once. The other rows (collocation and
interpolation defects, nearly linear) are differentiated by CasADi a few rows at a time, and the objective too
when it is not a point call. The result equals CasADi's own derivatives (tests/solvers/test_pointwise.py).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.nlp import NLP, PointCall

ROWS_AT_ONCE = 6
"""The other rows are differentiated this many consecutive rows at a time: rows added together read the same few
knots, so each chunk needs few sweeps over a small graph, where all rows at once need as many sweeps over all of
them (figures: docs/design-notes.md)."""


def pointwise_derivatives(nlp: NLP) -> dict[str, ca.Function]:
    """IPOPT's {"jac_g": (x, p) → (g, ∂g/∂x), "hess_lag": (x, p, λ_f, λ_g) → upper triangle of
    ∇²ₓ(λ_f f + λ_gᵀ g)} for `nlp` (SX, with point calls), built as the module docstring says."""
    x, p, f, g = nlp.x, nlp.p, nlp.f, nlp.g
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g.numel())
    rows = [np.arange(c.first_row, c.first_row + c.function.numel_out(0)) for c in nlp.point_calls]
    calls = [*zip(nlp.point_calls, (lam_g[r.tolist()] for r in rows))]
    if nlp.objective_call is not None:
        calls.append((nlp.objective_call, lam_f))
    A, jacobians, hessians = _chain(calls, x)
    called = np.concatenate(rows) if rows else np.zeros(0, dtype=int)
    others = np.setdiff1d(np.arange(g.numel()), called).tolist()
    rest = g[others]
    objective = 0 if nlp.objective_call is not None else lam_f * f
    hess = ca.mtimes([A.T, ca.diagcat(*hessians), A]) + ca.hessian(objective + ca.dot(lam_g[others], rest), x)[0]
    if ca.depends_on(A, x):
        hess += _second_order(calls, jacobians, x)
    constraint_jacobians = jacobians[:len(rows)]  # the objective's, if any, comes last
    point_rows = ca.mtimes(ca.diagcat(*constraint_jacobians), A[:sum(j.size2() for j in constraint_jacobians), :])
    starts = range(0, len(others), ROWS_AT_ONCE)
    other_rows = [ca.jacobian(rest[i:min(i + ROWS_AT_ONCE, len(others))], x) for i in starts]
    jac = ca.vertcat(point_rows, *other_rows)[np.argsort(np.concatenate([called, others])).tolist(), :]
    return {"jac_g": ca.Function("nlp_jac_g", [x, p], [g, jac], ["x", "p"], ["g", "jac_g_x"]),
            "hess_lag": ca.Function("nlp_hess_l", [x, p, lam_f, lam_g], [ca.triu(hess)],
                                    ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])}


def _chain(calls: list[tuple[PointCall, ca.SX]], x: ca.SX) -> tuple[ca.SX, list[ca.SX], list[ca.SX]]:
    """(A = ∂Z/∂x with Z every call's z stacked, [∂F/∂z(z_k)], [∇²_z(λ_kᵀF)(z_k)]) for (call, λ_k) pairs; an input
    object shared by several calls is differentiated once."""
    derivatives: dict[int, tuple[ca.Function, ca.Function]] = {}
    offsets: dict[int, int] = {}  # id of an input → its first row in Z
    unique, positions, jacobians, hessians, size = [], [], [], [], 0
    for call, weights in calls:
        if id(call.function) not in derivatives:
            derivatives[id(call.function)] = _point_derivatives(call.function, len(call.inputs))
        jacobian, hessian = derivatives[id(call.function)]
        jacobians.append(jacobian(*call.inputs, *call.parameters))
        hessians.append(hessian(*call.inputs, *call.parameters, weights))
        for value in call.inputs:
            if id(value) not in offsets:
                offsets[id(value)], size = size, size + value.numel()
                unique.append(value)
            positions.append(offsets[id(value)] + np.arange(value.numel()))
    Z = ca.vertcat(*(ca.vec(v) for v in unique))
    return ca.jacobian(Z, x)[np.concatenate(positions).tolist(), :], jacobians, hessians


def _second_order(calls: list[tuple[PointCall, ca.SX]], jacobians: list[ca.SX], x: ca.SX) -> ca.SX:
    """Σᵢ vᵢ ∇²ₓZᵢ with v = blockdiag(∂F/∂z)ᵀ λ: the chain rule's term for inputs not linear in x."""
    Z = ca.vertcat(*(ca.vec(value) for call, _ in calls for value in call.inputs))
    v = ca.densify(ca.mtimes(ca.diagcat(*jacobians).T, ca.vertcat(*(weights for _, weights in calls))))
    symbols = ca.SX.sym("v", Z.numel())
    return ca.substitute(ca.hessian(ca.dot(symbols, Z), x)[0], symbols, v)


def _point_derivatives(function: ca.Function, differentiated: int) -> tuple[ca.Function, ca.Function]:
    """(∂F/∂z, ∇²_z(λᵀF)) of a point function F whose first `differentiated` inputs make z, as Functions of F's
    inputs (and λ, one per output row)."""
    symbols = [ca.SX.sym(function.name_in(i), function.size_in(i)) for i in range(function.n_in())]
    rows = function(*symbols)
    z = ca.vertcat(*(ca.vec(s) for s in symbols[:differentiated]))
    lam = ca.SX.sym("lam", rows.numel())
    return (ca.Function("point_jacobian", symbols, [ca.jacobian(rows, z)]),
            ca.Function("point_hessian", [*symbols, lam], [ca.hessian(ca.dot(lam, rows), z)[0]]))
