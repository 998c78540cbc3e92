"""Local collocation on a uniform mesh: what trapezoidal and Hermite–Simpson share.

N intervals of length h = t_f/N, knots t_k = k h (k = 0..N, increasing time: knot 0 is the start), and
σ ∈ [0, 1] the fraction of an interval, so dt/dσ = h. Per knot the variables are [q, q̇, q̈, u] as in
chebyshev.py (u is the rigid-body torque / τ_max, τ = τ_max ∘ u + friction(q̇)); a method may add the same
four at every interval midpoint σ = ½. A method (trapezoidal.py, hermite_simpson.py) gives only its math:

    collocation(a, h, x_k, x_k+1, x_m)          its defects on one interval, added to the Assembly a
    interpolate(x_k, x_k+1, x_m, h, σ)          (q, q̇, q̈, u, du/dσ) at σ: one formula for the NLP (CasADi,
                                                  σ a symbol) and for `decode` (NumPy, σ an array)
    jerk_integral(x_k, x_k+1, x_m, W)           ∫₀¹ (dq̈/dσ)ᵀ W (dq̈/dσ) dσ by the method's own quadrature

and this module assembles the same NLP around it for both:

    dynamics     residual(q, q̇, q̈, τ_max u) = 0 at every collocation point (knots, and midpoints if any)
    path         every path constraint at every knot (the variable bounds carry the state limits there), and
                 at one check per interval at σ_k, an NLP parameter (default ½); q is lifted to a variable
                 there. A refinement round moves σ_k of the interval where dense verification found a
                 violation (the newest violation in an interval wins), so no rebuild.
    torque rate  u has a kink at every knot, so the rate limit is imposed with both one-sided slopes there
                 (between knots du/dσ is constant or linear, so the knots hold its extremes).
    cost         t_f + μ ∫ q⃛ᵀ Q q⃛ dt = t_f + μ (1/h) Σ_k jerk_integral_k    (q⃛ = (dq̈/dσ)/h, dt = h dσ)
"""

from __future__ import annotations

from abc import abstractmethod

from typing import Any, NamedTuple
from collections.abc import Callable

import casadi as ca
import numpy as np

from ocpkit.errors import OptionError
from ocpkit.problem import Problem
from ocpkit.robots import Robot
from ocpkit.trajectory import Samples, Trajectory
from ocpkit.transcription.assembly import Assembly, joint_samples, knot_columns, problem_shape, straight_line
from ocpkit.transcription.base import NLP, Refinement, Transcription

CHECK_RANGE = (0.1, 0.9)  # a moved check keeps this far (fraction of h) from the knots, whose rows it would repeat


class Node(NamedTuple):
    """[q, q̇, q̈, u] at one collocation point: CasADi (n, 1) columns, or NumPy (m, n) rows when decoding."""

    q: Any
    qd: Any
    qdd: Any
    u: Any


class Local(NamedTuple):
    """The interpolant at σ inside an interval, and the slope du/dσ of the scaled rigid-body torque."""

    q: Any
    qd: Any
    qdd: Any
    u: Any
    du_ds: Any


Interpolate = Callable[[Node, Node, "Node | None", Any, Any], Local]


class MeshInterpolant:
    """The method's interpolant of decoded knot (and midpoint) rows, for any t in [0, t_f]."""

    def __init__(self, tf: float, knots: np.ndarray, mids: np.ndarray | None, interpolate: Interpolate,
                 robot: Robot) -> None:
        self.tf, self.knots, self.mids, self.interpolate, self.robot = tf, knots, mids, interpolate, robot

    def __call__(self, t: np.ndarray) -> Samples:
        N = len(self.knots) - 1
        h = self.tf / N
        at = np.asarray(t, dtype=float) / h
        k = np.clip(np.floor(at).astype(int), 0, N - 1)  # interval of each t; t_f belongs to the last
        node = lambda rows: Node(*np.split(rows, 4, axis=1))  # noqa: E731
        mid = None if self.mids is None else node(self.mids[k])
        v = self.interpolate(node(self.knots[k]), node(self.knots[k + 1]), mid, h, (at - k)[:, None])
        return joint_samples(self.robot, t, v.q, v.qd, v.qdd, v.u, v.du_ds / h)


