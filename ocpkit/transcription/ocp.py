"""The optimal control problem a transcription discretizes: everything it needs beyond its own math.

Every OCP here has the structure the transcriptions are written against (docs/architecture.md, "Two families
of OCPs"): a chain of three integrators x → ẋ → ẍ of m values each, whose input dẍ/dt the jerk cost reads,
and the algebraic u (n,), the robot's rigid-body torque scaled by τ_max, tied to the chain at every collocation
point by the dynamics residual(q, q̇, q̈, τ_max u) = 0, where (q, q̇, q̈) = `robot_state(x, ẋ, ẍ)`. An OCP gives

- `chain` (m) and `parts`: the names of x, ẋ, ẍ in w (the transcriptions name u "u");
- `robot_state` / `robot_state_values`: the robot's (q, q̇, q̈) from the chain values, on CasADi symbols / NumPy rows;
- `jerk_s`: dq̈/dσ, the robot's jerk times dt/dσ, from the chain values, dẍ/dσ and dt/dσ (σ the
  transcription's own time variable), which the cost t_f + μ ∫ q⃛ᵀ Q q⃛ dt integrates;
- `knot_bounds`: whether constraints imposed as knot bounds (`at_knots = "bounds"`) can be bounds of the
  chain (x is q) or must be rows at the knots;
- `end_values` (x, ẋ, ẍ at start and goal, both at rest), `chain_bounds` (other bounds on chain parts) and
  `guess` (a chain trajectory to start from).

Two instances: `RobotOCP` (x = q, the paper's problem: the robot quantities are the chain itself) and
`PathTimingOCP` (x = s ∈ [0, 1] along a fixed path p(s), m = 1: the timing of a path, eq. in its docstring).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, NamedTuple

import casadi as ca
import numpy as np

from ocpkit.path_spline import PathSpline
from ocpkit.problem import Problem
from ocpkit.robots import Robot, rigid_torque
from ocpkit.trajectory import Samples, Trajectory


class Node(NamedTuple):
    """[x, ẋ, ẍ, u] at one point (for the robot OCP x = q): CasADi columns (m, 1) and u (n, 1), or NumPy rows
    (points, m) and (points, n) when decoding."""

    q: Any
    qd: Any
    qdd: Any
    u: Any


class OCP(ABC):
    """What a transcription needs of the problem it discretizes (module docstring)."""

    chain: int
    parts: tuple[str, str, str]
    knot_bounds: bool

    def __init__(self, robot: Robot) -> None:
        self.robot = robot

    @property
    @abstractmethod
    def key(self) -> tuple:
        """Hashable, equal exactly when two OCPs give the same NLP for the same transcription and robot."""

    @property
    def width(self) -> int:
        """Values of one node [x, ẋ, ẍ, u]: 3m + n."""
        return 3 * self.chain + self.robot.n

    def split(self, values: Any) -> Node:
        """A node from its stacked values: a CasADi column (width,) or NumPy rows (points, width)."""
        m, n = self.chain, self.robot.n
        if isinstance(values, np.ndarray) and values.ndim == 2:
            return Node(values[:, :m], values[:, m:2 * m], values[:, 2 * m:3 * m], values[:, 3 * m:3 * m + n])
        return Node(values[:m], values[m:2 * m], values[2 * m:3 * m], values[3 * m:3 * m + n])

    @abstractmethod
    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        """The robot's (q, q̇, q̈), each (n, 1), at a symbolic node."""

    @abstractmethod
    def robot_state_values(self, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray) -> tuple[np.ndarray, ...]:
        """The robot's (q, q̇, q̈), each (points, n), from chain rows (points, m)."""

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
    def columns(self, chain: Samples) -> np.ndarray:
        """Rows [x, ẋ, ẍ, u] (points, width) of sampled chain values, u = rnea(q, q̇, q̈) / τ_max (the
        rigid-body torque of the robot motion they stand for)."""
        q, qd, qdd = self.robot_state_values(chain.q, chain.qd, chain.qdd)
        return np.hstack([chain.q, chain.qd, chain.qdd, rigid_torque(self.robot, q, qd, qdd) / self.robot.tau_max])

    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """Robot samples from interpolated node rows and du/dt: (q, q̇, q̈) = robot_state(x, ẋ, ẍ), τ = τ_max u +
        friction(q̇), τ̇ = τ_max u̇ + friction'(q̇) q̈ (the torque the plan commands; verify compares it with
        rnea(q, q̇, q̈) + friction(q̇))."""
        robot = self.robot
        q, qd, qdd = self.robot_state_values(x.q, x.qd, x.qdd)
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, robot.tau_max * x.u + robot.friction(qd),
                       robot.tau_max * du_dt + robot.friction_slope(qd) * qdd)


