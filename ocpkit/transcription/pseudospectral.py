"""Pseudospectral transcription on K equal segments, for any node family (chebyshev.py, lgl.py).

One global coordinate σ = 2t/t_f − 1 ∈ [−1, 1]. The time is split into K equal segments; segment b (b = 0..K−1,
b = 0 the *last* in time) carries a polynomial of degree N through the N + 1 points s_i of the node family
(decreasing from 1 to −1) placed at σ = c_b + s_i/K, c_b = 1 − (2b + 1)/K. So t = t_f (σ + 1)/2 and on every
segment dt/ds = h = t_f/(2K). Columns j = 0..KN of X = [q; q̇; q̈; u] run in decreasing time (column 0 at t_f,
column KN at t = 0); segment b owns columns bN..bN+N, and adjacent segments share their joint column. With the
family's differentiation matrix D and quadrature weights w, and X_b the columns of segment b:

    dynamics     D Q_b = h Q̇_b,  D Q̇_b = h Q̈_b  on every segment;  residual(q, q̇, q̈, τ_max u) = 0 at every column
    torque rate  dτ/ds = τ_max (D U_b)_i + friction'(q̇) h q̈, bounded |dτ/ds| ≤ h τ̇_max; at a joint with both
                 one-sided slopes (u has a kink there)
    jerk         q⃛ = (D Q̈_b)_i / h, per segment (it may jump at a joint)
    cost         t_f + μ Σ_b Σ_i h w_i q⃛ᵀ Q q⃛  =  t_f + μ (1/h) Σ_b Σ_i w_i (D Q̈_b)_iᵀ Q (D Q̈_b)_i

Continuity at a joint: the shared column makes q, q̇, q̈ and u continuous, and the two segments' D rows at it make
each side's polynomial derivatives match the shared q̇ and q̈, so q(t) is C². That is the physics, not a
restriction: the torque-rate limit makes τ continuous, and with q, q̇ continuous so is q̈ = M⁻¹(τ − …). Only the
jerk q⃛ and dτ/dt may jump, which is the freedom K > 1 buys (a switch of an active constraint can sit at a joint
instead of ringing through one global polynomial). K = 1 is the single-polynomial method of the paper.

Collision between knots: the interpolant is linear in the knot values, so the path constraints are also imposed
at check times (q lifted there as q_k = L(σ_k) Q to keep the Jacobian sparse): in every segment one fixed check at
the θ-midpoint (s = cos θ) of every long knot interval, plus `adaptive_checks` slots anywhere in [0, t_f] whose
interpolation rows are NLP parameters, so a refinement round can move them to where dense verification found a
violation without rebuilding the NLP.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.errors import OptionError
from ocpkit.problem import Problem
from ocpkit.robots import Robot
from ocpkit.trajectory import Samples, Trajectory
from ocpkit.transcription.assembly import Assembly, joint_samples, knot_columns, problem_shape, straight_line
from ocpkit.transcription.base import NLP, Refinement, Transcription
from ocpkit.transcription.polynomials import NodeFamily


@dataclass(frozen=True)
class Grid:
    """K equal segments of N intervals each of a node family, on σ ∈ [−1, 1] (module docstring)."""

    family: NodeFamily
    N: int
    K: int

    def to_global(self, segment: np.ndarray, s: np.ndarray) -> np.ndarray:
        """σ of local s in segment b: c_b + s/K."""
        return 1.0 - (2 * segment + 1) / self.K + s / self.K

    @property
    def knots(self) -> np.ndarray:
        """σ of the KN + 1 columns, decreasing (a joint once)."""
        s = self.family.points(self.N)
        return np.concatenate([self.to_global(0, s)] + [self.to_global(b, s[1:]) for b in range(1, self.K)])

    def in_segments(self, s: np.ndarray) -> np.ndarray:
        """σ of the local points s repeated in every segment, shape (K len(s),)."""
        return np.concatenate([self.to_global(b, np.asarray(s)) for b in range(self.K)])

    def matrices(self, sigma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(L, L'), each (len(σ), KN + 1): the piecewise interpolant at σ and its d/ds (local s of σ's segment,
        the segment before in column order where σ is a joint)."""
        sigma = np.atleast_1d(np.asarray(sigma, dtype=float))
        segment = np.clip(np.floor((1.0 - sigma) * self.K / 2).astype(int), 0, self.K - 1)
        s = self.K * (sigma - self.to_global(segment, 0.0))
        rows, columns = np.arange(len(sigma))[:, None], segment[:, None] * self.N + np.arange(self.N + 1)
        L, Ld = np.zeros((2, len(sigma), self.K * self.N + 1))
        L[rows, columns] = self.family.interpolation(self.N, s)
        Ld[rows, columns] = self.family.derivative(self.N, s)
        return L, Ld