class MeshNLP(NLP):
    """The NLP of one shape for a local collocation method; subclasses give `midpoints` and the three
    static methods of the module docstring."""

    midpoints: bool = False
    check_default: float = 0.5  # σ of every interval's check before any refinement

    @staticmethod
    @abstractmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: Node | None) -> None:
        """Add the interval's defect rows to `a` (interval length h, knots x0, x1, midpoint xm)."""

    @staticmethod
    @abstractmethod
    def interpolate(x0: Node, x1: Node, xm: Node | None, h: Any, s: Any) -> Local:
        """The interval's own interpolant at σ = s ∈ [0, 1] (CasADi symbols or NumPy arrays)."""

    @staticmethod
    @abstractmethod
    def jerk_integral(x0: Node, x1: Node, xm: Node | None, weights: ca.DM) -> ca.SX:
        """∫ jerkᵀ Q jerk over the interval divided by h, by the method's quadrature (weights = diag Q)."""

    def __init__(self, problem: Problem, dynamics_name: str, knots: int, margin: float, shape_key: tuple) -> None:
        robot = problem.robot
        n, N = robot.n, knots
        self.n, self.N, self.robot = n, N, robot
        tf = ca.SX.sym("tf")
        h = tf / N
        a = self.assembly = Assembly(problem, dynamics_name, margin, dt_ds=h)
        X = ca.SX.sym("X", 4 * n, N + 1)  # column k = [q; qd; qdd; u] at knot k (t = k h)
        M = ca.SX.sym("X_mid", 4 * n, N if self.midpoints else 0)  # column k: at the midpoint of interval k
        Qc = ca.SX.sym("q_check", n, N)  # q at interval k's check
        check_at = ca.SX.sym("check_at", N)  # σ_k of interval k's check
        node = lambda C, k: Node(*(C[j * n:(j + 1) * n, k] for j in range(4)))  # noqa: E731
        x = [node(X, k) for k in range(N + 1)]
        xm = [node(M, k) if self.midpoints else None for k in range(N)]

        for k in range(N + 1):  # knots: dynamics, path constraints, torque rate with both one-sided slopes
            a.dynamics_defect(*x[k])
            leaving = [self.interpolate(x[k], x[k + 1], xm[k], h, 0.0).du_ds] if k < N else []
            entering = [self.interpolate(x[k - 1], x[k], xm[k - 1], h, 1.0).du_ds] if k > 0 else []
            slope, *other_side = leaving + entering
            a.add_path(a.point(*x[k], slope), at_knot=True)
            for slope in other_side:
                a.add_torque_rate(a.point(*x[k], slope))
        for k in range(N):  # intervals: the method's defects, midpoint dynamics, the check at σ_k
            self.collocation(a, h, x[k], x[k + 1], xm[k])
            if self.midpoints:
                a.dynamics_defect(*xm[k])
            v = self.interpolate(x[k], x[k + 1], xm[k], h, check_at[k])
            a.defect(Qc[:, k] - v.q)
            a.add_path(a.point(Qc[:, k], v.qd, v.qdd, v.u, v.du_ds))

        weights = ca.DM(problem.jerk_weights)
        jerk = sum(self.jerk_integral(x[k], x[k + 1], xm[k], weights) for k in range(N))
        super().__init__(**a.nlp_fields(ca.vertcat(ca.vec(X), ca.vec(M), ca.vec(Qc), tf), tf + a.mu / h * jerk,
                                        check_at, shape_key))

    # -- numbers for one problem -------------------------------------------------------------------
    def bounds(self, problem: Problem, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """Knot 0 is the start, knot N the goal; midpoint and check variables are free (their limits are
        path constraints at the checks: bounds as well would repeat those rows when σ_k = ½)."""
        free = self.n * self.N * (4 * self.midpoints + 1)
        return self.assembly.bounds(problem, refinement, self.N + 1, start=0, goal=self.N, free=free)

    def parameters(self, problem: Problem, refinement: Refinement = Refinement()) -> np.ndarray:
        """p for this problem; each of the refinement's check fractions (oldest first, so the newest wins)
        moves the check of its interval there."""
        check_at = np.full(self.N, self.check_default)
        for fraction in refinement.check_fractions[::-1]:
            k = min(int(np.clip(fraction, 0, 1) * self.N), self.N - 1)
            check_at[k] = np.clip(fraction * self.N - k, *CHECK_RANGE)
        return self.assembly.parameter_values(problem, refinement, check_at)

    def initial_guess(self, problem: Problem) -> np.ndarray:
        """The straight joint-space line over t_f = time.guess, as in the paper (`assembly.straight_line`)."""
        return self.encode(straight_line(problem))

    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """Sample `trajectory` at this NLP's knots, midpoints and default checks (scaled to its t_f); u is the
        rigid-body torque rnea(q, qd, qdd) / tau_max of the sampled motion."""
        tf, N = trajectory.tf, self.N
        at = lambda s: trajectory.interpolant(tf * s / N)  # noqa: E731  s in intervals
        intervals = np.arange(N)
        mids = knot_columns(self.robot, at(intervals + 0.5)).ravel() if self.midpoints else []
        return np.concatenate([knot_columns(self.robot, at(np.arange(N + 1.0))).ravel(), mids,
                               at(intervals + self.check_default).q.ravel(), [tf]])

    def decode(self, w: np.ndarray) -> Trajectory:
        width, N = 4 * self.n, self.N
        knots = np.asarray(w[: width * (N + 1)]).reshape(N + 1, width)
        mids = np.asarray(w[width * (N + 1): width * (2 * N + 1)]).reshape(N, width) if self.midpoints else None
        tf = float(w[-1])
        interpolant = MeshInterpolant(tf, knots, mids, self.interpolate, self.robot)
        return Trajectory(interpolant(tf * np.arange(N + 1) / N), interpolant)


class MeshTranscription(Transcription):
    """A local collocation method with N = `knots` intervals; `margin` (m) is added to every sphere clearance
    so the interpolant between check times stays clear. Subclasses name their `nlp` class."""

    nlp: type[MeshNLP]

    def __init__(self, knots: int = 20, margin: float = 0.01) -> None:
        if knots < 2:
            raise OptionError(f"{self.name} needs knots ≥ 2, got {knots}")
        self.knots, self.margin = knots, margin

    def shape_key(self, problem: Problem, dynamics_name: str) -> tuple:
        return (self.name, self.knots, self.margin, *problem_shape(problem, dynamics_name))

    def build(self, problem: Problem, dynamics_name: str) -> MeshNLP:
        return self.nlp(problem, dynamics_name, self.knots, self.margin, self.shape_key(problem, dynamics_name))
