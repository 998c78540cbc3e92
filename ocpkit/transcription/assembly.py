"""What every transcription's NLP shares, so each transcription module holds only its own math.

A transcription supplies its collocation defects, its interpolant (and through it the values at check times
between knots), its torque rate dτ/ds and its jerk quadrature. `Assembly` does the rest the same way for all:

- the path constraints (`StateLimits`, `TorqueLimit`, `TorqueRateLimit`, `SphereCollision`) at one point,
  fed by `point(q, q̇, q̈, u, du/ds)` with the joint torque τ = τ_max ∘ u + friction(q̇) and its rate
  dτ/ds = τ_max du/ds + friction'(q̇) (dt/ds) q̈, where dt/ds is the transcription's (t_f/2 on Chebyshev's
  s ∈ [-1, 1], h = t_f/N on a mesh interval's σ ∈ [0, 1]), so rate bounds read |dτ/ds| ≤ (dt/ds) τ̇_max and
  t_f never divides;
- the dynamic defect residual(q, q̇, q̈, τ_max u) at a collocation point;
- the rows g with their bounds lbg ≤ g ≤ ubg, in the order the transcription adds them;
- the parameter vector p = [μ, margin, limit_scale, collision parameters, the transcription's own], and its
  numbers for a problem: the clearance margin (grown by a refinement) is capped at MAX_MARGIN and at half the
  start's and goal's clearance, both fixed, so a larger margin would make the NLP infeasible;
- the variable bounds x = [knot columns [q; q̇; q̈; u], free variables, t_f]: position and velocity limits
  at every knot (velocity scaled by the refinement's limit_scale), start and goal with rest (q̇ = q̈ = 0,
  eq. (10)) at the two end knots;
- the paper's initial guess (the straight joint-space line at t_f = time.guess) and the knot columns of any
  trajectory, u being its rigid-body torque rnea(q, q̇, q̈) / τ_max (see chebyshev.py for why u is that).
"""

from __future__ import annotations

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
from ocpkit.transcription.base import Refinement


class Assembly:
    """The shared symbols and constraint rows of one NLP under construction (see the module docstring).

    `margin` (m) is the default clearance margin; `dt_ds` the transcription's dt/ds (a CasADi expression)."""

    def __init__(self, problem: Problem, dynamics_name: str, margin: float, dt_ds: ca.SX) -> None:
        robot = problem.robot
        self.robot, self.margin, self.dt_ds = robot, margin, dt_ds
        self.dynamics = make_dynamics(dynamics_name, robot)
        self.tau_max = ca.DM(robot.tau_max)
        self.mu, self.margin_symbol, self.limit_scale = ca.SX.sym("mu"), ca.SX.sym("margin"), ca.SX.sym("limit_scale")
        self.torque_rate = TorqueRateLimit(robot, self.limit_scale)
        self.constraints = [StateLimits(robot, self.limit_scale), TorqueLimit(robot, self.limit_scale),
                            self.torque_rate, SphereCollision(self.dynamics, problem, self.margin_symbol)]
        v, a = ca.SX.sym("qd", robot.n), ca.SX.sym("qdd", robot.n)
        self._friction = ca.Function("friction", [v], [self.dynamics.friction(v)])
        self._friction_rate = ca.Function("friction_rate", [v, a], [ca.jtimes(self.dynamics.friction(v), v, a)])
        self.g: list[ca.SX] = []
        self.lbg: list[np.ndarray] = []
        self.ubg: list[np.ndarray] = []

    # -- rows ----------------------------------------------------------------------------------------
    def add(self, expr: ca.SX, lower, upper) -> None:
        """The rows lower ≤ expr ≤ upper (bounds broadcast to expr's length)."""
        self.g.append(expr)
        self.lbg.append(np.broadcast_to(lower, (expr.numel(),)))
        self.ubg.append(np.broadcast_to(upper, (expr.numel(),)))

    def defect(self, expr: ca.SX) -> None:
        """The rows expr = 0."""
        self.add(expr, 0.0, 0.0)

    def dynamics_defect(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, u: ca.SX) -> None:
        """The dynamics at one collocation point: residual(q, q̇, q̈, τ_max u) = 0."""
        self.defect(self.dynamics.residual(q, qd, qdd, self.tau_max * u))

    def point(self, q: ca.SX, qd: ca.SX, qdd: ca.SX, u: ca.SX, du_ds: ca.SX) -> PointValues:
        """Values at one time; du_ds is du/ds, so dτ/ds = τ_max du_ds + friction'(q̇) (dt/ds) q̈."""
        return PointValues(q, qd, qdd, self.tau_max * u + self._friction(qd),
                           self.tau_max * du_ds + self._friction_rate(qd, self.dt_ds * qdd), self.dt_ds)

    def add_path(self, values: PointValues, at_knot: bool = False) -> None:
        """Every path constraint at one point; at a knot, less those the knot's variable bounds imply."""
        for constraint in self.constraints:
            if not (at_knot and constraint.enforced_by_knot_bounds):
                self.add(*constraint.evaluate(values))

    def add_torque_rate(self, values: PointValues) -> None:
        """The torque-rate limit alone: for a second, one-sided dτ/ds where τ has a kink (a knot)."""
        self.add(*self.torque_rate.evaluate(values))

    def nlp_fields(self, x: ca.SX, f: ca.SX, own_parameters: ca.SX, shape_key: tuple) -> dict:
        """The NLP's fields: x, f, p = [μ, margin, limit_scale, collision parameters, own_parameters], g."""
        collision = ca.vertcat(*[c.parameters for c in self.constraints])
        fields = dict(x=x, p=ca.vertcat(self.mu, self.margin_symbol, self.limit_scale, collision, own_parameters),
                      f=f, g=ca.vertcat(*self.g), lbg=np.concatenate(self.lbg), ubg=np.concatenate(self.ubg),
                      shape_key=shape_key)
        return self.dynamics.lift(fields)

    # -- numbers for one problem ---------------------------------------------------------------------
    def parameter_values(self, problem: Problem, refinement: Refinement, own: np.ndarray) -> np.ndarray:
        """p for this problem (the order of `nlp_fields`), with the margin grown and capped (module docstring)."""
        centers = sphere_centers(self.robot, np.stack([problem.start, problem.goal]))
        ends = clearances(self.robot, problem.scene, centers)
        margin = min(self.margin + refinement.extra_margin, MAX_MARGIN, 0.5 * ends.smallest())
        collision = [c.parameter_values(problem) for c in self.constraints]
        return np.concatenate([[problem.mu, margin, refinement.limit_scale], *collision, own])

    def bounds(self, problem: Problem, refinement: Refinement, knots: int, start: int, goal: int,
               free: int) -> tuple[np.ndarray, np.ndarray]:
        """(lbx, ubx) for x = [vec of `knots` columns [q; q̇; q̈; u], `free` unbounded variables, t_f]; column
        `start` holds the start at rest, column `goal` the goal at rest."""
        r, n = self.robot, self.robot.n
        unbounded, qd_max = np.full(n, np.inf), r.qd_max * refinement.limit_scale
        lower = np.tile(np.concatenate([r.q_lower, -qd_max, -unbounded, -unbounded])[:, None], (1, knots))
        upper = np.tile(np.concatenate([r.q_upper, qd_max, unbounded, unbounded])[:, None], (1, knots))
        for i, q in ((goal, problem.goal), (start, problem.start)):  # rest at both ends, eq. (10)
            lower[: 3 * n, i] = upper[: 3 * n, i] = np.concatenate([q, np.zeros(2 * n)])
        rest = np.full(free, np.inf)
        lbx = np.concatenate([lower.ravel(order="F"), -rest, [problem.time.min]])
        ubx = np.concatenate([upper.ravel(order="F"), rest, [problem.time.max]])
        return lbx, ubx


