"""Chebyshev pseudospectral transcription, exactly the paper's section III.

Knots T_i = (t_f/2)(cos(iπ/N) + 1), i = 0..N (knot 0 is t = t_f, knot N is t = 0). Per knot the
decision variables are x_i = [q_i, qd_i, qdd_i, u_i]. The control u is the rigid-body part of the joint
torque, scaled: tau = tau_max ∘ u + friction(qd). At the knots this is exactly the paper's control; between
knots the torque interpolant is the polynomial u plus the friction law on the velocity polynomial, which
follows the steep Coulomb term (tanh) where a joint reverses; a polynomial through the knot torques cannot
(we measured 2 % of the torque range of dynamic inconsistency from that alone). With the differentiation
matrix D (on s ∈ [-1, 1]) and Clenshaw–Curtis weights w:

    dynamics     D X = (t_f/2) F(X, U):  D Q = (t_f/2) Qd,  D Qd = (t_f/2) Qdd,  residual(q_i, qd_i, qdd_i, tau_max u_i) = 0
    torque rate  tau'(t) = (2/t_f) (tau_max D U + friction'(qd) (t_f/2) Qdd), bounded as |dtau/ds| ≤ (t_f/2) taud_max
    jerk         q'''(T_i) = (2/t_f) (D Qdd)_i
    cost         t_f + μ Σ_i (t_f/2) w_i q'''_iᵀ Q q'''_i  =  t_f + μ (2/t_f) Σ_i w_i (D Qdd)_iᵀ Q (D Qdd)_i

Because D is exact for degree-N polynomials, D Q = (t_f/2) Qd at all N+1 knots makes the velocity
polynomial the exact derivative of the position polynomial (likewise for acceleration).

Collision between knots: the barycentric interpolant is linear in the knot values, so the path
constraints are also imposed at extra check times s_k (q lifted there as q_k = L(s_k) Q to keep the
Jacobian sparse): one fixed check at the θ-midpoint of every long knot interval, plus `adaptive_checks`
slots whose interpolation rows are NLP parameters, so a refinement round can move them to where dense
verification found a violation without rebuilding the NLP.

What is not Chebyshev-specific (the path constraints at a point, the parameter vector, the bounds, the
straight-line guess) is shared by all transcriptions in assembly.py.
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
from ocpkit.transcription.base import NLP, TRANSCRIPTIONS, Refinement, Transcription
from ocpkit.transcription.polynomials import (
    clenshaw_curtis_weights, derivative_matrix, differentiation_matrix, interpolation_matrix, lobatto_points)


@dataclass(frozen=True)
class ChebyshevInterpolant:
    """Barycentric interpolant of the knot values; `columns` is (4n, N+1) in knot order (knot 0 at t_f)."""

    tf: float
    columns: np.ndarray
    robot: Robot

    def __call__(self, t: np.ndarray) -> Samples:
        n_intervals, n = self.columns.shape[1] - 1, self.robot.n
        s = 2.0 * np.asarray(t, dtype=float) / self.tf - 1.0
        values = interpolation_matrix(n_intervals, s) @ self.columns.T
        du_dt = derivative_matrix(n_intervals, s) @ self.columns[3 * n:].T * (2.0 / self.tf)
        return joint_samples(self.robot, t, *np.split(values, 4, axis=1), du_dt)


class ChebyshevNLP(NLP):
    """The NLP of one shape, with the maps from a problem to bounds/parameters/guess and back."""

    def __init__(self, problem: Problem, dynamics_name: str, knots: int, margin: float,
                 adaptive_checks: int, shape_key: tuple) -> None:
        robot = problem.robot
        n, N = robot.n, knots
        self.n, self.N, self.robot = n, N, robot
        D, weights = differentiation_matrix(N), clenshaw_curtis_weights(N)
        self.check_s = _fixed_check_times(N)
        self.adaptive_default = _default_adaptive_times(N, adaptive_checks)

        X = ca.SX.sym("X", 4 * n, N + 1)  # column i = [q; qd; qdd; u] at knot i
        Qc = ca.SX.sym("q_check", n, len(self.check_s) + adaptive_checks)
        tf = ca.SX.sym("tf")
        Q, Qd, Qdd, U = (X[k * n:(k + 1) * n, :] for k in range(4))
        rows = ca.SX.sym("adaptive_rows", adaptive_checks, N + 1)  # L(s_k), one row per slot
        drows = ca.SX.sym("adaptive_drows", adaptive_checks, N + 1)  # d/ds L(s_k)
        a = self.assembly = Assembly(problem, dynamics_name, margin, dt_ds=tf / 2)  # path constraints, rows, p

        Dc = ca.DM(D)
        dQ, dQd, dQdd, dU = (ca.mtimes(M, Dc.T) for M in (Q, Qd, Qdd, U))
        for i in range(N + 1):
            a.defect(dQ[:, i] - tf / 2 * Qd[:, i])  # D X = (t_f/2) F(X, U)
            a.defect(dQd[:, i] - tf / 2 * Qdd[:, i])
            a.dynamics_defect(Q[:, i], Qd[:, i], Qdd[:, i], U[:, i])
            a.add_path(a.point(Q[:, i], Qd[:, i], Qdd[:, i], U[:, i], dU[:, i]), at_knot=True)

        check_rows = [ca.DM(interpolation_matrix(N, self.check_s)), rows]
        check_drows = [ca.DM(derivative_matrix(N, self.check_s)), drows]
        L, Ld = ca.vertcat(*check_rows), ca.vertcat(*check_drows)
        for k in range(L.size1()):
            row, drow = ca.transpose(L[k, :]), ca.transpose(Ld[k, :])
            a.defect(Qc[:, k] - ca.mtimes(Q, row))
            a.add_path(a.point(Qc[:, k], ca.mtimes(Qd, row), ca.mtimes(Qdd, row), ca.mtimes(U, row),
                               ca.mtimes(U, drow)))

        jerk_s = ca.vec(dQdd)  # (D Qdd) column by column; jerk = (2/t_f) jerk_s
        quad = ca.DM(np.kron(weights, problem.jerk_weights))
        objective = tf + a.mu * (2.0 / tf) * ca.dot(quad, jerk_s**2)
        super().__init__(**a.nlp_fields(ca.vertcat(ca.vec(X), ca.vec(Qc), tf), objective,
                                        ca.vertcat(ca.vec(rows), ca.vec(drows)), shape_key))
        self.s_knots = lobatto_points(N)
        self.n_checks = Qc.size2()

    # -- numbers for one problem -------------------------------------------------------------------
    def bounds(self, problem: Problem, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """Knot N is t = 0 (the start), knot 0 is t_f (the goal); the check-point q are free."""
        return self.assembly.bounds(problem, refinement, self.N + 1, start=self.N, goal=0, free=self.n * self.n_checks)

    def parameters(self, problem: Problem, refinement: Refinement = Refinement()) -> np.ndarray:
        """p for this problem; the refinement's first check fractions move the adaptive slots (the rest stay
        at their defaults); margin and limit scale as in `Assembly.parameter_values`."""
        s = self.adaptive_default.copy()
        chosen = 2.0 * np.clip(refinement.check_fractions[: len(s)], 0, 1) - 1.0
        s[: len(chosen)] = chosen
        rows, drows = interpolation_matrix(self.N, s), derivative_matrix(self.N, s)
        return self.assembly.parameter_values(problem, refinement,
                                              np.concatenate([rows.ravel(order="F"), drows.ravel(order="F")]))

    def initial_guess(self, problem: Problem) -> np.ndarray:
        """The straight joint-space line over t_f = time.guess, as in the paper (`assembly.straight_line`)."""
        return self.encode(straight_line(problem))

    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """Sample `trajectory` at this NLP's knots and check times (scaled to its t_f); u is the rigid-body
        torque rnea(q, qd, qdd) / tau_max of the sampled motion."""
        tf = trajectory.tf
        at = lambda s: trajectory.interpolant(tf * (s + 1.0) / 2.0)  # noqa: E731
        knots, checks = at(self.s_knots), at(np.concatenate([self.check_s, self.adaptive_default]))
        return np.concatenate([knot_columns(self.robot, knots).ravel(), checks.q.ravel(), [tf]])

    def decode(self, w: np.ndarray) -> Trajectory:
        n, N = self.n, self.N
        columns = np.asarray(w[: 4 * n * (N + 1)]).reshape(N + 1, 4 * n).T
        tf = float(w[-1])
        interpolant = ChebyshevInterpolant(tf, columns, self.robot)
        return Trajectory(interpolant(tf * (self.s_knots[::-1] + 1.0) / 2.0), interpolant)


def _fixed_check_times(knots: int) -> np.ndarray:
    """s of the fixed checks: the θ-midpoints of the knot intervals at least half as long (in time) as the
    longest one. Intervals near the ends are short (knots cluster there) and the robot starts and stops
    at rest there, so checks between them cost constraints and buy nothing."""
    theta = np.pi * (np.arange(knots) + 0.5) / knots
    return np.cos(theta[np.sin(theta) >= 0.5 - 1e-12])


def _default_adaptive_times(knots: int, count: int) -> np.ndarray:
    """Default s of the adaptive slots: quarter points (in θ) of the middle knot intervals, where the
    knots are sparsest in time."""
    middle = knots // 2 - (count // 2 + 1) // 2 + np.arange((count + 1) // 2)
    theta = np.concatenate([(middle + 0.25), (middle + 0.75)])[:count] * np.pi / knots
    return np.sort(np.cos(np.clip(theta, 0, np.pi)))


class Chebyshev(Transcription):
    """Chebyshev pseudospectral transcription with N = `knots` intervals (N + 1 Chebyshev–Lobatto points).

    `margin` (m) is added to every sphere clearance so the polynomial between check times stays clear;
    `adaptive_checks` is the number of check slots a refinement round may move."""

    name = "chebyshev"

    def __init__(self, knots: int = 12, margin: float = 0.01, adaptive_checks: int = 4) -> None:
        if knots < 2:
            raise OptionError(f"chebyshev needs knots ≥ 2, got {knots}")
        self.knots, self.margin, self.adaptive_checks = knots, margin, adaptive_checks

    def shape_key(self, problem: Problem, dynamics_name: str) -> tuple:
        return (self.name, self.knots, self.margin, self.adaptive_checks, *problem_shape(problem, dynamics_name))

    def build(self, problem: Problem, dynamics_name: str) -> ChebyshevNLP:
        return ChebyshevNLP(problem, dynamics_name, self.knots, self.margin, self.adaptive_checks,
                            self.shape_key(problem, dynamics_name))


TRANSCRIPTIONS.register(Chebyshev.name, Chebyshev)
