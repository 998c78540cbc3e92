"""Solve an `Ocp` with any registered transcription and NLP solver; the `Solution` with the transcription's own
dense interpolant, the multipliers and, for the pseudospectral transcriptions, costate estimates."""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.ocp.instance import ModelOCP
from ocpkit.ocp.model import Ocp, columns
from ocpkit.registry import construct
from ocpkit.solvers import SOLVERS, SolverResult
from ocpkit.transcription import TRANSCRIPTIONS, Discretization

SOLVER_DEFAULTS = {"ipopt": {"tol": 1e-10, "bound_relax_factor": 0.0}}
"""Options a solver gets unless told otherwise: the classic problems' optima are compared to 1e-6 and more, which
IPOPT's default relaxation of the bounds by 1e-8 would spoil on a state-constrained arc."""


@dataclass(frozen=True)
class Solution:
    """A solved `Ocp`: status, iterations, wall time of the solve (s), objective, t_f (s), the discretization and
    the solver's result (w, multipliers), the set-up time (s). Values in the user's units at any t ∈ [0, t_f]
    through `x`, `u`, `p`."""

    model: Ocp
    ocp: ModelOCP
    discretization: Discretization
    result: SolverResult
    objective: float
    transcription: str
    knots: int
    setup_time: float = 0.0
    """Building the NLP and preparing the solver (s)."""

    @property
    def status(self) -> str:
        return self.result.status.value

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def iterations(self) -> int:
        return self.result.iterations

    @property
    def wall_time(self) -> float:
        return self.result.wall_time

    @property
    def segments(self) -> int:
        """The pseudospectral segments (1 for the mesh transcriptions)."""
        grid = getattr(self.discretization, "grid", None)
        return grid.K if grid is not None else 1

    @property
    def t0(self) -> float:
        """The initial time (s)."""
        first, last = self.model.t0_bounds
        return first if first == last else self.p("t0")

    @property
    def T(self) -> float:
        """t_f (s)."""
        return self.t0 + self.trajectory.tf

    @functools.cached_property
    def trajectory(self) -> Trajectory:
        """The decoded trajectory of scaled nodes (ocpkit.formats.trajectory: x̃ as q, ũ as tau)."""
        return self.discretization.decode(self.result.w)

    @property
    def knot_times(self) -> np.ndarray:
        """The transcription's knot times (s), increasing."""
        return self.t0 + self.trajectory.knots.t

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x (points, states + parameters), u (points, controls), u̇ (points, controls)) at times t ∈ [t0, t_f]
        (s), user units."""
        s = self._relative(np.atleast_1d(np.asarray(t, dtype=float)) - self.t0)
        return s.q * self.ocp.x_scale, s.tau * self.ocp.u_scale, s.taud * self.ocp.u_scale

    def _relative(self, t: np.ndarray) -> Samples:
        """The decoded trajectory at times since the start t (s)."""
        return self.trajectory.interpolant(t)

    def x(self, name: str, t: np.ndarray) -> np.ndarray:
        """State `name` at times t: (points,) for a scalar, else (points, size)."""
        return self._part(name, self.sample(t)[0], [*self.model.states, *self.model.parameters])

    def u(self, name: str, t: np.ndarray) -> np.ndarray:
        """Control `name` at times t: (points,) for a scalar, else (points, size)."""
        return self._part(name, self.sample(t)[1], self.model.controls)

    def p(self, name: str) -> float | np.ndarray:
        """Parameter `name`'s optimal value ("t0" for a free initial time)."""
        s = self._relative(np.zeros(1))
        value = self._part(name, s.q * self.ocp.x_scale, [*self.model.states, *self.model.parameters])
        return float(value[0]) if np.ndim(value) == 1 else value[0]

    def _part(self, name: str, values: np.ndarray, family: list) -> np.ndarray:
        parts = columns(family, values)
        if name not in parts:
            raise KeyError(f"{self.model.name} has no {name!r} here: {list(parts)}")
        return parts[name][:, 0] if parts[name].shape[1] == 1 else parts[name]

    def costates(self) -> tuple[np.ndarray, np.ndarray]:
        """(t (points,), λ (points, states + parameters)) at the collocated knots, in the user's units, estimated
        from the collocation rows' multipliers: λ_j = −Λ_j / w_j / scale (a pseudospectral transcription's
        covector mapping, Λ in CasADi's sign convention, w_j the quadrature weights of the segments collocating
        knot j; ValueError for other transcriptions). Convention: H = L + λᵀ f."""
        rows = getattr(self.discretization, "collocation_rows", None)
        if rows is None or self.result.lam_g is None:
            raise ValueError(f"{self.transcription} with this solver gives no costate estimates")
        grid = self.discretization.grid
        columns = sorted({j for j, _, _ in rows})
        multipliers = {j: np.zeros(self.ocp.states) for j in columns}
        weights = dict.fromkeys(columns, 0.0)
        for j, first, weight in rows:
            multipliers[j] += self.result.lam_g[first:first + self.ocp.states]
            weights[j] += weight
        t = self.t0 + self.trajectory.tf * (grid.knots[columns] + 1.0) / 2.0
        lam = -np.stack([multipliers[j] / weights[j] for j in columns]) / self.ocp.x_scale
        order = np.argsort(t)
        return t[order], lam[order]


def solve(model: Ocp, transcription: str = "chebyshev", knots: int = 30, solver: str = "ipopt",
          transcription_options: dict | None = None, solver_options: dict | None = None,
          start: Solution | None = None) -> Solution:
    """Discretize `model` with the transcription `transcription` (`ocpkit list`; its options, e.g. segments, in
    `transcription_options`) at `knots` and solve it with `solver` from the model's guess, or from the solution
    `start` of the same model (any transcription or grid) sampled at the new knots."""
    began = time.perf_counter()
    ocp = ModelOCP(model)
    method = construct(TRANSCRIPTIONS.get(transcription), transcription,
                       {"knots": knots, **(transcription_options or {})})
    discretization = method.build(None, None, ocp.constraints, ocp)
    nlp = discretization.nlp
    options = {**SOLVER_DEFAULTS.get(solver, {}), **(solver_options or {})}
    prepared = construct(SOLVERS.get(solver), solver, options).prepare(nlp)
    setup_time = time.perf_counter() - began
    bounds, parameters = discretization.bounds(None), discretization.parameters(None)
    guess = discretization.initial_guess(None) if start is None else discretization.encode(start.trajectory)
    guess = np.clip(guess, *bounds)
    result = prepared.solve(guess, parameters, bounds)
    objective = float(ca.Function("f", [nlp.x, nlp.p], [nlp.f])(result.w, parameters))
    return Solution(model, ocp, discretization, result, objective, transcription, knots, setup_time)

