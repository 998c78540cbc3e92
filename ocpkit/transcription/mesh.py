"""Local collocation on a uniform mesh: what trapezoidal and Hermite–Simpson share.

A method (trapezoidal.py, hermite_simpson.py) gives only its math: `collocation` (its defects on one interval),
`interpolate` (x, u, du/dσ at σ: one formula for the NLP rows and for `decode`) and `cost_rule` (the
quadrature of the running cost on an interval);
`MeshDiscretization` assembles the same NLP around it for both. Variables and rows are created stage by stage
(stage k: knot k, then interval k's midpoint, check and rows), so the KKT matrix is block-banded; `staged=True`
adds the exact stage structure fatrop needs (`ocpkit.nlp.Stages`): per-stage t_f copies T_k, end-of-interval
copies e_k, and gap-closing rows x_{k+1} = [e_k, T_k] first in each stage.

Equations, the row order of a stage and the staged form: docs/transcription.md, section "Mesh methods".
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint
from ocpkit.dynamics import Dynamics
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.nlp import Refinement, Stages
from ocpkit.problem import Problem
from ocpkit.transcription.assembly import Assembly, Node
from ocpkit.transcription.base import Discretization, Transcription
from ocpkit.transcription.ocp import OCP, RobotOCP

CHECK_RANGE = (0.1, 0.9)  # a moved check keeps this far (fraction of h) from the knots, whose rows it would repeat


class Local(NamedTuple):
    """The interpolant [x, u] at σ inside an interval and the controls' slope du/dσ."""

    x: Any
    u: Any
    du_ds: Any

    @property
    def node(self) -> Node:
        return Node(self.x, self.u)


Rate = Callable[[Node, Any], Any]
"""f(x, u, t) at a node at time t (`OCP.rate`)."""
Interpolate = Callable[[Node, Node, "Node | None", Rate, Any, Any, Any], Local]


class MeshInterpolant:
    """The method's interpolant of decoded knot (and midpoint) rows, for any t in [0, t_f]."""

    def __init__(self, tf: float, knots: np.ndarray, mids: np.ndarray | None, interpolate: Interpolate,
                 ocp: OCP, chain: bool = False) -> None:
        self.tf, self.knots, self.mids, self.interpolate, self.ocp = tf, knots, mids, interpolate, ocp
        self.chain = chain  # samples of the OCP's nodes (Discretization.decode) instead of what it reports

    def __call__(self, t: np.ndarray) -> Samples:
        N = len(self.knots) - 1
        h = self.tf / N
        at = np.asarray(t, dtype=float) / h
        k = np.clip(np.floor(at).astype(int), 0, N - 1)  # interval of each t; t_f belongs to the last
        node = self.ocp.split
        mid = None if self.mids is None else node(self.mids[k])
        v = self.interpolate(node(self.knots[k]), node(self.knots[k + 1]), mid, self.ocp.rate, h, (at - k)[:, None],
                             k * h)
        if self.chain:
            return self.ocp.chain_samples(t, v.node, v.du_ds / h)
        return self.ocp.samples(t, v.node, v.du_ds / h)


