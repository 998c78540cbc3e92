"""An `Ocp` as the transcriptions see it (`ModelOCP`): nodes [x̃, p̃, ũ] of scaled values (value / scale), the
parameters p carried as states with ṗ = 0 (the collocation keeps them constant, and the Mayer term and the end
rows read them from the end nodes), the path rows as two constraint plug-ins (`ModelPath`, `ModelRatePath`:
rows that read a control's rate u̇ = (du/dσ) / (dt/dσ) are imposed once per one-sided slope, like a robot's
torque rate).

Every expression of the `Ocp` is turned once into a CasADi Function of the scaled symbols, so the transcription
calls it at each point; no check points are lifted between knots (`check_parts` = 0): the dense certificate
(ocpkit.ocp.certify) looks there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint, Context, Rows
from ocpkit.errors import OptionError
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.ocp.model import Ocp, Row
from ocpkit.problem import Problem
from ocpkit.transcription.ocp import OCP, Node, PointFunction


@dataclass(frozen=True)
class ModelPoint:
    """Scaled values at one point: x̃ (states + parameters, 1), ũ (controls, 1), du/dσ (controls, 1), dt/dσ and the
    time since the start (s)."""

    x: ca.SX
    u: ca.SX
    du_ds: ca.SX
    dt_ds: ca.SX
    t: ca.SX


class ModelPath(Constraint):
    """The Ocp's path rows that read no rate: lower ≤ h(x, u, p, t) ≤ upper at every point."""

    name = "path"

    def __init__(self, function: ca.Function, lower: np.ndarray, upper: np.ndarray) -> None:
        self.function, self.lower, self.upper = function, lower, upper

    def shape(self) -> tuple:
        return (self.function.name(), len(self.lower))

    def evaluate(self, point: ModelPoint, context: Context) -> Rows:
        return Rows(self.function(point.x, point.u, point.du_ds / point.dt_ds, point.t), self.lower, self.upper)


class ModelRatePath(ModelPath):
    """The Ocp's path rows that read a control's rate u̇, once per one-sided slope where it jumps."""

    name = "rate-path"
    reads_rate = True


