"""What every transcription's NLP shares, so each transcription module holds only its own math.

A transcription creates its variables through `Assembly.w` (a Layout: the order of creation is the order in
w) and adds its rows in the order it wants them; the assembly supplies the rest the same way for all:

- the shared parameters p = [μ, margin, limit_scale, each constraint's own parameters, ...];
- the values at a point, `point(node, du_ds, dt_ds)`: joint torque τ = τ_max ∘ u + friction(q̇) and its rate
  dτ/ds = τ_max du/ds + friction'(q̇) (dt/ds) q̈, where dt/ds is the transcription's (t_f/(2K) on a
  pseudospectral segment, h = t_f/N on a mesh interval), so rate bounds read |dτ/ds| ≤ (dt/ds) τ̇_max and t_f
  never divides;
- the path constraints at a point (`path`, `rates`), each constraint imposed as it declares (constraints.base);
- the dynamic defect residual(q, q̇, q̈, τ_max u) at a collocation point;
- the rows lbg ≤ g ≤ ubg in the order they were added, and the finished `NLP`;
- the knot columns [q, q̇, q̈, u] of any trajectory (u is its rigid-body torque rnea(q, q̇, q̈) / τ_max, see
  docs/transcription.md, section "The control u", for why) and the paper's straight-line guess.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint, Context, PointValues, Rows
from ocpkit.dynamics import Dynamics
from ocpkit.nlp import NLP, Layout, Stages
from ocpkit.problem import Problem
from ocpkit.robots import Robot, rigid_torque
from ocpkit.trajectory import Samples, Trajectory


class Node(NamedTuple):
    """[q, q̇, q̈, u] at one point: CasADi (n, 1) columns, or NumPy (m, n) rows when decoding."""

    q: Any
    qd: Any
    qdd: Any
    u: Any


class Assembly:
    """The variables, parameters and rows of one NLP under construction (see the module docstring)."""

    def __init__(self, problem: Problem, dynamics: Dynamics, constraints: Sequence[Constraint]) -> None:
        self.robot, self.dynamics, self.constraints = problem.robot, dynamics, tuple(constraints)
        self.w, self.p = Layout("w"), Layout("p")
        self.mu, margin, limit_scale = (self.p.add(name) for name in ("mu", "margin", "limit_scale"))
        self.contexts = [Context(dynamics, margin, limit_scale, {
            name: self.p.add(f"{c.name}.{name}", *shape) for name, shape in c.parameter_shapes().items()})
            for c in self.constraints]
        self.tau_max = ca.DM(self.robot.tau_max)
        v, a = ca.SX.sym("qd", self.robot.n), ca.SX.sym("qdd", self.robot.n)  # friction'(q̇) a by AD of the law
        self._friction = ca.Function("friction", [v], [dynamics.friction(v)])
        self._friction_rate = ca.Function("friction_rate", [v, a], [ca.jtimes(dynamics.friction(v), v, a)])
        self.g: list[ca.SX] = []
        self.lbg: list[np.ndarray] = []
        self.ubg: list[np.ndarray] = []

    # -- variables -----------------------------------------------------------------------------------
    def node(self, name: str) -> Node:
        """New variables [q; q̇; q̈; u] (4n) in w under `name`."""
        x, n = self.w.add(name, 4 * self.robot.n), self.robot.n
        return Node(*(x[k * n:(k + 1) * n] for k in range(4)))

    def name_knots(self, knots: Sequence[str], start: int, goal: int) -> None:
        """Name the knot nodes `knots` (in the transcription's column order) as "X" (K, 4n) and "q", "qd",
        "qdd", "u" (K, n); the [q, q̇, q̈] of knot `start` as "start" and of knot `goal` as "goal"."""
        n, X = self.robot.n, np.stack([self.w.index(name) for name in knots])
        self.w.name("X", X)
        for k, part in enumerate(("q", "qd", "qdd", "u")):
            self.w.name(part, X[:, k * n:(k + 1) * n])
        self.w.name("start", X[start, :3 * n])
        self.w.name("goal", X[goal, :3 * n])

    # -- rows ----------------------------------------------------------------------------------------
    @property
    def row_count(self) -> int:
        """Rows added so far."""
        return sum(len(lower) for lower in self.lbg)

    def add(self, rows: Rows) -> None:
        """The rows lower ≤ g ≤ upper (bounds broadcast to g's length)."""
        self.g.append(rows.g)
        self.lbg.append(np.broadcast_to(rows.lower, (rows.g.numel(),)))
        self.ubg.append(np.broadcast_to(rows.upper, (rows.g.numel(),)))

    def defect(self, expr: ca.SX) -> None:
        """The rows expr = 0."""
        self.add(Rows(expr, 0.0, 0.0))

    def dynamics_defect(self, x: Node) -> None:
        """The dynamics at one collocation point: residual(q, q̇, q̈, τ_max u) = 0."""
        self.defect(self.dynamics.residual(x.q, x.qd, x.qdd, self.tau_max * x.u))

    def point(self, x: Node, du_ds: ca.SX, dt_ds: ca.SX) -> PointValues:
        """Values at one point; du_ds is du/ds, so dτ/ds = τ_max du_ds + friction'(q̇) (dt/ds) q̈."""
        return PointValues(x.q, x.qd, x.qdd, self.tau_max * x.u + self._friction(x.qd),
                           self.tau_max * du_ds + self._friction_rate(x.qd, dt_ds * x.qdd), dt_ds)

    def path(self, x: Node, slopes: Sequence[ca.SX], dt_ds: ca.SX, at_knot: bool = False) -> None:
        """Every path constraint at one point, in the constraints' order: those not reading rates once (at a
        knot, less those imposed as knot bounds), those reading dτ/ds once per one-sided slope du/ds in
        `slopes` (none without slopes)."""
        first, *others = [self.point(x, slope, dt_ds) for slope in slopes] or [
            self.point(x, ca.SX.zeros(self.robot.n), dt_ds)]
        for constraint, context in zip(self.constraints, self.contexts):
            if _imposed(constraint, bool(slopes), at_knot):
                self.add(constraint.evaluate(first, context))
        for values in others:
            self._rates(values)

    def rates(self, x: Node, slopes: Sequence[ca.SX], dt_ds: ca.SX) -> None:
        """The constraints reading dτ/ds at one point, once per one-sided slope du/ds in `slopes`."""
        for slope in slopes:
            self._rates(self.point(x, slope, dt_ds))

    def _rates(self, values: PointValues) -> None:
        for constraint, context in zip(self.constraints, self.contexts):
            if constraint.reads_rate:
                self.add(constraint.evaluate(values, context))

    # -- the result ----------------------------------------------------------------------------------
    def nlp(self, f: ca.SX, shape_key: tuple, stages: Stages | None = None) -> NLP:
        """The finished NLP with objective f, as the dynamics backend hands it to solvers (`Dynamics.lift`)."""
        fields = self.dynamics.lift({"x": self.w.symbol(), "p": self.p.symbol(), "f": f, "g": ca.vertcat(*self.g)})
        return NLP(fields["x"], fields["p"], fields["f"], fields["g"], np.concatenate(self.lbg),
                   np.concatenate(self.ubg), self.w, self.p, shape_key, fields.get("exact_hessian", True), stages)


def _imposed(constraint: Constraint, with_rate: bool, at_knot: bool) -> bool:
    """Whether `path` adds `constraint` at a point (with a slope du/ds or not; at a knot or not)."""
    if constraint.reads_rate:
        return with_rate
    return not (at_knot and constraint.at_knots == "bounds")


def knot_columns(robot: Robot, samples: Samples) -> np.ndarray:
    """Rows [q, q̇, q̈, u] (m, 4n) of sampled values, u = rnea(q, q̇, q̈) / τ_max (the rigid-body torque)."""
    rigid = rigid_torque(robot, samples.q, samples.qd, samples.qdd)
    return np.hstack([samples.q, samples.qd, samples.qdd, rigid / robot.tau_max])


def joint_samples(robot: Robot, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
    """Samples from interpolated [q, q̇, q̈, u] rows and du/dt: τ = τ_max u + friction(q̇), τ̇ = τ_max u̇ +
    friction'(q̇) q̈ (the torque the plan commands; verify compares it with rnea(q, q̇, q̈) + friction(q̇))."""
    return Samples(np.asarray(t, dtype=float), x.q, x.qd, x.qdd, robot.tau_max * x.u + robot.friction(x.qd),
                   robot.tau_max * du_dt + robot.friction_slope(x.qd) * x.qdd)


def straight_line(problem: Problem) -> Trajectory:
    """The paper's initial guess: start to goal at constant joint speed over t_f = time.guess (infeasible at
    the ends, where it does not start and stop at rest)."""
    tf, delta = problem.time.guess, problem.goal - problem.start

    def line(t: np.ndarray) -> Samples:
        zeros = np.zeros((len(t), problem.robot.n))
        return Samples(t, problem.start + np.outer(t / tf, delta), np.tile(delta / tf, (len(t), 1)), zeros, zeros,
                       zeros)

    return Trajectory(line(np.array([0.0, tf])), line)
