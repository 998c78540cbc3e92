"""What every transcription's NLP shares, so each transcription module holds only its own math.

A transcription creates its variables through `Assembly.w` (a Layout: the order of creation is the order in
w) and adds its rows in the order it wants them; the assembly supplies the rest the same way for all, written
against the OCP it discretizes (ocpkit.transcription.ocp: the paper's robot OCP unless told otherwise):

- the shared parameters p = [μ, margin, limit_scale, each constraint's own parameters, the OCP's, ...];
- the nodes [x, u] (the OCP's states and controls);
- the values at a point, `point(node, du_ds, dt_ds)`, as the OCP gives them for its path constraints
  (`OCP.point_values`; for a robot: (q, q̇, q̈), the joint torque and its rate dτ/dσ) from the interpolant's
  slope du/dσ, where dt/dσ is the transcription's (t_f/(2K) on a pseudospectral segment, h = t_f/N on a mesh
  interval), so rate bounds read |dτ/dσ| ≤ (dt/dσ) τ̇_max and t_f never divides;
- the path constraints at a point (`path`, `rates`), each constraint imposed as it declares (constraints.base),
  through one CasADi Function per constraint of a symbolic point, made once and inlined at every point (running a
  constraint's Python code point by point makes graph construction slow);
- the OCP's algebraic rows at a collocation point (for the robot OCP the dynamics residual(q, q̇, q̈, τ_max u) =
  0), also through one Function of a symbolic node where the dynamics backend is symbolic (exact second
  derivatives);
- a record of those point Functions' rows (`NLP.point_calls`), from which IPOPT's derivatives are built point by
  point (ocpkit.solvers.pointwise);
- the OCP's running-cost inputs at a point (`running`); the objective, through a Function of its inputs where the
  transcription gives it so (`objective`);
- the rows lbg ≤ g ≤ ubg in the order they were added, and the finished `NLP`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint, Context, PointValues, Rows
from ocpkit.dynamics import Dynamics
from ocpkit.kept import Kept
from ocpkit.nlp import NLP, Layout, PointCall, Stages
from ocpkit.problem import Problem
from ocpkit.transcription.ocp import OCP, Node, RobotOCP

__all__ = ["Assembly", "Node", "forget_defects"]

_DEFECTS: Kept[tuple[OCP, ca.Function]] = Kept(16)
"""The OCP's defect Functions kept for reuse (`Assembly._defect_function`), one per dynamics backend and OCP, with
the OCP they were made for."""


class Assembly:
    """The variables, parameters and rows of one NLP under construction (see the module docstring)."""

    def __init__(self, problem: Problem | None, dynamics: Dynamics | None, constraints: Sequence[Constraint],
                 ocp: OCP | None = None) -> None:
        self.dynamics, self.constraints = dynamics, tuple(constraints)
        self.ocp = ocp or RobotOCP(problem.robot)
        self.w, self.p = Layout("w"), Layout("p")
        self.mu, margin, limit_scale = (self.p.add(name) for name in ("mu", "margin", "limit_scale"))
        self.contexts = [Context(dynamics, margin, limit_scale, {
            name: self.p.add(f"{c.name}.{name}", *shape) for name, shape in c.parameter_shapes().items()})
            for c in self.constraints]
        ocp_parameters = {name: self.p.add(f"ocp.{name}", *shape)
                          for name, shape in self.ocp.parameter_shapes().items()}
        self.ocp.use_parameters(ocp_parameters)
        self._ocp_parameters = tuple(ocp_parameters.values())
        self._point = self.ocp.point_values(dynamics)
        self._point_rows: dict[int, tuple[ca.Function, np.ndarray, np.ndarray]] = {}
        self._defect: ca.Function | None = None
        self._defect_by_function = getattr(dynamics, "exact_hessian", True)  # a callback backend records its calls
        self.point_calls: list[PointCall] = []
        self.objective_call: PointCall | None = None
        self.g: list[ca.SX] = []
        self.lbg: list[np.ndarray] = []
        self.row_count = 0  # rows added so far
        self.ubg: list[np.ndarray] = []

    # -- variables -----------------------------------------------------------------------------------
    def node(self, name: str) -> Node:
        """New variables [x; u] (the OCP's width) in w under `name`."""
        return self.ocp.split(self.w.add(name, self.ocp.width))

    def name_knots(self, knots: Sequence[str], start: int, goal: int) -> None:
        """Name the knot nodes `knots` (in the transcription's column order) as "X" (K, width) and each of the
        OCP's parts by its name (e.g. "q", "qd", "qdd", "u") (K, size); the first `OCP.ends` values of knot `start`
        as "start" and of knot `goal` as "goal"."""
        X = np.stack([self.w.index(name) for name in knots])
        self.w.name("X", X)
        for part, columns in self.ocp.part_slices().items():
            self.w.name(part, X[:, columns])
        self.w.name("start", X[start, :self.ocp.ends])
        self.w.name("goal", X[goal, :self.ocp.ends])

    # -- rows ----------------------------------------------------------------------------------------
    def add(self, rows: Rows) -> None:
        """The rows lower ≤ g ≤ upper (bounds broadcast to g's length)."""
        self.row_count += rows.g.numel()
        self.g.append(rows.g)
        self.lbg.append(np.broadcast_to(rows.lower, (rows.g.numel(),)))
        self.ubg.append(np.broadcast_to(rows.upper, (rows.g.numel(),)))

    def defect(self, expr: ca.SX) -> None:
        """The rows expr = 0."""
        self.add(Rows(expr, 0.0, 0.0))

    def dynamics_defect(self, x: Node) -> None:
        """The OCP's rows at one collocation point (`OCP.defect`: the dynamics for the robot OCP) = 0."""
        if not self._defect_by_function:
            self.defect(self.ocp.defect(self.dynamics, x))
            return
        values = self.ocp.join(x)
        parts = tuple(values[columns] for columns in self.ocp.part_slices().values())  # the Function's inputs
        if self._defect is None:
            self._defect = self._defect_function(parts)
        if self._defect.numel_out(0):
            self._call(self._defect, parts, self._ocp_parameters, 0.0, 0.0, compiled=True)

    def _defect_function(self, parts: tuple[ca.SX, ...]) -> ca.Function:
        """The Function (the node's parts, the OCP's parameters) → the OCP's defect: the same object for every
        NLP of the same dynamics backend and OCP (their keys), so the derivatives built for it, and their compiled
        code, are reused with it (ocpkit.solvers.pointwise), and its graph is made once."""
        key = (self.dynamics and self.dynamics.key, type(self.ocp), self.ocp.key, tuple(p.shape for p in parts),
               tuple(p.shape for p in self._ocp_parameters))

        def made() -> tuple[OCP, ca.Function]:  # with the OCP, whose key may hold its model's id: kept alive
            symbols = _symbols_like(parts)
            return self.ocp, ca.Function("defect", [*symbols, *self._ocp_parameters],
                                         [self.ocp.defect(self.dynamics, self.ocp.split(ca.vertcat(*symbols)))])

        return _DEFECTS.get(key, made)[1]

    def running(self, x: Node, du_ds: ca.SX, dt_ds: ca.SX, t: ca.SX) -> ca.SX:
        """The OCP's running-cost inputs at a point at time t where the controls have slope du/dσ = `du_ds`."""
        return self.ocp.running(x, du_ds, dt_ds, t)

    def objective(self, formula: Callable[..., ca.SX], inputs: Sequence[ca.SX], parameters: Sequence[ca.SX]) -> ca.SX:
        """The objective formula(*inputs, *parameters) (inputs: expressions of w and p; parameters: symbols of p),
        through one Function of symbolic inputs, recorded as the NLP's objective call."""
        symbols = _symbols_like(inputs)
        function = ca.Function("objective", [*symbols, *parameters], [formula(*symbols, *parameters)])
        self.objective_call = PointCall(function, tuple(inputs), tuple(parameters), 0)
        return function(*inputs, *parameters)

    def point(self, x: Node, du_ds: ca.SX, dt_ds: ca.SX, t: ca.SX | None) -> PointValues | tuple[ca.SX, ...]:
        """Values at one point at time t where the controls' interpolant has the slope du/dσ = `du_ds`; for an OCP
        whose constraints read the node (`OCP.constraints_read_node`), (x, u, du/dσ, dt/dσ), which the constraints'
        point Functions turn into the values."""
        if self.ocp.constraints_read_node:
            return x.x, x.u, du_ds, dt_ds
        return self._point(x, du_ds, dt_ds, t)

    def path(self, x: Node, slopes: Sequence[ca.SX], dt_ds: ca.SX, t: ca.SX | None, at_knot: bool = False) -> None:
        """Every path constraint at one point at time t, in the constraints' order: those not reading rates once
        (at a knot, less those imposed as knot bounds where the OCP's chain is q), those reading rates once per
        one-sided slope du/dσ in `slopes` (none without slopes)."""
        first, *others = [self.point(x, slope, dt_ds, t) for slope in slopes] or [
            self.point(x, ca.SX.zeros(self.ocp.controls), dt_ds, t)]
        for index, constraint in enumerate(self.constraints):
            if _imposed(constraint, bool(slopes), at_knot and self.ocp.knot_bounds):
                self._constraint(index, first)
        for values in others:
            self._rates(values)

    def rates(self, x: Node, slopes: Sequence[ca.SX], dt_ds: ca.SX, t: ca.SX) -> None:
        """The constraints reading rates at one point at time t, once per one-sided slope du/dσ in `slopes`."""
        for slope in slopes:
            self._rates(self.point(x, slope, dt_ds, t))

    def _rates(self, values: PointValues | tuple[ca.SX, ...]) -> None:
        for index, constraint in enumerate(self.constraints):
            if constraint.reads_rate:
                self._constraint(index, values)

    def _constraint(self, index: int, values: PointValues | tuple[ca.SX, ...]) -> None:
        """Constraint `index`'s rows at one point (`point`'s values, or the node), through one CasADi Function of a
        symbolic point made on first use: the constraint's Python code runs once per NLP instead of once per point
        (the calls are inlined)."""
        by_node = self.ocp.constraints_read_node
        fields = values if by_node else _point_fields(values)
        parameters = (*(self._ocp_parameters if by_node else ()), *_context_symbols(self.contexts[index]))
        if index not in self._point_rows:
            symbols = _symbols_like(fields)
            point = self._point(Node(*symbols[:2]), *symbols[2:], None) if by_node else type(values)(*symbols)
            rows = self.constraints[index].evaluate(point, self.contexts[index])
            function = ca.Function("point_rows", [*symbols, *parameters], [rows.g])
            self._point_rows[index] = function, rows.lower, rows.upper
        function, lower, upper = self._point_rows[index]
        self._call(function, fields, parameters, lower, upper, constraint=None if by_node else self.constraints[index])

    def _call(self, function: ca.Function, inputs: tuple, parameters: tuple, lower: np.ndarray | float,
              upper: np.ndarray | float, compiled: bool = False, constraint: Constraint | None = None) -> None:
        """The rows lower ≤ function(*inputs, *parameters) ≤ upper, recorded as a point call (see PointCall)."""
        self.point_calls.append(PointCall(function, inputs, parameters, self.row_count, compiled, constraint))
        self.add(Rows(function(*inputs, *parameters), lower, upper))

    # -- the result ----------------------------------------------------------------------------------
    def nlp(self, f: ca.SX, shape_key: tuple, stages: Stages | None = None) -> NLP:
        """The finished NLP with objective f, as the dynamics backend hands it to solvers (`Dynamics.lift`)."""
        g = ca.vertcat(*self.g)
        fields = {"x": self.w.symbol(), "p": self.p.symbol(), "f": f, "g": g}
        if self.dynamics is not None:
            fields = self.dynamics.lift(fields)
        unchanged = fields["g"] is g  # a lifted (MX) NLP has no SX point calls
        return NLP(fields["x"], fields["p"], fields["f"], fields["g"], np.concatenate(self.lbg),
                   np.concatenate(self.ubg), self.w, self.p, shape_key, fields.get("exact_hessian", True), stages,
                   tuple(self.point_calls) if unchanged else (), self.objective_call if unchanged else None)


def forget_defects() -> None:
    """Forget the defect Functions kept for reuse (`Assembly._defect_function`)."""
    _DEFECTS.clear()


def _point_fields(values: PointValues) -> tuple:
    """The fields of `values` (a dataclass of point values: PointValues for a robot) in order (dataclasses.astuple
    would deep-copy the CasADi expressions)."""
    return tuple(getattr(values, field.name) for field in dataclasses.fields(values))


def _context_symbols(context: Context) -> tuple[ca.SX, ...]:
    """The NLP parameter symbols a constraint may read: margin, limit_scale and its own parameters."""
    return context.margin, context.limit_scale, *context.parameters.values()


def _symbols_like(values: Sequence[ca.SX]) -> list[ca.SX]:
    """New symbols of the shapes of `values`: the inputs of a point Function (made once, called at every point)."""
    return [ca.SX.sym(f"input{i}", *value.shape) for i, value in enumerate(values)]


def _imposed(constraint: Constraint, with_rate: bool, at_knot: bool) -> bool:
    """Whether `path` adds `constraint` at a point (with a slope du/ds or not; at a knot or not)."""
    if constraint.reads_rate:
        return with_rate
    return not (at_knot and constraint.at_knots == "bounds")
