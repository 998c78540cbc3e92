"""Dynamics backends `pinocchio` and `pinocchio-rnea`: the dynamic defect evaluated by numeric pinocchio
through a CasADi callback, with pinocchio's analytic first derivatives.

Forms, as for the symbolic backends:
- `pinocchio` (forward, the paper's): residual = q̈ − ABA(q, q̇, τ_rigid) in rad/s², with ABA from `pinocchio.aba`
  and its derivatives from `pinocchio.computeABADerivatives` (∂q̈/∂q, ∂q̈/∂q̇ and ∂q̈/∂τ = M(q)⁻¹).
- `pinocchio-rnea` (inverse): residual = (RNEA(q, q̇, q̈) − τ_rigid) / τ_max, with `pinocchio.rnea` and
  `pinocchio.computeRNEADerivatives` (∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M(q)).
Friction, `forward`, `inverse` and the sphere kinematics stay symbolic (inherited from `casadi` /
`casadi-rnea`): only the rigid-body dynamics of the defect goes through pinocchio.

SX and MX. A `casadi.Callback` can be called on MX only; the transcriptions build their NLPs in SX (cheap to
evaluate, one graph). So `residual` on SX arguments returns the defect with a fresh SX *placeholder* symbol in
place of the pinocchio value and records the call; `lift(fields)` then turns the finished SX NLP into an MX
one of three nodes: x, p ↦ the stacked arguments (one SX function), one callback call that evaluates all
recorded points at once (one Python call per evaluation, not one per point), and x, p, values ↦ f, g (the
original SX function). `lift` then forgets the recorded calls, so one instance serves several builds, one
after the other (record, lift, record, lift). On MX arguments `residual` calls the callback directly; on numbers
it calls pinocchio. These backends take no options.

Hessian strategy: the callback provides values and first derivatives only, so the NLP has no exact Lagrangian
Hessian. `exact_hessian = False` tells the solver to use a quasi-Newton approximation instead (IPOPT and
sqpmethod: `hessian_approximation = limited-memory`, L-BFGS; blocksqp: its BFGS blocks; trust-constr: BFGS).
Solvers that need an exact Hessian (fatrop) or a symbolic graph (pyomo) report that as a status or error.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np
import pinocchio as pin

from ocpkit.dynamics.casadi_aba import CasadiAba, CasadiRnea
from ocpkit.robots import Robot

_ALIVE: list[ca.Callback] = []  # CasADi holds Python callbacks by raw pointer: keep every one referenced


def _symmetric(upper: np.ndarray) -> np.ndarray:
    """The symmetric matrix whose upper triangle is `upper`'s (pinocchio may fill M or M⁻¹ only there)."""
    return np.triu(upper) + np.triu(upper, 1).T


