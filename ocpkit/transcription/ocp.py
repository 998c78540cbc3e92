"""The optimal control problem a transcription discretizes: everything it needs beyond its own math.

Every OCP here has the structure the transcriptions are written against (docs/architecture.md, "Two families
of OCPs"): a chain of three integrators x → ẋ → ẍ of m values each, whose input dẍ/dt the jerk cost reads,
and algebraic variables u (`algebraic` values, possibly none). An OCP gives

- `chain` (m) and `parts`: the names of x, ẋ, ẍ in w (the transcriptions name u "u");
- `defect`: its rows at a collocation point (the dynamics, for the robot OCP);
- `torque`: the joint torque τ and dτ/dσ at a point, from the node, its slopes du/dσ and dẍ/dσ and dt/dσ;
- `robot_state`: the robot's (q, q̇, q̈) from the chain values;
- `jerk_s`: dq̈/dσ, the robot's jerk times dt/dσ, from the chain values, dẍ/dσ and dt/dσ (σ the
  transcription's own time variable), which the cost t_f + μ ∫ q⃛ᵀ Q q⃛ dt integrates;
- `knot_bounds`: whether constraints imposed as knot bounds (`at_knots = "bounds"`) can be bounds of the
  chain (x is q) or must be rows at the knots;
- `end_values` (x, ẋ, ẍ at start and goal, both at rest), `chain_bounds` (other bounds on chain parts) and
  `guess` (a chain trajectory to start from);
- its own NLP parameters (`parameter_shapes`, `parameter_values`; the assembly hands the OCP their symbols by
  `use_parameters` before the build), so OCPs of one `key` share one NLP.

Two instances: `RobotOCP` (x = q, the paper's problem; u = rnea(q, q̇, q̈)/τ_max tied to the chain by the
dynamics residual at each collocation point) and `PathTimingOCP` (x = s ∈ [0, 1] along a fixed path p(s), m = 1,
no u: the torque is a function of the chain, so it holds exactly between knots too).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
import pinocchio as pin

from ocpkit.dynamics import Dynamics
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.path_spline import DEGREE, PathSpline, symbolic
from ocpkit.problem import Problem
from ocpkit.robots import Robot, rigid_torque


class Node(NamedTuple):
    """[x, ẋ, ẍ, u] at one point (for the robot OCP x = q): CasADi columns (m, 1) and u (algebraic, 1), or NumPy
    rows (points, m) and (points, algebraic) when decoding."""

    q: Any
    qd: Any
    qdd: Any
    u: Any


class Slope(NamedTuple):
    """The slopes du/dσ (algebraic, 1) and dẍ/dσ (m, 1) of a transcription's interpolant at one point (one-sided
    at a knot where they jump)."""

    u: Any
    xdd: Any


Torque = Callable[[Node, Slope, Any], tuple[Any, Any]]
"""(node, slopes, dt/dσ) ↦ (τ, dτ/dσ), each (n, 1), N m."""


class OCP(ABC):
    """What a transcription needs of the problem it discretizes (module docstring)."""

    chain: int
    algebraic: int
    parts: tuple[str, str, str]
    knot_bounds: bool

    def __init__(self, robot: Robot) -> None:
        self.robot = robot

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
        """Values of one node [x, ẋ, ẍ, u]: 3m + algebraic."""
        return 3 * self.chain + self.algebraic

    def split(self, values: Any) -> Node:
        """A node from its stacked values: a CasADi column (width,) or NumPy rows (points, width)."""
        m, n = self.chain, self.algebraic
        if isinstance(values, np.ndarray) and values.ndim == 2:
            return Node(values[:, :m], values[:, m:2 * m], values[:, 2 * m:3 * m], values[:, 3 * m:3 * m + n])
        return Node(values[:m], values[m:2 * m], values[2 * m:3 * m], values[3 * m:3 * m + n])

    @abstractmethod
    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        """The robot's (q, q̇, q̈), each (n, 1), at a symbolic node."""


    @abstractmethod
    def defect(self, dynamics: Dynamics, x: Node) -> ca.SX:
        """The rows (k, 1) that must be 0 at a collocation point."""

    @abstractmethod
    def torque(self, dynamics: Dynamics) -> Torque:
        """The joint torque and its rate at a point (`Torque`), on `dynamics`' expressions."""

    @abstractmethod
    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        """dq̈/dσ (n, 1) at a symbolic node with dẍ/dσ = `dxdd_ds` (m, 1) and dt/dσ = `dt_ds` (s)."""

    @abstractmethod
    def end_values(self, problem: Problem) -> tuple[np.ndarray, np.ndarray]:
        """[x, ẋ, ẍ] (3m,) at the start and at the goal."""

    def chain_bounds(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Part name → (lower, upper) (m,) of every knot's chain part, besides the constraints'; none by default."""
        return {}

    @abstractmethod
    def guess(self, problem: Problem) -> Trajectory:
        """A chain trajectory (x, ẋ, ẍ in the Samples' q, qd, qdd) to start from when no other is given."""

    # -- numbers ---------------------------------------------------------------------------------------
    @abstractmethod
    def columns(self, chain: Samples) -> np.ndarray:
        """Rows [x, ẋ, ẍ, u] (points, width) of sampled chain values (x, ẋ, ẍ in the Samples' q, qd, qdd)."""

    def chain_samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """The chain's own samples at times t (points,): x, ẋ, ẍ as the Samples' q, qd, qdd and u, du/dt as tau,
        taud, as `Discretization.encode` and `write_checks` read them."""
        return Samples(np.asarray(t, dtype=float), x.q, x.qd, x.qdd, x.u, du_dt)

    @abstractmethod
    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray, dxdd_dt: np.ndarray) -> Samples:
        """Robot samples at times t (points,) from interpolated node rows and the interpolant's du/dt
        (points, algebraic) and dẍ/dt (points, m)."""


class RobotOCP(OCP):
    """The paper's problem: the chain is the robot's q, q̇, q̈ (m = n); start and goal at rest."""

    parts = ("q", "qd", "qdd")
    knot_bounds = True

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        self.chain = self.algebraic = robot.n

    @property
    def key(self) -> tuple:
        return ("robot",)

    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        return x.q, x.qd, x.qdd


    def defect(self, dynamics: Dynamics, x: Node) -> ca.SX:
        """residual(q, q̇, q̈, τ_max u)."""
        return dynamics.residual(x.q, x.qd, x.qdd, ca.DM(self.robot.tau_max) * x.u)

    def torque(self, dynamics: Dynamics) -> Torque:
        """τ = τ_max ∘ u + friction(q̇), dτ/dσ = τ_max du/dσ + friction'(q̇) (dt/dσ) q̈."""
        n, tau_max = self.robot.n, ca.DM(self.robot.tau_max)
        v, a = ca.SX.sym("qd", n), ca.SX.sym("qdd", n)  # friction'(q̇) a by AD of the law
        friction = ca.Function("friction", [v], [dynamics.friction(v)])
        friction_rate = ca.Function("friction_rate", [v, a], [ca.jtimes(dynamics.friction(v), v, a)])
        return lambda x, slope, dt_ds: (tau_max * x.u + friction(x.qd),
                                        tau_max * slope.u + friction_rate(x.qd, dt_ds * x.qdd))

    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        return dxdd_ds

    def columns(self, chain: Samples) -> np.ndarray:
        """u = rnea(q, q̇, q̈) / τ_max, the rigid-body torque of the sampled motion."""
        rigid = rigid_torque(self.robot, chain.q, chain.qd, chain.qdd)
        return np.hstack([chain.q, chain.qd, chain.qdd, rigid / self.robot.tau_max])

    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray, dxdd_dt: np.ndarray) -> Samples:
        """τ = τ_max u + friction(q̇), τ̇ = τ_max u̇ + friction'(q̇) q̈: the torque the plan commands; verify
        compares it with rnea(q, q̇, q̈) + friction(q̇)."""
        robot = self.robot
        return Samples(np.asarray(t, dtype=float), x.q, x.qd, x.qdd, robot.tau_max * x.u + robot.friction(x.qd),
                       robot.tau_max * du_dt + robot.friction_slope(x.qd) * x.qdd)

    def end_values(self, problem: Problem) -> tuple[np.ndarray, np.ndarray]:
        rest = np.zeros(2 * problem.robot.n)
        return np.concatenate([problem.start, rest]), np.concatenate([problem.goal, rest])

    def guess(self, problem: Problem) -> Trajectory:
        return straight_line(problem)


