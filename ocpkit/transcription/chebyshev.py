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
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
import pinocchio as pin

from ocpkit.constraints import PointValues, SphereCollision, StateLimits, TorqueLimit, TorqueRateLimit
from ocpkit.constraints.collision import MAX_MARGIN, active_terms
from ocpkit.dynamics.base import make_dynamics
from ocpkit.geometry import clearances, sphere_centers
from ocpkit.problem import Problem
from ocpkit.robots import Robot
from ocpkit.trajectory import Samples, Trajectory
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
        n_intervals, n, r = self.columns.shape[1] - 1, self.robot.n, self.robot
        s = 2.0 * np.asarray(t, dtype=float) / self.tf - 1.0
        values = interpolation_matrix(n_intervals, s) @ self.columns.T
        du_dt = derivative_matrix(n_intervals, s) @ self.columns[3 * n:].T * (2.0 / self.tf)
        q, qd, qdd, u = np.split(values, 4, axis=1)
        tau = r.tau_max * u + r.friction(qd)
        taud = r.tau_max * du_dt + r.friction_slope(qd) * qdd
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, tau, taud)


class ChebyshevNLP(NLP):
    """The NLP of one shape, with the maps from a problem to bounds/parameters/guess and back."""

    def __init__(self, problem: Problem, dynamics_name: str, knots: int, margin: float,
                 adaptive_checks: int, shape_key: tuple) -> None:
        robot = problem.robot
        n, N = robot.n, knots
        self.n, self.N, self.robot = n, N, robot
        self.dynamics = make_dynamics(dynamics_name, robot)
        D, weights = differentiation_matrix(N), clenshaw_curtis_weights(N)
        self.check_s = _fixed_check_times(N)
        self.adaptive_default = _default_adaptive_times(N, adaptive_checks)

        X = ca.SX.sym("X", 4 * n, N + 1)  # column i = [q; qd; qdd; u] at knot i
        Qc = ca.SX.sym("q_check", n, len(self.check_s) + adaptive_checks)
        tf = ca.SX.sym("tf")
        Q, Qd, Qdd, U = (X[k * n:(k + 1) * n, :] for k in range(4))
        tau_max = ca.DM(robot.tau_max)
        mu, margin_symbol, limit_scale = ca.SX.sym("mu"), ca.SX.sym("margin"), ca.SX.sym("limit_scale")
        self.margin = margin
        rows = ca.SX.sym("adaptive_rows", adaptive_checks, N + 1)  # L(s_k), one row per slot
        drows = ca.SX.sym("adaptive_drows", adaptive_checks, N + 1)  # d/ds L(s_k)

        self.constraints = [StateLimits(robot, limit_scale), TorqueLimit(robot, limit_scale),
                            TorqueRateLimit(robot, limit_scale), SphereCollision(self.dynamics, problem, margin_symbol)]
        v, a = ca.SX.sym("qd", n), ca.SX.sym("qdd", n)
        friction = ca.Function("friction", [v], [self.dynamics.friction(v)])
        friction_rate = ca.Function("friction_rate", [v, a], [ca.jtimes(self.dynamics.friction(v), v, a)])

        def point(q, qd, qdd, u, du_ds) -> PointValues:
            """Values at one time; du_ds is d u / d s, so dtau/ds = tau_max du_ds + friction'(qd) (t_f/2) qdd."""
            return PointValues(q, qd, qdd, tau_max * u + friction(qd), tau_max * du_ds + friction_rate(qd, tf / 2 * qdd),
                               tf / 2)
        Dc = ca.DM(D)
        dQ, dQd, dQdd, dU = (ca.mtimes(M, Dc.T) for M in (Q, Qd, Qdd, U))
        g, lbg, ubg = [], [], []

        def add(expr, lower, upper):
            g.append(expr)
            lbg.append(np.broadcast_to(lower, (expr.numel(),)))
            ubg.append(np.broadcast_to(upper, (expr.numel(),)))

        def add_path(values: PointValues, at_knot: bool):
            for constraint in self.constraints:
                if not (at_knot and constraint.enforced_by_knot_bounds):
                    add(*constraint.evaluate(values))

        for i in range(N + 1):
            add(dQ[:, i] - tf / 2 * Qd[:, i], 0.0, 0.0)  # D X = (t_f/2) F(X, U)
            add(dQd[:, i] - tf / 2 * Qdd[:, i], 0.0, 0.0)
            add(self.dynamics.residual(Q[:, i], Qd[:, i], Qdd[:, i], tau_max * U[:, i]), 0.0, 0.0)
            add_path(point(Q[:, i], Qd[:, i], Qdd[:, i], U[:, i], dU[:, i]), True)

        check_rows = [ca.DM(interpolation_matrix(N, self.check_s)), rows]
        check_drows = [ca.DM(derivative_matrix(N, self.check_s)), drows]
        L, Ld = ca.vertcat(*check_rows), ca.vertcat(*check_drows)
        for k in range(L.size1()):
            row, drow = ca.transpose(L[k, :]), ca.transpose(Ld[k, :])
            add(Qc[:, k] - ca.mtimes(Q, row), 0.0, 0.0)
            add_path(point(Qc[:, k], ca.mtimes(Qd, row), ca.mtimes(Qdd, row), ca.mtimes(U, row),
                           ca.mtimes(U, drow)), False)

        jerk_s = ca.vec(dQdd)  # (D Qdd) column by column; jerk = (2/t_f) jerk_s
        quad = ca.DM(np.kron(weights, problem.jerk_weights))
        objective = tf + mu * (2.0 / tf) * ca.dot(quad, jerk_s**2)

        collision_params = ca.vertcat(*[c.parameters for c in self.constraints])
        super().__init__(
            x=ca.vertcat(ca.vec(X), ca.vec(Qc), tf),
            p=ca.vertcat(mu, margin_symbol, limit_scale, collision_params, ca.vec(rows), ca.vec(drows)),
            f=objective, g=ca.vertcat(*g), lbg=np.concatenate(lbg), ubg=np.concatenate(ubg), shape_key=shape_key)
        self.s_knots = lobatto_points(N)
        self.n_checks = Qc.size2()

    # -- numbers for one problem -------------------------------------------------------------------
    def bounds(self, problem: Problem, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        r, n, N = self.robot, self.n, self.N
        free, qd_max = np.full(n, np.inf), r.qd_max * refinement.limit_scale
        lower = np.tile(np.concatenate([r.q_lower, -qd_max, -free, -free])[:, None], (1, N + 1))
        upper = np.tile(np.concatenate([r.q_upper, qd_max, free, free])[:, None], (1, N + 1))
        for i, q in ((0, problem.goal), (N, problem.start)):  # rest at both ends, eq. (10)
            lower[: 3 * n, i] = upper[: 3 * n, i] = np.concatenate([q, np.zeros(2 * n)])
        checks = np.full(n * self.n_checks, np.inf)
        lbx = np.concatenate([lower.ravel(order="F"), -checks, [problem.time.min]])
        ubx = np.concatenate([upper.ravel(order="F"), checks, [problem.time.max]])
        return lbx, ubx

    def parameters(self, problem: Problem, refinement: Refinement = Refinement()) -> np.ndarray:
        """p for this problem; the refinement's first check fractions move the adaptive slots (the rest stay
        at their defaults) and its extra margin adds to the clearance margin. The margin is capped at
        MAX_MARGIN and at half the start's and goal's clearance: both are fixed, so a larger margin would
        make the NLP infeasible."""
        s = self.adaptive_default.copy()
        chosen = 2.0 * np.clip(refinement.check_fractions[: len(s)], 0, 1) - 1.0
        s[: len(chosen)] = chosen
        ends = clearances(self.robot, problem.scene, sphere_centers(self.robot, np.stack([problem.start, problem.goal])))
        margin = min(self.margin + refinement.extra_margin, MAX_MARGIN, 0.5 * ends.smallest())
        collision = [c.parameter_values(problem) for c in self.constraints]
        rows, drows = interpolation_matrix(self.N, s), derivative_matrix(self.N, s)
        return np.concatenate([[problem.mu, margin, refinement.limit_scale], *collision, rows.ravel(order="F"),
                               drows.ravel(order="F")])

    def initial_guess(self, problem: Problem) -> np.ndarray:
        """Straight joint-space line from start to goal at constant speed over t_f = time.guess (infeasible
        at the ends, as in the paper), with the rigid-body torque that holds it: rnea(q, qd, 0)."""
        tf, delta = problem.time.guess, problem.goal - problem.start

        def line(t: np.ndarray) -> Samples:
            zeros = np.zeros((len(t), self.n))
            return Samples(t, problem.start + np.outer(t / tf, delta), np.tile(delta / tf, (len(t), 1)), zeros,
                           zeros, zeros)

        return self.encode(Trajectory(line(np.array([0.0, tf])), line))

    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """Sample `trajectory` at this NLP's knots and check times (scaled to its t_f); u is the rigid-body
        torque rnea(q, qd, qdd) / tau_max of the sampled motion."""
        tf, r = trajectory.tf, self.robot
        at = lambda s: trajectory.interpolant(tf * (s + 1.0) / 2.0)  # noqa: E731
        knots, checks = at(self.s_knots), at(np.concatenate([self.check_s, self.adaptive_default]))
        data = r.model.createData()
        rigid = np.array([pin.rnea(r.model, data, q, qd, qdd).copy()
                          for q, qd, qdd in zip(knots.q, knots.qd, knots.qdd)])
        columns = np.hstack([knots.q, knots.qd, knots.qdd, rigid / r.tau_max])
        return np.concatenate([columns.ravel(), checks.q.ravel(), [tf]])

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
            raise ValueError(f"chebyshev needs knots ≥ 2, got {knots}")
        self.knots, self.margin, self.adaptive_checks = knots, margin, adaptive_checks

    def shape_key(self, problem: Problem, dynamics_name: str) -> tuple:
        return (self.name, self.knots, self.margin, self.adaptive_checks, dynamics_name, id(problem.robot),
                problem.scene.n_obstacles, *(mask.tobytes() for mask in active_terms(problem)))

    def build(self, problem: Problem, dynamics_name: str) -> ChebyshevNLP:
        return ChebyshevNLP(problem, dynamics_name, self.knots, self.margin, self.adaptive_checks,
                            self.shape_key(problem, dynamics_name))


TRANSCRIPTIONS.register(Chebyshev.name, Chebyshev)