class RobotOCP(OCP):
    """The paper's problem: the chain is the robot's q, q̇, q̈ (m = n); start and goal at rest."""

    parts = ("q", "qd", "qdd")
    knot_bounds = True

    def __init__(self, robot: Robot) -> None:
        super().__init__(robot)
        self.chain = robot.n

    @property
    def key(self) -> tuple:
        return ("robot",)

    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        return x.q, x.qd, x.qdd

    def robot_state_values(self, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray) -> tuple[np.ndarray, ...]:
        return x, xd, xdd

    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        return dxdd_ds

    def end_values(self, problem: Problem) -> tuple[np.ndarray, np.ndarray]:
        rest = np.zeros(2 * problem.robot.n)
        return np.concatenate([problem.start, rest]), np.concatenate([problem.goal, rest])

    def guess(self, problem: Problem) -> Trajectory:
        return straight_line(problem)


class PathTimingOCP(OCP):
    """The timing of the fixed path q = p(s), s ∈ [0, 1] (m = 1), from rest at s = 0 to rest at s = 1:

        q̇ = p′ṡ,   q̈ = p′s̈ + p″ṡ²,   q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³

    with ṡ ≥ 0 (the path is not run backwards). Position limits hold along the path by construction; the
    velocity limits are rows at the knots (`knot_bounds` False)."""

    chain = 1
    parts = ("s", "sd", "sdd")
    knot_bounds = False

    def __init__(self, robot: Robot, path: PathSpline) -> None:
        super().__init__(robot)
        self.path = path

    @property
    def key(self) -> tuple:
        return "path-timing", self.path.key

    def robot_state(self, x: Node) -> tuple[ca.SX, ca.SX, ca.SX]:
        p, dp, ddp, _ = self.path.symbolic(x.q)
        return p, dp * x.qd, dp * x.qdd + ddp * x.qd ** 2

    def robot_state_values(self, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray) -> tuple[np.ndarray, ...]:
        p, dp, ddp, _ = self.path.values(x[:, 0])
        return p, dp * xd, dp * xdd + ddp * xd ** 2

    def jerk_s(self, x: Node, dxdd_ds: ca.SX, dt_ds: ca.SX) -> ca.SX:
        """p′ ds̈/dσ + (3p″ṡs̈ + p‴ṡ³) dt/dσ."""
        _, dp, ddp, dddp = self.path.symbolic(x.q)
        return dp * dxdd_ds + (3 * ddp * x.qd * x.qdd + dddp * x.qd ** 3) * dt_ds

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


def straight_line(problem: Problem) -> Trajectory:
    """The paper's initial guess: start to goal at constant joint speed over t_f = time.guess (infeasible at
    the ends, where it does not start and stop at rest)."""
    tf, delta = problem.time.guess, problem.goal - problem.start

    def line(t: np.ndarray) -> Samples:
        zeros = np.zeros((len(t), problem.robot.n))
        return Samples(t, problem.start + np.outer(t / tf, delta), np.tile(delta / tf, (len(t), 1)), zeros, zeros,
                       zeros)

    return Trajectory(line(np.array([0.0, tf])), line)