class PathTimingOCP(OCP):
    """The timing of the fixed path q = p(s), s ∈ [0, 1] (m = 1), from rest at s = 0 to rest at s = 1:

        q̇ = p′ṡ,   q̈ = p′s̈ + p″ṡ²,   q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³

    with ṡ ≥ 0 (the path is not run backwards). Position limits hold along the path by construction; the
    velocity limits are rows at the knots (`knot_bounds` False). No algebraic variables: τ = rnea(q, q̇, q̈) +
    friction(q̇) and dτ/dσ = ∂τ/∂(s, ṡ, s̈) · (ṡ dt/dσ, s̈ dt/dσ, ds̈/dσ) are functions of the chain, in the NLP
    and in the samples alike."""

    chain = 1
    algebraic = 0
    parts = ("s", "sd", "sdd")
    knot_bounds = False

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
        p, dp, ddp, _ = symbolic(x.q, *self.symbols)
        return p, dp * x.qd, dp * x.qdd + ddp * x.qd ** 2


    def defect(self, dynamics: Dynamics, x: Node) -> ca.SX:
        """None: the torque is not a variable."""
        return ca.SX(0, 1)

    def torque(self, dynamics: Dynamics) -> Torque:
        """τ(s, ṡ, s̈) = dynamics.inverse(q, q̇, q̈) and its derivative along (ds/dσ, dṡ/dσ, ds̈/dσ), by AD."""
        chain, change = ca.SX.sym("chain", 3), ca.SX.sym("change", 3)
        tau = dynamics.inverse(*self.robot_state(Node(chain[0], chain[1], chain[2], None)))
        function = ca.Function("path_torque", [chain, change, *self.symbols], [tau, ca.jtimes(tau, chain, change)])
        return lambda x, slope, dt_ds: function(ca.vertcat(x.q, x.qd, x.qdd),
                                                ca.vertcat(dt_ds * x.qd, dt_ds * x.qdd, slope.xdd), *self.symbols)

    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        """p′ ds̈/dσ + (3p″ṡs̈ + p‴ṡ³) dt/dσ."""
        _, dp, ddp, dddp = symbolic(x.q, *self.symbols)
        return dp * dxdd_ds + (3 * ddp * x.qd * x.qdd + dddp * x.qd ** 3) * dt_ds

    def columns(self, chain: Samples) -> np.ndarray:
        return np.hstack([chain.q, chain.qd, chain.qdd])

    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray, dxdd_dt: np.ndarray) -> Samples:
        """q = p(s) exactly; τ = rnea + friction(q̇) and its exact rate, with q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³."""
        robot, (s, sd, sdd) = self.robot, (x.q, x.qd, x.qdd)
        p, dp, ddp, dddp = self.path.values(s[:, 0])
        q, qd, qdd = p, dp * sd, dp * sdd + ddp * sd ** 2
        qddd = dp * dxdd_dt + 3 * ddp * sd * sdd + dddp * sd ** 3
        tau = rigid_torque(robot, q, qd, qdd) + robot.friction(qd)
        taud = rigid_torque_rate(robot, q, qd, qdd, qddd) + robot.friction_slope(qd) * qdd
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, tau, taud)

    def end_values(self, problem: Problem) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros(3), np.array([1.0, 0.0, 0.0])

    def chain_bounds(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        return {"s": (np.zeros(1), np.ones(1)), "sd": (np.zeros(1), np.full(1, np.inf))}

    def guess(self, problem: Problem) -> Trajectory:
        """s from 0 to 1 at constant speed over t_f = time.guess (not at rest at the ends, like the paper's line)."""
        tf = problem.time.guess

        def line(t: np.ndarray) -> Samples:
            t = np.asarray(t, dtype=float)[:, None]
            zeros = np.zeros_like(t)
            return Samples(t[:, 0], t / tf, zeros + 1.0 / tf, zeros, zeros, zeros)

        return Trajectory(line(np.array([0.0, tf])), line)


def rigid_torque_rate(robot: Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, qddd: np.ndarray) -> np.ndarray:
    """d/dt rnea(q, q̇, q̈) = ∂τ/∂q q̇ + ∂τ/∂q̇ q̈ + M q⃛ (N m/s) at every row (m, n): shape (m, n)."""
    data, rate = robot.model.createData(), np.empty(np.shape(q))
    for k in range(len(rate)):
        pin.computeRNEADerivatives(robot.model, data, q[k], qd[k], qdd[k])
        mass = np.triu(data.M) + np.triu(data.M, 1).T  # pinocchio fills the upper triangle
        rate[k] = data.dtau_dq @ qd[k] + data.dtau_dv @ qdd[k] + mass @ qddd[k]
    return rate


def straight_line(problem: Problem) -> Trajectory:
    """The paper's initial guess: start to goal at constant joint speed over t_f = time.guess (infeasible at
    the ends, where it does not start and stop at rest)."""
    tf, delta = problem.time.guess, problem.goal - problem.start

    def line(t: np.ndarray) -> Samples:
        zeros = np.zeros((len(t), problem.robot.n))
        return Samples(t, problem.start + np.outer(t / tf, delta), np.tile(delta / tf, (len(t), 1)), zeros, zeros,
                       zeros)

    return Trajectory(line(np.array([0.0, tf])), line)
