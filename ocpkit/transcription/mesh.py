"""Local collocation on a uniform mesh: what trapezoidal and Hermite–Simpson share.

A method (trapezoidal.py, hermite_simpson.py) gives only its math: `collocation` (its defects on one interval),
`interpolate` (x, ẋ, ẍ, u, du/dσ, dẍ/dσ at σ: one formula for the NLP rows and for `decode`) and `jerk_rule`
(the quadrature of the jerk cost on an interval);
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
from ocpkit.transcription.assembly import Assembly, Node, Slope
from ocpkit.transcription.base import Discretization, Transcription
from ocpkit.transcription.ocp import OCP, RobotOCP

CHECK_RANGE = (0.1, 0.9)  # a moved check keeps this far (fraction of h) from the knots, whose rows it would repeat


class Local(NamedTuple):
    """The interpolant [x, ẋ, ẍ, u] at σ inside an interval, the slope du/dσ of the scaled rigid-body torque and
    the slope dẍ/dσ (the chain's jerk times h)."""

    q: Any
    qd: Any
    qdd: Any
    u: Any
    du_ds: Any
    dqdd_ds: Any

    @property
    def slope(self) -> Slope:
        """(du/dσ, dẍ/dσ)."""
        return Slope(self.du_ds, self.dqdd_ds)


Interpolate = Callable[[Node, Node, "Node | None", Any, Any], Local]


class MeshInterpolant:
    """The method's interpolant of decoded knot (and midpoint) rows, for any t in [0, t_f]."""

    def __init__(self, tf: float, knots: np.ndarray, mids: np.ndarray | None, interpolate: Interpolate,
                 ocp: OCP, chain: bool = False) -> None:
        self.tf, self.knots, self.mids, self.interpolate, self.ocp = tf, knots, mids, interpolate, ocp
        self.chain = chain  # samples of the OCP's chain (Discretization.decode) instead of the robot's

    def __call__(self, t: np.ndarray) -> Samples:
        N = len(self.knots) - 1
        h = self.tf / N
        at = np.asarray(t, dtype=float) / h
        k = np.clip(np.floor(at).astype(int), 0, N - 1)  # interval of each t; t_f belongs to the last
        node = self.ocp.split
        mid = None if self.mids is None else node(self.mids[k])
        v = self.interpolate(node(self.knots[k]), node(self.knots[k + 1]), mid, h, (at - k)[:, None])
        x = Node(v.q, v.qd, v.qdd, v.u)
        if self.chain:
            return self.ocp.chain_samples(t, x, v.du_ds / h)
        return self.ocp.samples(t, x, v.du_ds / h, v.dqdd_ds / h)


class MeshDiscretization(Discretization):
    """The NLP of `ocp` (one shape) for a local collocation method (module docstring); subclasses give
    `midpoints`, `jerk_rule` and the two static methods. Variables per stage k: "knot{k}", ("tf{k}" if staged),
    "mid{k}" (if midpoints), "q_check{k}", ("end{k}" if staged); "tf" once at the end unless staged. Named: "X"
    (N+1, 3m + n), "M" (N, 3m + n), "E" (N, 3m + n), "q_check" (N, m), "tf" (every copy).
    Own parameter "check_at" (N,): σ of each interval's check."""

    midpoints: bool = False
    check_default: float = 0.5  # σ of every interval's check before any refinement
    jerk_rule: tuple[tuple[float, ...], tuple[float, ...]]
    """(σ points, weights) of the quadrature of ∫ (dq̈/dσ)ᵀ Q (dq̈/dσ) dσ over [0, 1]: exact for the robot OCP."""

    @staticmethod
    @abstractmethod
    def collocation(a: Assembly, h: ca.SX, x0: Node, x1: Node, xm: Node | None) -> None:
        """Add the interval's defect rows to `a` (interval length h, knots x0, x1, midpoint xm)."""

    @staticmethod
    @abstractmethod
    def interpolate(x0: Node, x1: Node, xm: Node | None, h: Any, s: Any) -> Local:
        """The interval's own interpolant at σ = s ∈ [0, 1] (CasADi symbols or NumPy arrays)."""

    def __init__(self, problem: Problem, dynamics: Dynamics, constraints: Sequence[Constraint], knots: int,
                 margin: float, staged: bool, shape_key: tuple, ocp: OCP) -> None:
        N = knots
        self.m, self.N, self.staged = ocp.chain, N, staged
        a = Assembly(problem, dynamics, constraints, ocp)
        x, T, mids, checks, ends = self._variables(a, N, staged)
        check_at = a.p.add("check_at", N)

        jerk, rows = 0, []
        for k in range(N + 1):
            h = T[k] / N
            if staged and k < N:  # gap closing first: x_{k+1} − [e_k, T_k] = 0
                a.defect(ca.vertcat(*(next_part - end_part for next_part, end_part in zip(x[k + 1], ends[k])),
                                    T[k + 1] - T[k]))
            first = a.row_count
            a.dynamics_defect(x[k])
            if k == N:
                a.path(x[k], [], h, at_knot=True)
            else:
                end = ends[k] if staged else x[k + 1]
                local = lambda s: self.interpolate(x[k], end, mids[k], h, s)  # noqa: E731
                a.path(x[k], [local(0.0).slope], h, at_knot=True)  # the slope leaving knot k
                self.collocation(a, h, x[k], end, mids[k])
                if self.midpoints:
                    a.dynamics_defect(mids[k])
                v = local(check_at[k])
                a.defect(checks[k] - v.q)
                a.path(Node(checks[k], v.qd, v.qdd, v.u), [v.slope], h)
                a.rates(end, [local(1.0).slope], h)  # the slope entering knot k + 1
                jerk += self._jerk_integral(a, local, h, ca.DM(problem.jerk_weights)) / h
            rows.append(a.row_count - first)
        stages = None
        if staged:
            controls = a.w.index("end0").size + a.w.index("q_check0").size + (ocp.width if self.midpoints else 0)
            stages = Stages((ocp.width + 1,) * (N + 1), (controls,) * N + (0,), tuple(rows))
        super().__init__(a.nlp(T[0] + a.mu * jerk, shape_key, stages), constraints, margin, ocp)

    def _jerk_integral(self, a: Assembly, local: Callable[[Any], Local], h: ca.SX, weights: ca.DM) -> ca.SX:
        """∫ (dq̈/dσ)ᵀ Q (dq̈/dσ) dσ over one interval by `jerk_rule` (weights = diag Q)."""
        total = 0
        for s, c in zip(*self.jerk_rule):
            v = local(s)
            j = a.jerk_s(Node(v.q, v.qd, v.qdd, v.u), v.dqdd_ds, h)
            total += c * ca.dot(weights * j, j)
        return total

    def _variables(self, a: Assembly, N: int, staged: bool) -> tuple[list, list, list, list, list]:
        """Create w stage by stage (class docstring); (knots, t_f per stage, midpoints, check q, end values)."""
        x, T, mids, checks, ends = [], [], [], [], []
        for k in range(N + 1):
            x.append(a.node(f"knot{k}"))
            if staged:
                T.append(a.w.add(f"tf{k}"))
            if k < N:
                mids.append(a.node(f"mid{k}") if self.midpoints else None)
                checks.append(a.w.add(f"q_check{k}", self.m))
                if staged:
                    ends.append(a.node(f"end{k}"))
        if not staged:
            T = [a.w.add("tf")] * (N + 1)
        stack = lambda prefix, count: np.stack([a.w.index(f"{prefix}{k}") for k in range(count)])  # noqa: E731
        a.name_knots([f"knot{k}" for k in range(N + 1)], start=0, goal=N)
        a.w.name("q_check", stack("q_check", N))
        if self.midpoints:
            a.w.name("M", stack("mid", N))
        if staged:
            a.w.name("tf", stack("tf", N + 1).ravel())
            a.w.name("E", stack("end", N))
        return x, T, mids, checks, ends

    # -- numbers for one problem -------------------------------------------------------------------
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
        """Sample `trajectory` at this NLP's knots, midpoints and default checks (scaled to its t_f); u is the
        rigid-body torque rnea(q, qd, qdd) / tau_max of the sampled motion."""
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
        at = trajectory.tf * (np.arange(self.N) + self._check_at(refinement)) / self.N
        self.nlp.variables.write(values, "q_check", trajectory.interpolant(at).q)

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

    def build(self, problem: Problem, dynamics: Dynamics, constraints: Sequence[Constraint],
              ocp: OCP | None = None) -> MeshDiscretization:
        return self.discretization(problem, dynamics, constraints, self.knots, self.margin, self.staged,
                                   self.shape_key(dynamics, constraints, ocp), ocp or RobotOCP(problem.robot))