class MeshDiscretization(Discretization):
    """The NLP of `ocp` (one shape) for a local collocation method (module docstring); subclasses give
    `midpoints`, `cost_rule` and the two static methods. Variables per stage k: "knot{k}", ("tf{k}" if staged),
    "mid{k}" (if midpoints), "<first part>_check{k}" (if the OCP lifts parts), ("end{k}" if staged); "tf" once at
    the end unless staged. Named: "X" (N+1, width), "M" (N, width) and each part's "<part>_mid" (N, size), "E"
    (N, width), "<first part>_check" (N, size; "q_check" for a robot), "tf" (every copy). Own parameter
    "check_at" (N,): σ of each interval's check."""

    midpoints: bool = False
    check_default: float = 0.5  # σ of every interval's check before any refinement
    cost_rule: tuple[tuple[float, ...], tuple[float, ...]]
    """(σ points, weights) of the quadrature of the running cost over [0, 1]: exact for the robot OCP's."""

    @staticmethod
    @abstractmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: Node | None, f: Rate, t0: ca.SX) -> None:
        """Add the interval's defect rows to `a` (interval length h from time t0, knots x0, x1, midpoint xm,
        f = OCP.rate)."""

    @staticmethod
    @abstractmethod
    def interpolate(x0: Node, x1: Node, xm: Node | None, f: Rate, h: Any, s: Any, t0: Any) -> Local:
        """The interval's own interpolant at σ = s ∈ [0, 1] of the interval from time t0 (CasADi symbols or NumPy
        arrays)."""

    def __init__(self, problem: Problem | None, dynamics: Dynamics | None, constraints: Sequence[Constraint],
                 knots: int, margin: float, staged: bool, shape_key: tuple, ocp: OCP) -> None:
        N = knots
        self.N, self.staged = N, staged
        self.lift = ocp.parts[0] if ocp.check_parts else None  # the part lifted at each interval's check
        a = Assembly(problem, dynamics, constraints, ocp)
        x, T, mids, checks, ends = self._variables(a, N, staged, ocp)
        check_at = a.p.add("check_at", N)

        interval_costs, rows = [], []
        parameters = ocp.objective_parameters(a.mu)
        for k in range(N + 1):
            h = T[k] / N
            t0 = k * h  # the start of interval k
            if staged and k < N:  # gap closing first: x_{k+1} − [e_k, T_k] = 0
                a.defect(ca.vertcat(*(next_part - end_part for next_part, end_part in zip(x[k + 1], ends[k])),
                                    T[k + 1] - T[k]))
            first = a.row_count
            a.dynamics_defect(x[k])
            if k == N:
                a.path(x[k], [], h, t0, at_knot=True)
            else:
                end = ends[k] if staged else x[k + 1]
                local = lambda s: self.interpolate(x[k], end, mids[k], ocp.rate, h, s, t0)  # noqa: E731
                a.path(x[k], [local(0.0).du_ds], h, t0, at_knot=True)  # the slope leaving knot k
                self.collocation(a, h, x[k], end, mids[k], ocp.rate, t0)
                if self.midpoints:
                    a.dynamics_defect(mids[k])
                if self.lift is None and self.midpoints:  # no check of its own: the path at the midpoint
                    a.path(mids[k], [local(0.5).du_ds], h, t0 + h / 2)
                if self.lift is not None:
                    v = local(check_at[k])
                    values, size = ocp.join(v.node), self.lift[1]
                    a.defect(checks[k] - values[:size])
                    a.path(ocp.split(ca.vertcat(checks[k], values[size:])), [v.du_ds], h, t0 + check_at[k] * h)
                a.rates(end, [local(1.0).du_ds], h, t0 + h)  # the slope entering knot k + 1
                runs = [a.running(local(s).node, local(s).du_ds, h, t0 + s * h) for s in self.cost_rule[0]]
                interval_costs.append(ocp.lagrange(ca.vertcat(*runs), np.asarray(self.cost_rule[1]), T[k], N,
                                                   parameters))
            rows.append(a.row_count - first)
        ocp.boundary(a, x[0], x[N], T[N])
        stages = None
        if staged:
            controls = a.w.index("end0").size + (a.w.index(f"{self.lift[0]}_check0").size if self.lift else 0) \
                + (ocp.width if self.midpoints else 0)
            stages = Stages((ocp.width + 1,) * (N + 1), (controls,) * N + (0,), tuple(rows))
        objective = ocp.mayer(T[0], ocp.mayer_inputs(x[0], x[N]), parameters) + ca.sum1(ca.vertcat(*interval_costs))
        super().__init__(a.nlp(objective, shape_key, stages), constraints, margin, ocp)

    def _variables(self, a: Assembly, N: int, staged: bool, ocp: OCP) -> tuple[list, list, list, list, list]:
        """Create w stage by stage (class docstring); (knots, t_f per stage, midpoints, check q, end values)."""
        x, T, mids, checks, ends = [], [], [], [], []
        for k in range(N + 1):
            x.append(a.node(f"knot{k}"))
            if staged:
                T.append(a.w.add(f"tf{k}"))
            if k < N:
                mids.append(a.node(f"mid{k}") if self.midpoints else None)
                if self.lift is not None:
                    checks.append(a.w.add(f"{self.lift[0]}_check{k}", self.lift[1]))
                if staged:
                    ends.append(a.node(f"end{k}"))
        if not staged:
            T = [a.w.add("tf")] * (N + 1)
        stack = lambda prefix, count: np.stack([a.w.index(f"{prefix}{k}") for k in range(count)])  # noqa: E731
        a.name_knots([f"knot{k}" for k in range(N + 1)], start=0, goal=N)
        if self.lift is not None:
            a.w.name(f"{self.lift[0]}_check", stack(f"{self.lift[0]}_check", N))
        if self.midpoints:
            M = stack("mid", N)
            a.w.name("M", M)
            for part, columns in ocp.part_slices().items():
                a.w.name(f"{part}_mid", M[:, columns])
        if staged:
            a.w.name("tf", stack("tf", N + 1).ravel())
            a.w.name("E", stack("end", N))
        return x, T, mids, checks, ends

    # -- numbers for one problem -------------------------------------------------------------------
    def bounds(self, problem: Problem | None, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """The knots' bounds (`Discretization.bounds`) and the OCP's own bounds of its parts at the midpoints too."""
        lbx, ubx = super().bounds(problem, refinement)
        if self.midpoints:
            for name, (lower, upper) in self.ocp.chain_bounds().items():
                self.nlp.variables.write(lbx, f"{name}_mid", lower)
                self.nlp.variables.write(ubx, f"{name}_mid", upper)
        return lbx, ubx

    def own_parameters(self, refinement: Refinement) -> dict[str, np.ndarray]:
        """Each of the refinement's check fractions (oldest first, so the newest wins) moves the check of its
        interval there, keeping CHECK_RANGE from the knots."""
        return {"check_at": self._check_at(refinement)}

    def _check_at(self, refinement: Refinement) -> np.ndarray:
        """σ of each interval's check after `refinement` (N,), in fractions of its interval."""
        check_at = np.full(self.N, self.check_default)
        for fraction in refinement.check_fractions[::-1]:
            k = min(int(np.clip(fraction, 0, 1) * self.N), self.N - 1)
            check_at[k] = np.clip(fraction * self.N - k, *CHECK_RANGE)
        return check_at

    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """Sample `trajectory` at this NLP's knots, midpoints and default checks (scaled to its t_f), as
        `OCP.columns` reads it (for a robot, u is the rigid-body torque rnea(q, qd, qdd) / tau_max)."""
        tf, N, w = trajectory.tf, self.N, self.nlp.variables
        at = lambda s: trajectory.interpolant(tf * s / N)  # noqa: E731  s in intervals
        intervals, values = np.arange(N), np.zeros(w.size)
        knots = self.ocp.columns(at(np.arange(N + 1.0)))
        w.write(values, "X", knots)
        if self.midpoints:
            w.write(values, "M", self.ocp.columns(at(intervals + 0.5)))
        if self.staged:
            w.write(values, "E", knots[1:])
        self.write_checks(values, trajectory, Refinement())
        w.write(values, "tf", tf)
        return values

    def write_checks(self, values: np.ndarray, trajectory: Trajectory, refinement: Refinement) -> None:
        if self.lift is None:
            return
        at = trajectory.tf * (np.arange(self.N) + self._check_at(refinement)) / self.N
        nodes = self.ocp.columns(trajectory.interpolant(at))
        self.nlp.variables.write(values, f"{self.lift[0]}_check", nodes[:, :self.lift[1]])

    def decode(self, w: np.ndarray, chain: bool = False) -> Trajectory:
        layout = self.nlp.variables
        knots, tf = layout.read(w, "X"), float(layout.read(w, "tf")[0])
        mids = layout.read(w, "M") if self.midpoints else None
        interpolant = MeshInterpolant(tf, knots, mids, self.interpolate, self.ocp, chain)
        return Trajectory(interpolant(tf * np.arange(self.N + 1) / self.N), interpolant)


class MeshTranscription(Transcription):
    """A local collocation method with N = `knots` intervals; `margin` (m) is added to every sphere clearance
    so the interpolant between check times stays clear; `staged` gives the NLP the exact stage structure of the
    module docstring (for fatrop). Subclasses name their `discretization` class."""

    discretization: type[MeshDiscretization]

    max_intervals = 256

    def __init__(self, knots: int = 20, margin: float = 0.01, staged: bool = False) -> None:
        self.knots, self.margin, self.staged = knots, margin, staged
        self.check_knots(knots, knots)

    def free_path_values(self, knots: int) -> int:
        """3 values per knot and midpoint, less 2 rows per interval (4 with midpoints), less 6."""
        midpoints = int(self.discretization.midpoints)
        return 3 * (knots + 1 + knots * midpoints) - 2 * knots * (1 + midpoints) - 6

    def options_key(self) -> tuple:
        return self.name, self.knots, self.margin, self.staged

    def build(self, problem: Problem | None, dynamics: Dynamics | None, constraints: Sequence[Constraint],
              ocp: OCP | None = None) -> MeshDiscretization:
        return self.discretization(problem, dynamics, constraints, self.knots, self.margin, self.staged,
                                   self.shape_key(dynamics, constraints, ocp), ocp or RobotOCP(problem.robot))
