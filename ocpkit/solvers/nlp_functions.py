"""CasADi functions of an NLP's (w, p) for the solvers that drive their own iterations in Python
(`scipy_minimize`, `scp`): objective, constraints and their derivatives, built once per NLP (in `prepare`)."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca

from ocpkit.nlp import NLP


@dataclass(frozen=True)
class NLPFunctions:
    """CasADi functions of (w, p) for one NLP: f, ∇f (n_w,), g (n_g,), ∂g/∂w (n_g × n_w, sparse) and,
    when asked for, ∇²f and ∇²(vᵀg) (n_w × n_w) for constraint multipliers v (n_g,)."""

    f: ca.Function
    grad_f: ca.Function
    g: ca.Function
    jac_g: ca.Function
    hess_f: ca.Function | None
    hess_vg: ca.Function | None

    @classmethod
    def build(cls, nlp: NLP, objective_hessian: bool, constraint_hessian: bool) -> NLPFunctions:
        """The functions of `nlp`, with ∇²f and ∇²(vᵀg) only where asked for (their graphs cost set-up time)."""
        x, p, f, g = nlp.x, nlp.p, nlp.f, nlp.g
        v = ca.SX.sym("v", g.numel())
        return cls(ca.Function("f", [x, p], [f]), ca.Function("grad_f", [x, p], [ca.gradient(f, x)]),
                   ca.Function("g", [x, p], [g]), ca.Function("jac_g", [x, p], [ca.jacobian(g, x)]),
                   ca.Function("hess_f", [x, p], [ca.hessian(f, x)[0]]) if objective_hessian else None,
                   ca.Function("hess_vg", [x, p, v], [ca.hessian(ca.dot(v, g), x)[0]]) if constraint_hessian else None)
