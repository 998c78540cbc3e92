"""Pseudospectral transcription on K equal segments, for any node family (chebyshev.py, lgl.py, lgr.py).

    D X = h F    on every segment (`collocation_defect`), h = dt/ds = t_f/(2K), at the collocated points

What is specific to the code: `Grid` maps a segment's local s to global σ; the knot columns run in decreasing
time (column 0 is t_f, the last the start) and adjacent segments share their joint column; a joint's dynamics
defect and non-rate path constraints come from the earlier segment in column order, its torque-rate rows once
per segment's slope; q, q̇ and q̈ are lifted at the check points (`q_check`, `qd_check`, `qdd_check`), the fixed
ones per segment and the adaptive slots, whose interpolation rows are NLP parameters so a refinement moves them
without a rebuild. Lifted, every nonlinear row at a check point reads that point's own variables: a nonlinear
function of the interpolating combination of all knots (friction(L q̇) in a torque row) would make its Hessian
block dense in every knot, which CasADi pays for when it builds the Hessian and IPOPT in every factorization.

Equations: docs/transcription.md, section "Pseudospectral"; the check points: section "Why constraints are
also imposed between knots".
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint
from ocpkit.dynamics import Dynamics
from ocpkit.errors import OptionError
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.nlp import Refinement
from ocpkit.problem import Problem
from ocpkit.transcription.assembly import Assembly
from ocpkit.transcription.base import Discretization, Transcription
from ocpkit.transcription.ocp import OCP, Node, RobotOCP
from ocpkit.transcription.polynomials import NodeFamily, barycentric_interpolation


@dataclass(frozen=True)
class Grid:
    """K segments of N intervals each of a node family, on σ ∈ [−1, 1] (docs/transcription.md): equal ones, or
    ones ending at `breaks` (the K − 1 interior boundaries as fractions τ ∈ (0, 1) of the horizon, increasing)."""

    family: NodeFamily
    N: int
    K: int
    breaks: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.breaks and len(self.breaks) != self.K - 1:
            raise ValueError(f"{self.K} segments need {self.K - 1} breaks, got {len(self.breaks)}")

    @functools.cached_property
    def _edges(self) -> np.ndarray:
        """σ of the K + 1 segment ends in column order (decreasing: 1 first)."""
        return np.concatenate([[1.0], 2.0 * np.asarray(self.breaks[::-1]) - 1.0, [-1.0]])

    def scale(self, segment: int | np.ndarray) -> float | np.ndarray:
        """K_b = ds/dσ of segment b: K on equal segments, 2 / its σ-length otherwise."""
        if not self.breaks:
            return np.full(np.shape(segment), self.K) if np.ndim(segment) else self.K
        return 2.0 / (self._edges[segment] - self._edges[np.asarray(segment) + 1])

    def to_global(self, segment: int | np.ndarray, s: np.ndarray) -> np.ndarray:
        """σ of local s in segment b: c_b + s/K_b."""
        if not self.breaks:
            return 1.0 - (2 * segment + 1) / self.K + s / self.K
        center = (self._edges[segment] + self._edges[np.asarray(segment) + 1]) / 2
        return center + s / self.scale(segment)

    def segment_of(self, sigma: np.ndarray) -> np.ndarray:
        """The segment holding each σ (at a joint, the later one in column order)."""
        if not self.breaks:
            return np.clip(np.floor((1.0 - sigma) * self.K / 2).astype(int), 0, self.K - 1)
        return np.clip(np.searchsorted(-self._edges[1:-1], -sigma, side="right"), 0, self.K - 1)

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
        segment = self.segment_of(sigma)
        s = self.scale(segment) * (sigma - self.to_global(segment, 0.0))
        rows, columns = np.arange(len(sigma))[:, None], segment[:, None] * self.N + np.arange(self.N + 1)
        L, Ld = np.zeros((2, len(sigma), self.K * self.N + 1))
        L[rows, columns] = self.family.interpolation(self.N, s)
        Ld[rows, columns] = self.family.derivative(self.N, s)
        return L, Ld


@dataclass(frozen=True)
class PseudospectralInterpolant:
    """The piecewise barycentric interpolant of the knot values; `columns` is (width, KN + 1) in column order;
    `jumps` (K − 1, controls), where controls may jump at breaks: segment b's own control at its joint with
    segment b − 1 (b ≥ 1)."""

    tf: float
    columns: np.ndarray
    ocp: OCP
    grid: Grid
    chain: bool = False  # samples of the OCP's nodes (Discretization.decode) instead of what it reports
    jumps: np.ndarray | None = None

    def __call__(self, t: np.ndarray) -> Samples:
        sigma = np.atleast_1d(2.0 * np.asarray(t, dtype=float) / self.tf - 1.0)
        L, Ld = self.grid.matrices(sigma)
        segment = self.grid.segment_of(sigma)
        dsigma_dt = 2.0 * np.reshape(self.grid.scale(segment), (-1, 1)) / self.tf
        values, rates = L @ self.columns.T, Ld @ self.columns.T * dsigma_dt
        if self.jumps is not None:  # segment b's polynomial through its own control at the joint
            rows, first = self.ocp.states, np.flatnonzero(segment > 0)
            joint = segment[first] * self.grid.N
            change = self.jumps[segment[first] - 1] - self.columns[rows:, joint].T
            values[first, rows:] += L[first, joint][:, None] * change
            rates[first, rows:] += (Ld[first, joint] * dsigma_dt[first, 0])[:, None] * change
        x, du_dt = self.ocp.split(values), rates[:, self.ocp.states:]
        if self.chain:
            return self.ocp.chain_samples(t, x, du_dt)
        return self.ocp.samples(t, x, du_dt)


def collocation_defect(D: np.ndarray, X: ca.SX, F: ca.SX, h: ca.SX) -> ca.SX:
    """D X = h F on one segment: the residual D X − h F (N+1, n), X and F holding a state and its time
    derivative at the segment's N + 1 points as rows, D the family's differentiation matrix on s."""
    return ca.mtimes(ca.DM(D), X) - h * F


class PseudospectralDiscretization(Discretization):
    """The NLP of `ocp` (one shape) on `grid` (docs/transcription.md), with the maps from a problem to its numbers
    and back. Variables: knot columns "knot0".. in column order (named "X", "q",
    ... by the assembly), "<part>_check" (size, checks) for each part the OCP lifts ("q_check", "qd_check",
    "qdd_check" for a robot), "tf"; own parameters "adaptive_rows", "adaptive_drows" (slots, KN + 1): L(σ_k)
    and d/ds L(σ_k) of the adaptive check slots."""

    def __init__(self, problem: Problem | None, dynamics: Dynamics | None, constraints: Sequence[Constraint],
                 grid: Grid, margin: float, adaptive_checks: int, shape_key: tuple, ocp: OCP,
                 end_checks: bool = False) -> None:
        N, K = grid.N, grid.K
        self.grid = grid
        D, weights = grid.family.differentiation(N), grid.family.quadrature_weights(N)
        collocated, points = grid.family.collocation_mask(N), grid.family.points(N)
        lifted = ocp.lifted
        self.check_sigma = grid.in_segments(long_interval_midpoints(points, end_checks)) if lifted else np.zeros(0)
        adaptive_checks = adaptive_checks if lifted else 0
        self.adaptive_default = grid.to_global(K // 2, middle_quarter_points(points, adaptive_checks))
        columns = K * N + 1

        a = Assembly(problem, dynamics, constraints, ocp)
        x = [a.node(f"knot{j}") for j in range(columns)]  # column j at σ_j: t_f first, the start last
        a.name_knots([f"knot{j}" for j in range(columns)], start=columns - 1, goal=0)
        checks = len(self.check_sigma) + adaptive_checks
        lifted_values = [a.w.add(f"{part}_check", size, checks) for part, size in lifted]
        tf = a.w.add("tf")
        rows = a.p.add("adaptive_rows", adaptive_checks, columns)  # L(σ_k), one row per slot
        drows = a.p.add("adaptive_drows", adaptive_checks, columns)  # d/ds L(σ_k)
        steps = [tf / (2 * grid.scale(b)) for b in range(K)]  # dt/ds on each segment
        times = [tf * (sigma + 1.0) / 2.0 for sigma in grid.knots]  # t of each column

        # a Lobatto segment collocates its joints too: at a break its control may jump, so the earlier segment
        # gets a control of its own at the joint ("jump<b>"; LGR's joint is collocated by one segment only)
        self.jumps = bool(grid.breaks) and bool(collocated[0]) and bool(collocated[-1])
        runs, self.collocation_rows = [], []  # (column, first row of its state defect, quadrature weight)
        for b in range(K):
            own, at = x[b * N: b * N + N + 1], times[b * N: b * N + N + 1]
            if self.jumps and b > 0:
                own = [Node(own[0].x, a.w.add(f"jump{b}", ocp.controls)), *own[1:]]
            X = ca.horzcat(*(v.x for v in own)).T  # (points, states)
            F = ca.horzcat(*(ocp.rate(v, t) for v, t in zip(own, at))).T
            U = ca.horzcat(*(v.u for v in own)).T
            h = steps[b]
            defect, du_ds = collocation_defect(D, X, F, h), ca.mtimes(ca.DM(D), U)
            for i, node in enumerate(own):
                if collocated[i]:
                    self.collocation_rows.append((b * N + i, a.row_count, weights[i]))
                    a.defect(defect[i, :].T)
                slope = du_ds[i, :].T
                if b > 0 and i == 0 and not self.jumps:  # the joint with segment b − 1: its other one-sided rate
                    a.rates(node, [slope], h, at[i])
                else:
                    a.dynamics_defect(node)
                    a.path(node, [slope], h, at[i], at_knot=True)
                runs.append(a.running(node, slope, h, at[i]))  # from (D U_b) point by point

        if self.jumps:
            a.w.name("U_jump", np.stack([a.w.index(f"jump{b}") for b in range(1, K)]))
        if ocp.extrapolated_controls:
            self._extrapolate_controls(a, x, grid)
        fixed_rows, fixed_drows = grid.matrices(self.check_sigma)
        L, Ld = ca.vertcat(ca.DM(fixed_rows), rows), ca.vertcat(ca.DM(fixed_drows), drows)
        values = ca.horzcat(*(ocp.join(v) for v in x))  # (width, KN + 1)
        U = ca.horzcat(*(v.u for v in x))
        slices = list(ocp.part_slices().values())
        for k in range(L.size1() if lifted else 0):
            row, drow = ca.transpose(L[k, :]), ca.transpose(Ld[k, :])
            for variable, columns in zip(lifted_values, slices):
                a.defect(variable[:, k] - ca.mtimes(values[columns, :], row))
            rest = slice(slices[len(lifted) - 1].stop, ocp.width)
            node = ocp.split(ca.vertcat(*(variable[:, k] for variable in lifted_values),
                                        ca.mtimes(values[rest, :], row)))
            # only OCPs that never read t lift checks, on equal segments (Pseudospectral.build)
            a.path(node, [ca.mtimes(U, drow)], steps[0], None)

        ocp.boundary(a, x[-1], x[0], tf)
        ends, quad, per_tf = ocp.mayer_inputs(x[-1], x[0]), np.tile(weights, K), 2.0 * K
        if grid.breaks:
            quad, per_tf = np.concatenate([weights / grid.scale(b) for b in range(K)]), 2.0

        def formula(r: ca.SX, t_f: ca.SX, *rest: ca.SX) -> ca.SX:
            inputs, parameters = rest[:len(ends)], rest[len(ends):]
            return ocp.mayer(t_f, inputs, parameters) + ocp.lagrange(r, quad, t_f, per_tf, parameters)

        objective = a.objective(formula, [ca.vertcat(*runs), tf, *ends], ocp.objective_parameters(a.mu))
        super().__init__(a.nlp(objective, shape_key), constraints, margin, ocp)

    def _extrapolate_controls(self, a: Assembly, x: list, grid: Grid) -> None:
        """Rows u_j = (the degree N − 1 interpolant of its segment's collocated controls)(s_j) at every knot that
        no segment collocates (LGR's free end): nothing else fixes u there, and a free value would bend the
        control's polynomial everywhere."""
        N, points = grid.N, grid.family.points(grid.N)
        mask = grid.family.collocation_mask(N)
        collocated = {b * N + i for b in range(grid.K) for i in np.flatnonzero(mask)}
        for b in range(grid.K):
            for m in np.flatnonzero(~mask):
                if b * N + m in collocated:
                    continue
                others = np.flatnonzero(mask)
                weights = grid.family.barycentric_weights(N)[others] * (points[others] - points[m])
                row = barycentric_interpolation(points[others], weights, points[m:m + 1])[0]
                a.defect(x[b * N + m].u - sum(c * x[b * N + i].u for c, i in zip(row, others)))

    # -- numbers for one problem -------------------------------------------------------------------
    def bounds(self, problem: Problem | None, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """The knots' bounds (`Discretization.bounds`) and the controls' at the jumps."""
        lbx, ubx = super().bounds(problem, refinement)
        if self.jumps:
            chain = self.ocp.chain_bounds()
            controls = [(name, columns) for name, columns in self.ocp.part_slices().items()
                        if columns.start >= self.ocp.states]
            index = self.nlp.variables.index("U_jump")
            for name, columns in controls:
                lower, upper = chain[name]
                shift = slice(columns.start - self.ocp.states, columns.stop - self.ocp.states)
                lbx[index[:, shift]], ubx[index[:, shift]] = lower, upper
        return lbx, ubx

    def own_parameters(self, refinement: Refinement) -> dict[str, np.ndarray]:
        """The refinement's first check fractions move the adaptive slots (the rest stay at their defaults)."""
        rows, drows = self.grid.matrices(self._adaptive_sigma(refinement))
        return {"adaptive_rows": rows, "adaptive_drows": drows}

    def _adaptive_sigma(self, refinement: Refinement) -> np.ndarray:
        """σ of the adaptive check slots after `refinement` (slots,)."""
        sigma = self.adaptive_default.copy()
        chosen = 2.0 * np.clip(refinement.check_fractions[: len(sigma)], 0, 1) - 1.0
        sigma[: len(chosen)] = chosen
        return sigma

    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """Sample `trajectory` at this NLP's knots and check times (scaled to its t_f), as `OCP.columns` reads it
        (for a robot, u is the rigid-body torque rnea(q, qd, qdd) / tau_max of the sampled motion)."""
        tf, w = trajectory.tf, self.nlp.variables
        values = np.zeros(w.size)
        w.write(values, "X", self.ocp.columns(trajectory.interpolant(tf * (self.grid.knots + 1.0) / 2.0)))
        if self.jumps:
            joints = tf * (self.grid.knots[self.grid.N:-1:self.grid.N] + 1.0) / 2.0
            w.write(values, "U_jump", self.ocp.columns(trajectory.interpolant(joints))[:, self.ocp.states:])
        self.write_checks(values, trajectory, Refinement())
        w.write(values, "tf", tf)
        return values

    def write_checks(self, values: np.ndarray, trajectory: Trajectory, refinement: Refinement) -> None:
        sigma = np.concatenate([self.check_sigma, self._adaptive_sigma(refinement)])
        if not len(sigma):
            return
        nodes = self.ocp.columns(trajectory.interpolant(trajectory.tf * (sigma + 1.0) / 2.0))
        slices = self.ocp.part_slices()
        for part, _ in self.ocp.lifted:
            self.nlp.variables.write(values, f"{part}_check", nodes[:, slices[part]].T)

    def decode(self, w: np.ndarray, chain: bool = False) -> Trajectory:
        layout = self.nlp.variables
        columns, tf = layout.read(w, "X").T, float(layout.read(w, "tf")[0])
        jumps = layout.read(w, "U_jump") if self.jumps else None
        interpolant = PseudospectralInterpolant(tf, columns, self.ocp, self.grid, chain, jumps)
        return Trajectory(interpolant(tf * (self.grid.knots[::-1] + 1.0) / 2.0), interpolant)


def long_interval_midpoints(points: np.ndarray, every: bool = False) -> np.ndarray:
    """Local s of the fixed checks: the θ-midpoints (s = cos θ) of the knot intervals where sin θ ≥ ½, i.e.
    about half as long (in time) as the longest one. Intervals near the ends are short (knots cluster there) and
    the robot starts and stops at rest there, so checks between them cost constraints and buy little — unless
    the start or goal sits close to an obstacle, where the arm still moves fast enough to dip into it between
    knots (MBM's goals on a shelf): `every` checks the midpoints of all intervals."""
    theta = np.arccos(points)
    middle = (theta[:-1] + theta[1:]) / 2
    return np.cos(middle if every else middle[np.sin(middle) >= 0.5 - 1e-12])


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
    refinement round may move; `end_checks` adds fixed checks in the short intervals near the ends too
    (`long_interval_midpoints`); `breaks` (fractions of the horizon in (0, 1), increasing) end unequal segments
    instead, for an `Ocp` (`ocpkit.ocp.mesh` puts them at a solution's control switches)."""

    family: NodeFamily

    max_intervals = 256
    max_knots: int = 64
    """The most knot intervals on one segment: its blocks are dense (design notes, "NLP size limits")."""

    def __init__(self, knots: int = 12, segments: int = 1, margin: float = 0.01, adaptive_checks: int = 4,
                 end_checks: bool = False, breaks: Sequence[float] = ()) -> None:
        if segments < 1:
            raise OptionError(f"{self.name} needs segments ≥ 1, got {segments}")
        breaks = tuple(float(b) for b in breaks)
        if breaks:
            if segments not in (1, len(breaks) + 1):
                raise OptionError(f"{self.name}: segments={segments} disagrees with {len(breaks)} breaks "
                                  f"({len(breaks) + 1} segments)")
            if not (0.0 < breaks[0] and breaks[-1] < 1.0 and all(a < b for a, b in zip(breaks, breaks[1:]))):
                raise OptionError(f"{self.name}: breaks must increase strictly inside (0, 1), got {list(breaks)}")
            segments = len(breaks) + 1
        self.knots, self.segments, self.margin, self.adaptive_checks = knots, segments, margin, adaptive_checks
        self.end_checks, self.breaks = end_checks, breaks
        if knots > self.max_knots:
            raise OptionError(f"{self.name} takes at most {self.max_knots} knot intervals per segment, got {knots}: "
                              "its dense blocks take too long and too much memory to build; use segments")
        self.check_knots(knots, knots * segments)

    def free_path_values(self, knots: int) -> int:
        """3 (K N + 1) point values less 2 rows per collocated point, less 6."""
        collocated = self.segments * int(self.family.collocation_mask(knots).sum())
        return 3 * (self.segments * knots + 1) - 2 * collocated - 6

    def options_key(self) -> tuple:
        return self.name, self.knots, self.segments, self.margin, self.adaptive_checks, self.end_checks, self.breaks

    def build(self, problem: Problem | None, dynamics: Dynamics | None, constraints: Sequence[Constraint],
              ocp: OCP | None = None) -> PseudospectralDiscretization:
        instance = ocp or RobotOCP(problem.robot)
        if self.breaks and instance.lifted:
            raise OptionError(f"{self.name}: breaks are for OCPs without lifted check points (an `Ocp`), not a "
                              "robot's: use equal segments")
        return PseudospectralDiscretization(problem, dynamics, constraints, Grid(self.family, self.knots,
                                            self.segments, self.breaks), self.margin, self.adaptive_checks,
                                            self.shape_key(dynamics, constraints, ocp), instance, self.end_checks)
