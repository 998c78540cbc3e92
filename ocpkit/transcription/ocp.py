"""The optimal control problem a transcription discretizes: everything it needs beyond its own math.

Every OCP here is an ODE ẋ = f(x, u) on states x and controls u, with path rows and a cost (docs/architecture.md,
"One transcription code path"). A transcription holds a node [x, u] at each of its points, collocates
ẋ = f(x, u) by its own rule, interpolates u by its own polynomial (so du/dσ exists at every point) and asks the
OCP for the rest:

- `parts`: names and widths of the node's consecutive parts (x's then u's), which name the knot variables;
  `ends` (the leading node values fixed or bounded at the start and goal, "start" and "goal"); `check_parts`
  (the leading parts lifted as variables at the check points between knots);
- `rate`: f(x, u) at a node (CasADi or NumPy rows); `defect`: algebraic rows = 0 at each collocation point;
- `point_values`: the values the OCP's path constraints read at a point, from the node, du/dσ and dt/dσ (σ the
  transcription's own time variable);
- `running`: the integrand's inputs at a quadrature point, and `mayer` and `lagrange`, which make the cost from
  them (`objective_parameters` are NLP parameters the cost reads), `boundary` rows on the end nodes;
- bounds on the parts (`chain_bounds`), the ends (`end_bounds`) and t_f (`time_bounds`), and a guess;
- its own NLP parameters (`parameter_shapes`, `parameter_values`; the assembly hands the OCP their symbols by
  `use_parameters` before the build), so OCPs of one `key` share one NLP.

Three instances: `RobotOCP` (the paper's problem: x = [q, q̇], u = [q̈, τ/τ_max], f = [q̇, q̈], the dynamics
residual as the algebraic rows, cost t_f + μ ∫ q⃛ᵀ Q q⃛ dt with q⃛ = dq̈/dt, a control rate), `PathTimingOCP`
(x = [s, ṡ] along a fixed path p(s), u = s̈) and `ModelOCP` (ocpkit.ocp: any `Ocp` a user writes).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
import pinocchio as pin

from ocpkit.constraints import PointValues
from ocpkit.dynamics import Dynamics
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.path_spline import DEGREE, PathSpline, symbolic
from ocpkit.problem import Problem
from ocpkit.robots import Robot, rigid_torque


class Node(NamedTuple):
    """[x, u] at one point: CasADi columns (states, 1) and (controls, 1), or NumPy rows (points, states) and
    (points, controls) when decoding."""

    x: Any
    u: Any


PointFunction = Callable[[Node, Any, Any, Any], Any]
"""(node, du/dσ, dt/dσ, t) ↦ the values the OCP's path constraints read at that point (t in s; None where the
transcription does not form it: at the lifted check points, which only OCPs that never read t have)."""


class OCP(ABC):
    """What a transcription needs of the problem it discretizes (module docstring)."""

    states: int
    controls: int
    parts: tuple[tuple[str, int], ...]
    ends: int
    check_parts: int = 0
    knot_bounds: bool = False
    extrapolated_controls: bool = False
    """Whether a pseudospectral transcription fixes the controls at a knot it does not collocate (LGR's free end)
    by extrapolation; a robot's dynamics rows fix them there already."""
    constraints_read_node: bool = False
    """Whether the path constraints' point Functions take the node itself (x, u, du/dσ, dt/dσ) and form the point
    values inside, instead of taking the values: for an OCP whose values are not linear in its node (a path
    timing's q = p(s)), so the constraint rows stay point calls linear in w, differentiated once per Function
    (ocpkit.solvers.pointwise) rather than through the whole NLP's graph. Its point values must not read t."""

    @property
    @abstractmethod
    def key(self) -> tuple:
        """Hashable, equal exactly when two OCPs give the same NLP for the same transcription and robot (their
        parameter values may differ)."""

    def parameter_shapes(self) -> dict[str, tuple[int, int]]:
        """Name → (rows, columns) of each NLP parameter of the OCP; none by default."""
        return {}

    def parameter_values(self) -> dict[str, np.ndarray]:
        """Name → value (shaped as declared) of each parameter."""
        return {}

    def use_parameters(self, symbols: dict[str, ca.SX]) -> None:
        """Take the symbols of the declared parameters, by name, for the expressions built afterwards."""

    @property
    def width(self) -> int:
        """Values of one node [x, u]."""
        return self.states + self.controls

    def split(self, values: Any) -> Node:
        """A node from its stacked values: a CasADi column (width,) or NumPy rows (points, width)."""
        n = self.states
        if isinstance(values, np.ndarray) and values.ndim == 2:
            return Node(values[:, :n], values[:, n:self.width])
        return Node(values[:n], values[n:self.width])

    @staticmethod
    def join(x: Node) -> Any:
        """The stacked values of a node (the inverse of `split`)."""
        if isinstance(x.x, np.ndarray):
            return np.hstack([x.x, x.u])
        return ca.vertcat(x.x, x.u)

    def part_slices(self) -> dict[str, slice]:
        """Part name → its slice of a node's values."""
        slices, start = {}, 0
        for name, size in self.parts:
            slices[name] = slice(start, start + size)
            start += size
        return slices

    @property
    def lifted(self) -> tuple[tuple[str, int], ...]:
        """The parts lifted at the check points (the first `check_parts`)."""
        return self.parts[:self.check_parts]

    @abstractmethod
    def rate(self, x: Node, t: Any) -> Any:
        """ẋ = f(x, u, t) (states,) at a symbolic node at time t, or rows (points, states) at NumPy nodes at times
        t (points,)."""

    def defect(self, dynamics: Dynamics | None, x: Node) -> ca.SX:
        """The algebraic rows (k, 1) that must be 0 at a collocation point; none by default."""
        return ca.SX(0, 1)

    @abstractmethod
    def point_values(self, dynamics: Dynamics | None) -> PointFunction:
        """The values the path constraints read at a point (`PointFunction`), on `dynamics`' expressions."""

    @abstractmethod
    def running(self, x: Node, du_ds: ca.SX, dt_ds: ca.SX, t: ca.SX) -> ca.SX:
        """The running cost's inputs (k, 1) at a quadrature point at time t with du/dσ = `du_ds` and dt/dσ =
        `dt_ds`."""

    def objective_parameters(self, mu: ca.SX) -> list[ca.SX]:
        """The NLP parameter symbols the cost reads (`mu` is the shared cost weight); none by default."""
        return []

    def mayer_inputs(self, start: Node, goal: Node) -> list[ca.SX]:
        """The expressions of w the Mayer term reads besides t_f; none by default."""
        return []

    @abstractmethod
    def mayer(self, tf: ca.SX, inputs: Sequence[ca.SX], parameters: Sequence[ca.SX]) -> ca.SX:
        """The Mayer term at t_f from `mayer_inputs` (as symbols or expressions) and `objective_parameters`."""

    @abstractmethod
    def lagrange(self, runs: ca.SX, weights: np.ndarray, tf: ca.SX, per_tf: float,
                 parameters: Sequence[ca.SX]) -> ca.SX:
        """∫ L dt over points sharing dt/dσ = tf / per_tf, from their stacked `running` values `runs` and the
        σ-quadrature `weights` (points,)."""

    def boundary(self, a: Any, start: Node, goal: Node, tf: ca.SX) -> None:
        """Add rows on the end nodes to the assembly `a`; none by default."""

    def cost_weight(self, problem: Problem | None) -> float:
        """μ, the value of the shared cost weight parameter; 0 by default."""
        return 0.0

    @abstractmethod
    def time_bounds(self, problem: Problem | None) -> tuple[float, float]:
        """(lower, upper) of t_f (s)."""

    @abstractmethod
    def end_bounds(self, problem: Problem | None) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """((lower, upper) at the start, (lower, upper) at the goal) of the first `ends` node values."""

    def chain_bounds(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Part name → (lower, upper) of every knot's part, besides the constraints'; none by default."""
        return {}

    @abstractmethod
    def guess(self, problem: Problem | None) -> Trajectory:
        """A chain trajectory (`chain_samples`' form) to start from when no other is given."""

    # -- numbers ---------------------------------------------------------------------------------------
    @abstractmethod
    def columns(self, chain: Samples) -> np.ndarray:
        """Node rows [x, u] (points, width) of a chain trajectory's samples (`chain_samples`' form)."""

    @abstractmethod
    def chain_samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """The node's own samples at times t (points,), as `Discretization.encode` and `write_checks` read them."""

    @abstractmethod
    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """The samples a decoded trajectory reports at times t (points,), from interpolated node rows and the
        interpolant's du/dt (points, controls)."""


class ChainOCP(OCP):
    """An OCP whose states are a chain of two integrators x → ẋ (m values each) driven by the first m controls
    ẍ: f = [ẋ, ẍ], time-invariant. Its chain samples carry x, ẋ, ẍ as the Samples' q, qd, qdd and the other
    controls and their rates as tau, taud; its running input is the robot's jerk times dt/dσ (`jerk_s`), which the
    cost t_f + μ ∫ q⃛ᵀ Q q⃛ dt integrates with Q = diag(1 / R²) (R the gear ratios, `Problem.jerk_weights`)."""

    chain: int
    ends = 0
    check_parts = 3

    def __init__(self, robot: Robot) -> None:
        self.robot = robot

    def rate(self, x: Node, t: Any) -> Any:
        m = self.chain
        if isinstance(x.x, np.ndarray):
            return np.hstack([x.x[:, m:], x.u[:, :m]])
        return ca.vertcat(x.x[m:], x.u[:m])

    def chain_parts(self, x: Node) -> tuple[Any, Any, Any, Any]:
        """(x, ẋ, ẍ, the other controls) of a node (columns or rows)."""
        m = self.chain
        if isinstance(x.x, np.ndarray):
            return x.x[:, :m], x.x[:, m:], x.u[:, :m], x.u[:, m:]
        return x.x[:m], x.x[m:], x.u[:m], x.u[m:]

    @abstractmethod
    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        """The robot's (q, q̇, q̈), each (n, 1), at a symbolic node."""

    def point_values(self, dynamics: Dynamics | None) -> PointFunction:
        torque = self.torque_function(dynamics)
        return lambda x, du_ds, dt_ds, t: PointValues(*self.robot_state(x), *torque(x, du_ds, dt_ds), dt_ds)

    @abstractmethod
    def torque_function(self, dynamics: Dynamics) -> Callable[[Node, Any, Any], tuple[Any, Any]]:
        """(node, du/dσ, dt/dσ) ↦ (τ, dτ/dσ), each (n, 1), N m."""

    def running(self, x: Node, du_ds: ca.SX, dt_ds: ca.SX, t: ca.SX) -> ca.SX:
        return self.jerk_s(x, du_ds[:self.chain], dt_ds)

    @abstractmethod
    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        """dq̈/dσ (n, 1) at a symbolic node with dẍ/dσ = `dxdd_ds` (m, 1) and dt/dσ = `dt_ds` (s)."""

    def objective_parameters(self, mu: ca.SX) -> list[ca.SX]:
        """μ."""
        return [mu]

    def mayer(self, tf: ca.SX, inputs: Sequence[ca.SX], parameters: Sequence[ca.SX]) -> ca.SX:
        """t_f."""
        return tf

    def lagrange(self, runs: ca.SX, weights: np.ndarray, tf: ca.SX, per_tf: float,
                 parameters: Sequence[ca.SX]) -> ca.SX:
        """μ (per_tf / t_f) Σ w (jerk_s)ᵀ Q (jerk_s): jerk = jerk_s / (dt/dσ), dt = (dt/dσ) dσ."""
        quad = ca.DM(np.kron(weights, 1.0 / self.robot.gear_ratios ** 2))
        return parameters[0] * (per_tf / tf) * ca.dot(quad, runs ** 2)

    def cost_weight(self, problem: Problem | None) -> float:
        return problem.mu

    def time_bounds(self, problem: Problem | None) -> tuple[float, float]:
        return problem.time.min, problem.time.max

    def chain_samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """x, ẋ, ẍ as the Samples' q, qd, qdd and the other controls and their rates as tau, taud."""
        m = self.chain
        q, qd, qdd, other = self.chain_parts(x)
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, other, du_dt[:, m:])


class RobotOCP(ChainOCP):
    """The paper's problem: x = [q, q̇], u = [q̈, τ_rigid/τ_max] (m = n); start and goal at rest."""

    knot_bounds = True

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        n = self.chain = robot.n
        self.states = self.controls = 2 * n
        self.parts = (("q", n), ("qd", n), ("qdd", n), ("u", n))
        self.ends = 3 * n

    @property
    def key(self) -> tuple:
        return ("robot",)

    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        return self.chain_parts(x)[:3]

    def defect(self, dynamics: Dynamics | None, x: Node) -> ca.SX:
        """residual(q, q̇, q̈, τ_max u)."""
        q, qd, qdd, u = self.chain_parts(x)
        return dynamics.residual(q, qd, qdd, ca.DM(self.robot.tau_max) * u)

    def torque_function(self, dynamics: Dynamics) -> Callable[[Node, Any, Any], tuple[Any, Any]]:
        """τ = τ_max ∘ u + friction(q̇), dτ/dσ = τ_max du/dσ + friction'(q̇) (dt/dσ) q̈."""
        n, tau_max = self.robot.n, ca.DM(self.robot.tau_max)
        v, a = ca.SX.sym("qd", n), ca.SX.sym("qdd", n)  # friction'(q̇) a by AD of the law
        friction = ca.Function("friction", [v], [dynamics.friction(v)])
        friction_rate = ca.Function("friction_rate", [v, a], [ca.jtimes(dynamics.friction(v), v, a)])

        def torque(x: Node, du_ds: Any, dt_ds: Any) -> tuple[Any, Any]:
            _, qd, qdd, u = self.chain_parts(x)
            return tau_max * u + friction(qd), tau_max * du_ds[n:] + friction_rate(qd, dt_ds * qdd)

        return torque

    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        return dxdd_ds

    def columns(self, chain: Samples) -> np.ndarray:
        """u = rnea(q, q̇, q̈) / τ_max, the rigid-body torque of the sampled motion."""
        rigid = rigid_torque(self.robot, chain.q, chain.qd, chain.qdd)
        return np.hstack([chain.q, chain.qd, chain.qdd, rigid / self.robot.tau_max])

    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """τ = τ_max u + friction(q̇), τ̇ = τ_max u̇ + friction'(q̇) q̈: the torque the plan commands; verify
        compares it with rnea(q, q̇, q̈) + friction(q̇)."""
        robot, n = self.robot, self.robot.n
        q, qd, qdd, u = self.chain_parts(x)
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, robot.tau_max * u + robot.friction(qd),
                       robot.tau_max * du_dt[:, n:] + robot.friction_slope(qd) * qdd)

    def end_bounds(self, problem: Problem | None) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        rest = np.zeros(2 * problem.robot.n)
        start, goal = np.concatenate([problem.start, rest]), np.concatenate([problem.goal, rest])
        return (start, start), (goal, goal)

    def guess(self, problem: Problem | None) -> Trajectory:
        return straight_line(problem)


class PathTimingOCP(ChainOCP):
    """The timing of the fixed path q = p(s), s ∈ [0, 1]: x = [s, ṡ], u = s̈ (m = 1), from rest at s = 0 to rest
    at s = 1:

        q̇ = p′ṡ,   q̈ = p′s̈ + p″ṡ²,   q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³

    with ṡ ≥ 0 (the path is not run backwards). Position limits hold along the path by construction; the
    velocity limits are rows at the knots (`knot_bounds` False). No other controls: τ = rnea(q, q̇, q̈) +
    friction(q̇) and dτ/dσ = ∂τ/∂(s, ṡ, s̈) · (ṡ dt/dσ, s̈ dt/dσ, ds̈/dσ) are functions of the node, in the NLP
    and in the samples alike."""

    chain = 1
    states = 2
    controls = 1
    parts = (("s", 1), ("sd", 1), ("sdd", 1))
    ends = 3
    constraints_read_node = True  # q = p(s): not linear in s

    def __init__(self, robot: Robot, path: PathSpline) -> None:
        super().__init__(robot)
        self.path = path
        self.symbols: tuple[ca.SX, ca.SX] = ()

    @property
    def key(self) -> tuple:
        """The number of the path's polynomial pieces: the path itself enters as parameters."""
        return "path-timing", self.path.intervals

    def parameter_shapes(self) -> dict[str, tuple[int, int]]:
        """"breaks" and "coefficients" of the path (`PathSpline.parameters`)."""
        K = self.path.intervals
        return {"breaks": (K + 1, 1), "coefficients": ((DEGREE + 1) * self.robot.n, K)}

    def parameter_values(self) -> dict[str, np.ndarray]:
        return dict(zip(("breaks", "coefficients"), self.path.parameters()))

    def use_parameters(self, symbols: dict[str, ca.SX]) -> None:
        self.symbols = symbols["breaks"], symbols["coefficients"]

    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        s, sd, sdd, _ = self.chain_parts(x)
        p, dp, ddp, _ = symbolic(s, *self.symbols)
        return p, dp * sd, dp * sdd + ddp * sd ** 2

    def torque_function(self, dynamics: Dynamics) -> Callable[[Node, Any, Any], tuple[Any, Any]]:
        """τ(s, ṡ, s̈) = dynamics.inverse(q, q̇, q̈) and its derivative along (ds/dσ, dṡ/dσ, ds̈/dσ), by AD."""
        chain, change = ca.SX.sym("chain", 3), ca.SX.sym("change", 3)
        tau = dynamics.inverse(*self.robot_state(Node(chain[:2], chain[2:])))
        function = ca.Function("path_torque", [chain, change, *self.symbols], [tau, ca.jtimes(tau, chain, change)])

        def torque(x: Node, du_ds: Any, dt_ds: Any) -> tuple[Any, Any]:
            s, sd, sdd, _ = self.chain_parts(x)
            return function(ca.vertcat(s, sd, sdd), ca.vertcat(dt_ds * sd, dt_ds * sdd, du_ds[0]), *self.symbols)

        return torque

    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        """p′ ds̈/dσ + (3p″ṡs̈ + p‴ṡ³) dt/dσ."""
        s, sd, sdd, _ = self.chain_parts(x)
        _, dp, ddp, dddp = symbolic(s, *self.symbols)
        return dp * dxdd_ds + (3 * ddp * sd * sdd + dddp * sd ** 3) * dt_ds

    def columns(self, chain: Samples) -> np.ndarray:
        return np.hstack([chain.q, chain.qd, chain.qdd])

    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """q = p(s) exactly; τ = rnea + friction(q̇) and its exact rate, with q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³."""
        robot, (s, sd, sdd, _) = self.robot, self.chain_parts(x)
        p, dp, ddp, dddp = self.path.values(s[:, 0])
        q, qd, qdd = p, dp * sd, dp * sdd + ddp * sd ** 2
        qddd = dp * du_dt[:, :1] + 3 * ddp * sd * sdd + dddp * sd ** 3
        tau = rigid_torque(robot, q, qd, qdd) + robot.friction(qd)
        taud = rigid_torque_rate(robot, q, qd, qdd, qddd) + robot.friction_slope(qd) * qdd
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, tau, taud)

    def end_bounds(self, problem: Problem | None) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        start, goal = np.zeros(3), np.array([1.0, 0.0, 0.0])
        return (start, start), (goal, goal)

    def chain_bounds(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        return {"s": (np.zeros(1), np.ones(1)), "sd": (np.zeros(1), np.full(1, np.inf))}

    def guess(self, problem: Problem | None) -> Trajectory:
        """s from 0 to 1 at constant speed over t_f = time.guess (not at rest at the ends, like the paper's line)."""
        tf = problem.time.guess

        def line(t: np.ndarray) -> Samples:
            t = np.asarray(t, dtype=float)[:, None]
            zeros = np.zeros_like(t)
            return Samples(t[:, 0], t / tf, zeros + 1.0 / tf, zeros, np.zeros((len(t), 0)), np.zeros((len(t), 0)))

        return Trajectory(line(np.array([0.0, tf])), line)


def rigid_torque_rate(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, qddd: np.ndarray) -> np.ndarray:
    """d/dt rnea(q, q̇, q̈) = ∂τ/∂q q̇ + ∂τ/∂q̇ q̈ + M q⃛ (N m/s) at every row (m, n): shape (m, n)."""
    data, (m, n) = robot.model.createData(), np.shape(q)
    dtau_dq, dtau_dv, mass = np.empty((m, n, n)), np.empty((m, n, n)), np.empty((m, n, n))
    for k in range(m):  # the C++ calls only; the products below are batched
        pin.computeRNEADerivatives(robot.model, data, q[k], qd[k], qdd[k])
        dtau_dq[k], dtau_dv[k], mass[k] = data.dtau_dq, data.dtau_dv, data.M
    upper = np.triu(np.ones((n, n), dtype=bool))  # pinocchio fills M's upper triangle only
    mass = np.where(upper, mass, np.swapaxes(mass, 1, 2))
    return (np.einsum("kij,kj->ki", dtau_dq, qd) + np.einsum("kij,kj->ki", dtau_dv, qdd)
            + np.einsum("kij,kj->ki", mass, qddd))


def straight_line(problem: Problem) -> Trajectory:
    """The paper's initial guess: start to goal at constant joint speed over t_f = time.guess (infeasible at
    the ends, where it does not start and stop at rest)."""
    tf, delta = problem.time.guess, problem.goal - problem.start

    def line(t: np.ndarray) -> Samples:
        zeros = np.zeros((len(t), problem.robot.n))
        return Samples(t, problem.start + np.outer(t / tf, delta), np.tile(delta / tf, (len(t), 1)), zeros, zeros,
                       zeros)

    return Trajectory(line(np.array([0.0, tf])), line)