def problem_shape(problem: Problem, dynamics_name: str) -> tuple:
    """The part of a shape key every transcription shares: dynamics, robot, obstacle count, kept collision
    terms (start, goal, time bounds, μ and the obstacles' positions are numbers, not shape)."""
    return (dynamics_name, id(problem.robot), problem.scene.n_obstacles,
            *(mask.tobytes() for mask in active_terms(problem)))


def knot_columns(robot: Robot, samples: Samples) -> np.ndarray:
    """Rows [q, q̇, q̈, u] (m, 4n) of sampled values, u = rnea(q, q̇, q̈) / τ_max (the rigid-body torque)."""
    data = robot.model.createData()
    rigid = np.array([pin.rnea(robot.model, data, q, qd, qdd).copy()
                      for q, qd, qdd in zip(samples.q, samples.qd, samples.qdd)])
    return np.hstack([samples.q, samples.qd, samples.qdd, rigid / robot.tau_max])


def joint_samples(robot: Robot, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, u: np.ndarray,
                  du_dt: np.ndarray) -> Samples:
    """Samples from interpolated [q, q̇, q̈, u] and du/dt: τ = τ_max u + friction(q̇), τ̇ = τ_max u̇ + friction'(q̇) q̈
    (the torque the plan commands; verify compares it with rnea(q, q̇, q̈) + friction(q̇))."""
    return Samples(np.asarray(t, dtype=float), q, qd, qdd, robot.tau_max * u + robot.friction(qd),
                   robot.tau_max * du_dt + robot.friction_slope(qd) * qdd)


def straight_line(problem: Problem) -> Trajectory:
    """The paper's initial guess: start to goal at constant joint speed over t_f = time.guess (infeasible at
    the ends, where it does not start and stop at rest)."""
    tf, delta = problem.time.guess, problem.goal - problem.start

    def line(t: np.ndarray) -> Samples:
        zeros = np.zeros((len(t), problem.robot.n))
        return Samples(t, problem.start + np.outer(t / tf, delta), np.tile(delta / tf, (len(t), 1)), zeros, zeros,
                       zeros)

    return Trajectory(line(np.array([0.0, tf])), line)