class ModelOCP(OCP):
    """The transcriptions' view of an `Ocp` (module docstring)."""

    check_parts = 0
    knot_bounds = False
    extrapolated_controls = True

    def __init__(self, model: Ocp) -> None:
        model.check()
        self.model = model
        held = [*model.states, *model.parameters]
        self.states, self.controls = sum(v.size for v in held), sum(v.size for v in model.controls)
        self.parts = tuple((v.name, v.size) for v in (*held, *model.controls))
        self.ends = self.states
        self.x_scale = np.concatenate([v.scale for v in held])
        self.u_scale = np.concatenate([v.scale for v in model.controls]) if model.controls else np.zeros(0)
        # the transcription's time runs from 0 and its t_f is the duration T − t0: t = t0 + t_rel, T = t0 + D
        X, U, R, T, t = (ca.SX.sym("X", self.states), ca.SX.sym("U", self.controls),
                         ca.SX.sym("R", self.controls), ca.SX.sym("D"), ca.SX.sym("t_rel"))
        real = [ca.vertcat(*(v.symbol for v in held)), ca.vertcat(*(v.symbol for v in model.controls)),
                ca.vertcat(*(model.rate(v.symbol) for v in model.controls))]
        scaled = [ca.DM(self.x_scale) * X, ca.DM(self.u_scale) * U, ca.DM(self.u_scale) * R]
        clock = [model.t, model.T], [model.t0 + t, model.t0 + T]  # t0 is a parameter's symbol when free: two steps
        own = lambda expr: ca.substitute([ca.substitute([ca.SX(expr)], *clock)[0]], real, scaled)[0]  # noqa: E731

        rhs = ca.vertcat(*(model.derivatives[v.name] for v in model.states), ca.SX.zeros(self.states - sum(
            v.size for v in model.states)))
        self._maps: dict[int, ca.Function] = {}
        self._f = self._function("dynamics", [X, U, t], own(rhs) / ca.DM(self.x_scale), "set_der", [R, T])
        rows = lambda found: ca.vertcat(*(own(r.expr) for r in found))  # noqa: E731
        bounds = lambda found: (np.concatenate([r.lower for r in found] or [np.zeros(0)]),  # noqa: E731
                                np.concatenate([r.upper for r in found] or [np.zeros(0)]))
        plain = [r for r in model.path if not ca.depends_on(own(r.expr), R)]
        rated = [r for r in model.path if ca.depends_on(own(r.expr), R)]
        self.constraints: list[Constraint] = [
            kind(self._function(kind.name.replace("-", "_"), [X, U, R, t], rows(found), "subject_to", [T]),
                 *bounds(found))
            for kind, found in ((ModelPath, plain), (ModelRatePath, rated)) if found]
        self._running = self._function("running", [X, U, R, t], own(model.lagrange), "minimize_integral", [T])
        self._mayer = self._function("mayer", [X, T], own(model.mayer), "minimize_end", [U, R, t])
        self._start = self._function("start", [X], rows(model.start), "at_start", [U, R, T, t])
        ends = model.end + self._final_time_rows()
        self._end = self._function("end", [X, T], rows(ends), "at_end", [U, R, t])
        self._start_bounds, self._end_bounds = bounds(model.start), bounds(ends)

    def _final_time_rows(self) -> list[Row]:
        """With a free initial time, T = t0 + D within its bounds as an end row (else the bounds of D say it)."""
        model = self.model
        if model.t0_bounds[0] == model.t0_bounds[1]:
            return []
        lower, upper = (model.T_fixed,) * 2 if model.T_fixed is not None else model.T_bounds
        return [Row(ca.SX(model.T), np.array([lower]), np.array([upper]))]

    def _function(self, name: str, inputs: list[ca.SX], output: ca.SX, what: str, barred: list[ca.SX]) -> ca.Function:
        """ca.Function of `inputs`; OptionError naming the Ocp call `what` if `output` reads a `barred` symbol or one
        the Ocp never declared."""
        if any(ca.depends_on(output, symbol) for symbol in barred if symbol.numel()):
            raise OptionError(f"{self.model.name}: {what} reads a symbol it cannot (states, controls, rates, "
                              "parameters, t and T each have their place: see ocpkit.ocp.model)")
        try:
            return ca.Function(name, inputs, [output])
        except RuntimeError as exc:
            raise OptionError(f"{self.model.name}: {what} reads a symbol that is not a declared state, control, "
                              f"parameter, t or T: {str(exc).splitlines()[-1]}") from None

    @property
    def key(self) -> tuple:
        return "model", self.model.name, id(self.model)

    def rate(self, x: Node, t: Any) -> Any:
        if isinstance(x.x, np.ndarray):
            times = np.broadcast_to(np.asarray(t, dtype=float).ravel(), (len(x.x),))[None, :]
            if len(x.x) not in self._maps:  # f over that many nodes at once, made once
                self._maps[len(x.x)] = self._f.map(len(x.x))
            return np.asarray(self._maps[len(x.x)](x.x.T, x.u.T, times)).T.reshape(x.x.shape)
        return self._f(x.x, x.u, t)

    def point_values(self, dynamics: Any) -> PointFunction:
        return lambda x, du_ds, dt_ds, t: ModelPoint(x.x, x.u, du_ds, dt_ds, t)

    def running(self, x: Node, du_ds: ca.SX, dt_ds: ca.SX, t: ca.SX) -> ca.SX:
        return self._running(x.x, x.u, du_ds / dt_ds, t)

    def mayer_inputs(self, start: Node, goal: Node) -> list[ca.SX]:
        return [goal.x]

    def mayer(self, tf: ca.SX, inputs: Sequence[ca.SX], parameters: Sequence[ca.SX]) -> ca.SX:
        return self._mayer(inputs[0], tf)

    def lagrange(self, runs: ca.SX, weights: np.ndarray, tf: ca.SX, per_tf: float,
                 parameters: Sequence[ca.SX]) -> ca.SX:
        """(t_f / per_tf) Σ w L: dt = (t_f / per_tf) dσ."""
        return (tf / per_tf) * ca.dot(ca.DM(weights), runs)

    def boundary(self, a: Any, start: Node, goal: Node, tf: ca.SX) -> None:
        """The Ocp's `at_start` and `at_end` rows."""
        for expr, (lower, upper) in ((self._start(start.x), self._start_bounds),
                                     (self._end(goal.x, tf), self._end_bounds)):
            if expr.numel():
                a.add(Rows(expr, lower, upper))

    def time_bounds(self, problem: Problem | None) -> tuple[float, float]:
        """(lower, upper) of the duration T − t0 (s), the transcription's t_f."""
        model, (first, last) = self.model, self.model.t0_bounds
        lower, upper = (model.T_fixed,) * 2 if model.T_fixed is not None else model.T_bounds
        return max(lower - last, 0.0), upper - first

    def end_bounds(self, problem: Problem | None) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        """Fixed start and end values where given, the variables' bounds elsewhere (scaled)."""
        held = [*self.model.states, *self.model.parameters]
        ends = []
        for fixed in (lambda v: v.start, lambda v: v.end):
            lower = np.concatenate([np.where(np.isnan(fixed(v)), v.lower, fixed(v)) / v.scale for v in held])
            upper = np.concatenate([np.where(np.isnan(fixed(v)), v.upper, fixed(v)) / v.scale for v in held])
            ends.append((lower, upper))
        return tuple(ends)

    def chain_bounds(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        return {v.name: (v.lower / v.scale, v.upper / v.scale) for v in self.model.variables}

    def guess(self, problem: Problem | None) -> Trajectory:
        """Each state on the line from its start to its end value (fixed ones, else its guess) over the guessed
        duration, or its guess function of τ = (t − t0)/(T − t0); the parameters and controls at their guesses
        (scaled)."""
        model = self.model
        T, held = model.T_guess - model.t0_guess, [*model.states, *model.parameters]

        def values(variables: list, t: np.ndarray) -> np.ndarray:
            columns = [v.guess_at(t / T) / v.scale for v in variables]
            return np.hstack(columns) if columns else np.zeros((len(t), 0))

        def line(t: np.ndarray) -> Samples:
            t = np.asarray(t, dtype=float)
            controls = values(model.controls, t)
            return self.chain_samples(t, Node(values(held, t), controls), np.zeros_like(controls))

        return Trajectory(line(np.array([0.0, T])), line)

    def columns(self, chain: Samples) -> np.ndarray:
        return np.hstack([chain.q, chain.tau])

    def chain_samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        """x̃ as the Samples' q, its rate f as qd, ũ as tau and dũ/dt as taud (qdd zeros)."""
        t = np.asarray(t, dtype=float)
        return Samples(t, x.x, self.rate(x, t), np.zeros_like(x.x), x.u, du_dt)

    def samples(self, t: np.ndarray, x: Node, du_dt: np.ndarray) -> Samples:
        return self.chain_samples(t, x, du_dt)