@dataclass(frozen=True)
class Algorithm:
    """A pinocchio algorithm y = F(q, v, a) for one point, a (n,) the third argument (q̈ or τ), and its
    Jacobian [∂y/∂q, ∂y/∂v, ∂y/∂a] (n, 3n)."""

    name: str
    value: Callable[[pin.Model, pin.Data, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
    derivatives: Callable[[pin.Model, pin.Data, np.ndarray, np.ndarray, np.ndarray], tuple]


RNEA = Algorithm("rnea", pin.rnea, pin.computeRNEADerivatives)
ABA = Algorithm("aba", pin.aba, pin.computeABADerivatives)


class PinocchioCallback(ca.Callback):
    """`algorithm` at K points: input (3n, K) with columns [q; v; a], output (n, K) with columns y.

    The Jacobian (nK, 3nK) is block diagonal, one dense (n, 3n) block per point from the algorithm's
    analytic derivatives; the callback declares that sparsity so CasADi colours it."""

    def __init__(self, model: pin.Model, algorithm: Algorithm, points: int, opts: dict | None = None) -> None:
        ca.Callback.__init__(self)
        self.model, self.data, self.n, self.points = model, model.createData(), model.nv, points
        self.algorithm = algorithm
        self.construct(f"pinocchio_{algorithm.name}_{points}", opts or {})
        _ALIVE.append(self)

    def get_n_in(self) -> int:
        return 1

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(3 * self.n, self.points)

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(self.n, self.points)

    def eval(self, arg):
        return [ca.DM(self.values(np.asarray(arg[0], dtype=float)))]

    def _points(self, x: np.ndarray):
        """(q, v, a) of every column of x (3n, K)."""
        n = self.n
        return ((x[:n, k], x[n:2 * n, k], x[2 * n:, k]) for k in range(self.points))

    def values(self, x: np.ndarray) -> np.ndarray:
        """y (n, K) for columns x (3n, K)."""
        return np.stack([self.algorithm.value(self.model, self.data, *point) for point in self._points(x)], axis=1)

    def jacobian_blocks(self, x: np.ndarray) -> list[np.ndarray]:
        """[∂y/∂q, ∂y/∂v, ∂y/∂a] (n, 3n) at every column of x."""
        blocks = []
        for point in self._points(x):
            dq, dv, da = self.algorithm.derivatives(self.model, self.data, *point)
            blocks.append(np.hstack([dq, dv, _symmetric(da)]))
        return blocks

    @property
    def jacobian_sparsity(self) -> ca.Sparsity:
        return ca.kron(ca.DM.eye(self.points), ca.DM.ones(self.n, 3 * self.n)).sparsity()

    def has_jacobian_sparsity(self) -> bool:
        return True

    def get_jacobian_sparsity(self) -> ca.Sparsity:
        return self.jacobian_sparsity

    def has_jacobian(self) -> bool:
        return True

    def get_jacobian(self, name: str, inames, onames, opts):
        return CallbackJacobian(name, self, opts)


class CallbackJacobian(ca.Callback):
    """dy/dx of a PinocchioCallback: inputs (x, nominal y), output the block-diagonal Jacobian. It has no
    derivatives of its own (hence no exact Hessian)."""

    def __init__(self, name: str, callback: PinocchioCallback, opts: dict) -> None:
        ca.Callback.__init__(self)
        self.callback = callback
        self.construct(name, opts)
        _ALIVE.append(self)

    def get_n_in(self) -> int:
        return 2

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return self.callback.get_sparsity_in(0) if i == 0 else self.callback.get_sparsity_out(0)

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return self.callback.jacobian_sparsity

    def eval(self, arg):
        blocks = self.callback.jacobian_blocks(np.asarray(arg[0], dtype=float))
        # nonzeros column-major: the block of point k owns columns 3nk..3n(k+1) and rows nk..n(k+1)
        return [ca.DM(self.callback.jacobian_sparsity, np.concatenate([b.ravel(order="F") for b in blocks]))]


class _CallbackDefect:
    """Mixin for a symbolic backend: the rigid-body term of its defect comes from `algorithm` through a
    PinocchioCallback (module docstring). Subclasses say how the defect is formed from that term."""

    algorithm: Algorithm
    exact_hessian = False
    robot: Robot

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        self._placeholders: list[ca.SX] = []  # one (n, 1) SX symbol per SX residual call since the last lift
        self._arguments: list[ca.SX] = []  # its [q; v; a] (3n, 1)

    @property
    def options(self) -> dict:
        """Empty: the callback backends take no options."""
        return {}

    def rigid_term(self, q, qd, a):
        """The algorithm at (q, qd, a): a placeholder on SX (recorded for `lift`), a callback on MX, numbers
        on numbers."""
        if any(isinstance(v, ca.MX) for v in (q, qd, a)):
            return self.callback(1)(ca.vertcat(q, qd, a))
        if any(isinstance(v, ca.SX) for v in (q, qd, a)):
            value = ca.SX.sym(f"{self.algorithm.name}_{len(self._placeholders)}", self.robot.n)
            self._placeholders.append(value)
            self._arguments.append(ca.vertcat(q, qd, a))
            return value
        model = self.robot.model
        numbers = (np.asarray(ca.DM(v), dtype=float).ravel() for v in (q, qd, a))
        return ca.DM(self.algorithm.value(model, model.createData(), *numbers))

    def callback(self, points: int) -> PinocchioCallback:
        """A new callback of this backend's algorithm over `points` points."""
        return PinocchioCallback(self.robot.model, self.algorithm, points)

    def lift(self, fields: dict) -> dict:
        """The SX NLP `fields` (x, p, f, g, ...) as an MX NLP in which the placeholders recorded since the last
        lift are the callback's values at their arguments; marks it `exact_hessian = False` and forgets those
        placeholders. Without recorded calls the fields come back unchanged but for that mark."""
        fields = dict(fields, exact_hessian=False)
        placeholders, arguments = self._take_recorded()
        if not placeholders:
            return fields
        x, p = fields["x"], fields["p"]
        stacked = ca.horzcat(*placeholders)  # (n, K)
        arguments_of = ca.Function("pinocchio_arguments", [x, p], [ca.horzcat(*arguments)])
        body = ca.Function("nlp_body", [x, p, stacked], [fields["f"], fields["g"]])
        X, P = ca.MX.sym("x", x.sparsity()), ca.MX.sym("p", p.sparsity())
        values = self.callback(len(placeholders))(arguments_of(X, P))
        f, g = body(X, P, values)
        return dict(fields, x=X, p=P, f=f, g=g)

    def _take_recorded(self) -> tuple[list[ca.SX], list[ca.SX]]:
        """The recorded placeholders and their arguments, the records emptied."""
        taken = self._placeholders, self._arguments
        self._placeholders, self._arguments = [], []
        return taken


class PinocchioAba(_CallbackDefect, CasadiAba):
    """Forward form by numeric pinocchio: the defect is q̈ − ABA(q, q̇, τ_rigid) in rad/s².

    ABA and its analytic derivatives (computeABADerivatives) through a CasADi callback: first derivatives only
    (module docstring)."""

    name = "pinocchio"
    algorithm = ABA

    def residual(self, q, qd, qdd, tau_rigid):
        """qdd − ABA(q, qd, tau_rigid), rad/s²."""
        return qdd - self.rigid_term(q, qd, tau_rigid)


class PinocchioRnea(_CallbackDefect, CasadiRnea):
    """Inverse form by numeric pinocchio: the defect is (RNEA(q, q̇, q̈) − τ_rigid) / τ_max, dimensionless.

    RNEA and its analytic derivatives (computeRNEADerivatives) through a CasADi callback: first derivatives only
    (module docstring)."""

    name = "pinocchio-rnea"
    algorithm = RNEA

    def residual(self, q, qd, qdd, tau_rigid):
        """(RNEA(q, qd, qdd) − tau_rigid) / tau_max, dimensionless."""
        return (self.rigid_term(q, qd, qdd) - tau_rigid) / ca.DM(self.robot.tau_max)
