"""Certify a solved `Ocp` densely: re-integrate ẋ = f(x, u, p) from the solution's start with its own control
interpolant u(t) (SciPy's `solve_ivp`, Radau: stiff-capable), and check every bound and path row on a dense grid.

The tolerances (`STATE_TOLERANCE`, `PATH_TOLERANCE`) are relative to each value's own size: a discretization
reproduces a smooth solution far better, a bang-bang one (whose control the interpolant smears) worse, and the
certificate reports the figures either way.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from ocpkit.ocp.solve import Solution

STATE_TOLERANCE = 1e-3
"""Largest re-integration error of a state accepted, relative to 1 + its largest magnitude on the solution."""
PATH_TOLERANCE = 1e-3
"""Largest excess of a bound or path row accepted, relative to 1 + the bound's magnitude."""
POINTS = 2001
"""Points of the dense grid on [0, t_f]."""


@dataclass(frozen=True)
class Certificate:
    """The dense check of one solution: the largest re-integration error of any state (relative, see
    STATE_TOLERANCE) and its absolute value, the largest relative excess of any bound, path or end row, and
    whether both are within tolerance."""

    state_error: float
    state_error_abs: float
    excess: float
    worst: str
    passed: bool


def certify(solution: Solution, points: int = POINTS, rtol: float = 1e-10, atol: float = 1e-10) -> Certificate:
    """The certificate of `solution` (module docstring) on `points` times in [0, t_f]."""
    model, ocp, T = solution.model, solution.ocp, solution.T
    t = np.linspace(0.0, T, points)
    x, u, du = solution.sample(t)
    scale = ocp.x_scale
    f = ocp.rate
    interpolant = solution.trajectory.interpolant

    def rhs(time: float, state: np.ndarray) -> np.ndarray:
        controls = interpolant(np.array([min(max(time, 0.0), T)])).tau
        return f(ocp.split(np.hstack([state[None, :] / scale, controls])))[0] * scale

    integrated = solve_ivp(rhs, (0.0, T), x[0], method="Radau", t_eval=t, rtol=rtol, atol=atol)
    error = np.abs(integrated.y.T - x) if integrated.success else np.full_like(x, np.inf)
    size = 1.0 + np.max(np.abs(x), axis=0)
    state_error = float(np.max(error / size)) if error.size else 0.0

    excesses = {f"bound of {v.name}": _excess(values, v.lower, v.upper)
                for v, values in zip(model.variables, _split(model, x, u))}
    real = [v.symbol for v in model.variables]
    rates = [model.rate(v.symbol) for v in model.controls]
    values = [*_split(model, x, u), *(du[:, _columns(model.controls, v)] for v in model.controls)]
    for number, row in enumerate(model.path):
        function = ca.Function("row", [*real, *rates], [row.expr])
        rows = np.asarray(function.map(points)(*(v.T for v in values))).T
        excesses[f"path row {number}"] = _excess(rows, row.lower, row.upper)
    for where, rows, index in (("at_start", model.start, 0), ("at_end", model.end, -1)):
        for number, row in enumerate(rows):
            function = ca.Function("row", [*real, model.T], [row.expr])
            value = np.asarray(function(*(v[index] for v in values[:len(real)]), T)).ravel()
            excesses[f"{where} row {number}"] = _excess(value[None, :], row.lower, row.upper)
    worst = max(excesses, key=excesses.get) if excesses else ""
    excess = excesses.get(worst, 0.0)
    return Certificate(state_error, float(np.max(error)) if error.size else 0.0, excess, worst,
                       state_error <= STATE_TOLERANCE and excess <= PATH_TOLERANCE)


def _excess(values: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> float:
    """The largest relative excess of `values` (points, k) over [lower, upper] (k,), 0 inside."""
    values = np.atleast_2d(values.T).T if values.ndim == 1 else values
    with np.errstate(invalid="ignore"):
        below = np.where(np.isfinite(lower), (lower - values) / (1.0 + np.abs(lower)), 0.0)
        above = np.where(np.isfinite(upper), (values - upper) / (1.0 + np.abs(upper)), 0.0)
    return float(max(np.max(below, initial=0.0), np.max(above, initial=0.0)))


def _columns(family: list, variable) -> slice:
    start = 0
    for other in family:
        if other is variable:
            return slice(start, start + variable.size)
        start += other.size
    raise KeyError(variable.name)


def _split(model, x: np.ndarray, u: np.ndarray) -> list[np.ndarray]:
    """Each variable's values (points, size) in `model.variables` order, from x (states, then parameters) and u."""
    held = [*model.states, *model.parameters]
    return [x[:, _columns(held, v)] for v in held[:len(model.states)]] + \
        [u[:, _columns(model.controls, v)] for v in model.controls] + \
        [x[:, _columns(held, v)] for v in model.parameters]