@dataclass(frozen=True)
class PseudospectralInterpolant:
    """The piecewise barycentric interpolant of the knot values; `columns` is (4n, KN + 1) in column order."""

    tf: float
    columns: np.ndarray
    robot: Robot
    grid: Grid

    def __call__(self, t: np.ndarray) -> Samples:
        n = self.robot.n
        L, Ld = self.grid.matrices(2.0 * np.asarray(t, dtype=float) / self.tf - 1.0)
        values = L @ self.columns.T
        du_dt = Ld @ self.columns[3 * n:].T * (2.0 * self.grid.K / self.tf)
        return joint_samples(self.robot, t, *np.split(values, 4, axis=1), du_dt)


class PseudospectralNLP(NLP):
    """The NLP of one shape on `grid`, with the maps from a problem to bounds/parameters/guess and back."""

    def __init__(self, problem: Problem, dynamics_name: str, grid: Grid, margin: float, adaptive_checks: int,
                 shape_key: tuple) -> None:
        robot = problem.robot
        n, N, K = robot.n, grid.N, grid.K
        self.n, self.grid, self.robot = n, grid, robot
        D, weights = grid.family.differentiation(N), grid.family.quadrature_weights(N)
        points = grid.family.points(N)
        self.check_sigma = grid.in_segments(long_interval_midpoints(points))
        self.adaptive_default = grid.to_global(K // 2, middle_quarter_points(points, adaptive_checks))
        self.columns = K * N + 1

        X = ca.SX.sym("X", 4 * n, self.columns)  # column j = [q; qd; qdd; u] at σ_j
        Qc = ca.SX.sym("q_check", n, len(self.check_sigma) + adaptive_checks)
        tf = ca.SX.sym("tf")
        h = tf / (2 * K)  # dt/ds on every segment
        Q, Qd, Qdd, U = (X[k * n:(k + 1) * n, :] for k in range(4))
        rows = ca.SX.sym("adaptive_rows", adaptive_checks, self.columns)  # L(σ_k), one row per slot
        drows = ca.SX.sym("adaptive_drows", adaptive_checks, self.columns)  # d/ds L(σ_k)
        a = self.assembly = Assembly(problem, dynamics_name, margin, dt_ds=h)  # path constraints, rows, p

        Dc, jerk_s = ca.DM(D), []
        for b in range(K):
            own = slice(b * N, b * N + N + 1)
            dQ, dQd, dQdd, dU = (ca.mtimes(M[:, own], Dc.T) for M in (Q, Qd, Qdd, U))
            for i, j in enumerate(range(b * N, b * N + N + 1)):
                a.defect(dQ[:, i] - h * Qd[:, j])  # D X_b = h F(X_b, U_b)
                a.defect(dQd[:, i] - h * Qdd[:, j])
                values = a.point(Q[:, j], Qd[:, j], Qdd[:, j], U[:, j], dU[:, i])
                if b > 0 and i == 0:  # the joint with segment b − 1: its other one-sided torque rate
                    a.add_torque_rate(values)
                else:
                    a.dynamics_defect(Q[:, j], Qd[:, j], Qdd[:, j], U[:, j])
                    a.add_path(values, at_knot=True)
            jerk_s.append(ca.vec(dQdd))  # (D Q̈_b) column by column; jerk = jerk_s / h

        fixed_rows, fixed_drows = grid.matrices(self.check_sigma)
        L, Ld = ca.vertcat(ca.DM(fixed_rows), rows), ca.vertcat(ca.DM(fixed_drows), drows)
        for k in range(L.size1()):
            row, drow = ca.transpose(L[k, :]), ca.transpose(Ld[k, :])
            a.defect(Qc[:, k] - ca.mtimes(Q, row))
            a.add_path(a.point(Qc[:, k], ca.mtimes(Qd, row), ca.mtimes(Qdd, row), ca.mtimes(U, row),
                               ca.mtimes(U, drow)))

        quad = ca.DM(np.kron(np.tile(weights, K), problem.jerk_weights))
        objective = tf + a.mu * (2.0 * K / tf) * ca.dot(quad, ca.vertcat(*jerk_s) ** 2)
        super().__init__(**a.nlp_fields(ca.vertcat(ca.vec(X), ca.vec(Qc), tf), objective,
                                        ca.vertcat(ca.vec(rows), ca.vec(drows)), shape_key))
        self.n_checks = Qc.size2()

    # -- numbers for one problem -------------------------------------------------------------------
    def bounds(self, problem: Problem, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """The last column is t = 0 (the start), column 0 is t_f (the goal); the check-point q are free."""
        return self.assembly.bounds(problem, refinement, self.columns, start=self.columns - 1, goal=0,
                                    free=self.n * self.n_checks)

    def parameters(self, problem: Problem, refinement: Refinement = Refinement()) -> np.ndarray:
        """p for this problem; the refinement's first check fractions move the adaptive slots (the rest stay
        at their defaults); margin and limit scale as in `Assembly.parameter_values`."""
        sigma = self.adaptive_default.copy()
        chosen = 2.0 * np.clip(refinement.check_fractions[: len(sigma)], 0, 1) - 1.0
        sigma[: len(chosen)] = chosen
        rows, drows = self.grid.matrices(sigma)
        return self.assembly.parameter_values(problem, refinement,
                                              np.concatenate([rows.ravel(order="F"), drows.ravel(order="F")]))

    def initial_guess(self, problem: Problem) -> np.ndarray:
        """The straight joint-space line over t_f = time.guess, as in the paper (`assembly.straight_line`)."""
        return self.encode(straight_line(problem))

    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """Sample `trajectory` at this NLP's knots and check times (scaled to its t_f); u is the rigid-body
        torque rnea(q, qd, qdd) / tau_max of the sampled motion."""
        tf = trajectory.tf
        at = lambda sigma: trajectory.interpolant(tf * (sigma + 1.0) / 2.0)  # noqa: E731
        knots, checks = at(self.grid.knots), at(np.concatenate([self.check_sigma, self.adaptive_default]))
        return np.concatenate([knot_columns(self.robot, knots).ravel(), checks.q.ravel(), [tf]])

    def decode(self, w: np.ndarray) -> Trajectory:
        columns = np.asarray(w[: 4 * self.n * self.columns]).reshape(self.columns, 4 * self.n).T
        tf = float(w[-1])
        interpolant = PseudospectralInterpolant(tf, columns, self.robot, self.grid)
        return Trajectory(interpolant(tf * (self.grid.knots[::-1] + 1.0) / 2.0), interpolant)


def long_interval_midpoints(points: np.ndarray) -> np.ndarray:
    """Local s of the fixed checks: the θ-midpoints (s = cos θ) of the knot intervals where sin θ ≥ ½, i.e.
    about half as long (in time) as the longest one. Intervals near the ends are short (knots cluster there) and
    the robot starts and stops at rest there, so checks between them cost constraints and buy nothing."""
    theta = np.arccos(points)
    middle = (theta[:-1] + theta[1:]) / 2
    return np.cos(middle[np.sin(middle) >= 0.5 - 1e-12])


def middle_quarter_points(points: np.ndarray, count: int) -> np.ndarray:
    """Local s of `count` adaptive slots by default: quarter points (in θ) of the middle knot intervals, where
    the knots are sparsest in time."""
    theta = np.arccos(points)
    middle = np.clip((len(theta) - 1) // 2 - (count // 2 + 1) // 2 + np.arange((count + 1) // 2), 0, len(theta) - 2)
    step = theta[middle + 1] - theta[middle]
    quarters = np.concatenate([theta[middle] + 0.25 * step, theta[middle] + 0.75 * step])[:count]
    return np.sort(np.cos(quarters))


class Pseudospectral(Transcription):
    """A pseudospectral transcription of the node family `family`: `segments` = K equal segments of N = `knots`
    intervals each (KN + 1 knot columns; K = 1 is one global polynomial). `margin` (m) is added to every sphere
    clearance so the polynomial between check times stays clear; `adaptive_checks` is the number of check slots a
    refinement round may move."""

    family: NodeFamily

    def __init__(self, knots: int = 12, segments: int = 1, margin: float = 0.01, adaptive_checks: int = 4) -> None:
        if knots < 2:
            raise OptionError(f"{self.name} needs knots ≥ 2, got {knots}")
        if segments < 1:
            raise OptionError(f"{self.name} needs segments ≥ 1, got {segments}")
        self.knots, self.segments, self.margin, self.adaptive_checks = knots, segments, margin, adaptive_checks

    def shape_key(self, problem: Problem, dynamics_name: str) -> tuple:
        return (self.name, self.knots, self.segments, self.margin, self.adaptive_checks,
                *problem_shape(problem, dynamics_name))

    def build(self, problem: Problem, dynamics_name: str) -> PseudospectralNLP:
        return PseudospectralNLP(problem, dynamics_name, Grid(self.family, self.knots, self.segments), self.margin,
                                 self.adaptive_checks, self.shape_key(problem, dynamics_name))
