"""Dynamics backend `pinocchio`: the dynamic defect evaluated by numeric pinocchio through a CasADi callback.

Form: the inverse one of `casadi-rnea`, residual = (RNEA(q, q̇, q̈) − τ_rigid) / τ_max, with RNEA computed by
`pinocchio.rnea` and its first derivatives by `pinocchio.computeRNEADerivatives` (∂τ/∂q, ∂τ/∂q̇ and ∂τ/∂q̈ = M(q)).
Friction, `forward`, `inverse` and the sphere kinematics stay symbolic (inherited from `CasadiRnea`): only the
rigid-body dynamics of the defect goes through pinocchio.

SX and MX. A `casadi.Callback` can be called on MX only; the transcriptions build their NLPs in SX (cheap to
evaluate, one graph). So `residual` on SX arguments returns the defect with a fresh SX *placeholder* symbol in
place of RNEA(q, q̇, q̈) and records the call; `lift(fields)` then turns the finished SX NLP into an MX one of
three nodes: x, p ↦ the stacked RNEA arguments (one SX function), one callback call that evaluates all
recorded points at once (one Python call per evaluation, not one per point), and x, p, RNEA values ↦ f, g
(the original SX function). On MX arguments `residual` calls the callback directly; on numbers it calls
pinocchio.

Hessian strategy: the callback provides values and first derivatives only, so the NLP has no exact Lagrangian
Hessian. `exact_hessian = False` tells the solver to use a quasi-Newton approximation instead (IPOPT:
`hessian_approximation = limited-memory`, L-BFGS).
"""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin

from ocpkit.dynamics.casadi_aba import CasadiRnea
from ocpkit.robots import Robot

_ALIVE: list[ca.Callback] = []  # CasADi holds Python callbacks by raw pointer: keep every one referenced


class RneaCallback(ca.Callback):
    """pinocchio RNEA at K points: input (3n, K) with columns [q; q̇; q̈], output (n, K) with columns τ (N m).

    The Jacobian (nK, 3nK) is block diagonal, one dense (n, 3n) block [∂τ/∂q, ∂τ/∂q̇, M] per point, from
    `computeRNEADerivatives`; the callback declares that sparsity so CasADi colours it."""

    def __init__(self, name: str, model: pin.Model, points: int, opts: dict | None = None) -> None:
        ca.Callback.__init__(self)
        self.model, self.data, self.n, self.points = model, model.createData(), model.nv, points
        self._jacobian: RneaJacobian | None = None
        self.construct(name, opts or {})
        _ALIVE.append(self)

    def get_n_in(self) -> int:
        return 1

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return "x"

    def get_name_out(self, i: int) -> str:
        return "tau"

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(3 * self.n, self.points)

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(self.n, self.points)

    def eval(self, arg):
        return [ca.DM(self.rnea(np.asarray(arg[0], dtype=float)))]

    def rnea(self, x: np.ndarray) -> np.ndarray:
        """τ (n, K) for columns x (3n, K)."""
        n, out = self.n, np.empty((self.n, self.points))
        for k in range(self.points):
            out[:, k] = pin.rnea(self.model, self.data, x[:n, k], x[n:2 * n, k], x[2 * n:, k])
        return out

    def jacobian_blocks(self, x: np.ndarray) -> list[np.ndarray]:
        """[∂τ/∂q, ∂τ/∂q̇, ∂τ/∂q̈] (n, 3n) at every column of x."""
        n, blocks = self.n, []
        for k in range(self.points):
            dq, dv, da = pin.computeRNEADerivatives(self.model, self.data, x[:n, k], x[n:2 * n, k], x[2 * n:, k])
            mass = np.triu(da) + np.triu(da, 1).T  # pinocchio may fill the upper triangle only
            blocks.append(np.hstack([dq, dv, mass]))
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
        self._jacobian = RneaJacobian(name, self, opts)
        return self._jacobian


class RneaJacobian(ca.Callback):
    """d tau / d x of an RneaCallback: inputs (x, nominal τ), output the block-diagonal Jacobian. It has no
    derivatives of its own (hence no exact Hessian)."""

    def __init__(self, name: str, rnea: RneaCallback, opts: dict) -> None:
        ca.Callback.__init__(self)
        self.rnea = rnea
        self.construct(name, opts)
        _ALIVE.append(self)

    def get_n_in(self) -> int:
        return 2

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return self.rnea.get_sparsity_in(0) if i == 0 else self.rnea.get_sparsity_out(0)

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return self.rnea.jacobian_sparsity

    def eval(self, arg):
        blocks = self.rnea.jacobian_blocks(np.asarray(arg[0], dtype=float))
        # nonzeros column-major: the block of point k owns columns 3nk..3n(k+1) and rows nk..n(k+1)
        return [ca.DM(self.rnea.jacobian_sparsity, np.concatenate([b.ravel(order="F") for b in blocks]))]


class PinocchioRnea(CasadiRnea):
    """Inverse form with pinocchio's numeric RNEA and analytic derivatives in the defect (module docstring)."""

    name = "pinocchio"
    exact_hessian = False

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        self._placeholders: list[ca.SX] = []  # one (n, 1) SX symbol per SX residual call
        self._arguments: list[ca.SX] = []  # its [q; q̇; q̈] (3n, 1)

    def residual(self, q, qd, qdd, tau_rigid):
        """(RNEA(q, qd, qdd) − tau_rigid) / tau_max, dimensionless; SX arguments give a placeholder for RNEA
        that `lift` replaces by the callback."""
        scale = ca.DM(self.robot.tau_max)
        if any(isinstance(v, ca.MX) for v in (q, qd, qdd, tau_rigid)):
            rigid = self.callback(1)(ca.vertcat(q, qd, qdd))
        elif any(isinstance(v, ca.SX) for v in (q, qd, qdd, tau_rigid)):
            rigid = ca.SX.sym(f"rnea_{len(self._placeholders)}", self.robot.n)
            self._placeholders.append(rigid)
            self._arguments.append(ca.vertcat(q, qd, qdd))
        else:
            model = self.robot.model
            rigid = ca.DM(pin.rnea(model, model.createData(), *(np.asarray(ca.DM(v), dtype=float).ravel()
                                                                 for v in (q, qd, qdd))))
        return (rigid - tau_rigid) / scale

    def callback(self, points: int) -> RneaCallback:
        """A new RNEA callback over `points` points."""
        return RneaCallback(f"pinocchio_rnea_{points}", self.robot.model, points)

    def lift(self, fields: dict) -> dict:
        """The SX NLP `fields` (x, p, f, g, ...) as an MX NLP in which the recorded placeholders are the
        callback's values at their arguments; marks it `exact_hessian = False`. Without recorded calls the
        fields come back unchanged but for that mark."""
        fields = dict(fields, exact_hessian=False)
        if not self._placeholders:
            return fields
        x, p = fields["x"], fields["p"]
        placeholders = ca.horzcat(*self._placeholders)  # (n, K)
        arguments = ca.Function("rnea_arguments", [x, p], [ca.horzcat(*self._arguments)])
        body = ca.Function("nlp_body", [x, p, placeholders], [fields["f"], fields["g"]])
        X, P = ca.MX.sym("x", x.sparsity()), ca.MX.sym("p", p.sparsity())
        rigid = self.callback(len(self._placeholders))(arguments(X, P))
        f, g = body(X, P, rigid)
        return dict(fields, x=X, p=P, f=f, g=g)
