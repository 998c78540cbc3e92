"""Certify a solved `Ocp` densely: re-integrate ẋ = f(x, u, p, t) from the solution's start with its own control
u(t) (SciPy's `solve_ivp`, LSODA: it switches to a stiff method where the problem is stiff), and check every
bound, path row and end row on a grid. The right-hand side is made here from the `Ocp`'s own expressions in the
user's units, apart from the transcription's scaled NLP.

`certify` checks an ocpkit `Solution` on a dense grid with its transcription's control interpolant;
`certify_peer` checks a rockit solution (ocpkit.ocp.rockit_peer) on its own grid with its piecewise-constant
controls held between grid points. The tolerances (`STATE_TOLERANCE`, `PATH_TOLERANCE`) are relative to each
value's own size: a discretization reproduces a smooth solution far better than a bang-bang one, whose control
an interpolating polynomial smears, and the certificate reports the figures either way.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from ocpkit.ocp.model import Ocp, columns, stacked
from ocpkit.ocp.rockit_peer import PeerResult
from ocpkit.ocp.solve import Solution

STATE_TOLERANCE = 1e-3
"""Largest re-integration error of a state accepted, relative to 1 + its largest magnitude on the solution."""
PATH_TOLERANCE = 1e-3
"""Largest excess of a bound, path or end row accepted, relative to 1 + the bound's magnitude."""
POINTS = 2001
"""Points of the dense grid on [0, t_f]."""


@dataclass(frozen=True)
class Certificate:
    """The check of one solution: the largest re-integration error of any state (relative, see STATE_TOLERANCE)
    and its absolute value, the largest relative excess of any bound, path or end row (`worst` names it), and
    whether both are within tolerance."""

    state_error: float
    state_error_abs: float
    excess: float
    worst: str
    passed: bool


def certify(solution: Solution, points: int = POINTS) -> Certificate:
    """The certificate of an ocpkit `solution` on `points` times in [0, t_f]."""
    t = np.linspace(solution.t0, solution.T, points)
    x, u, du = solution.sample(t)
    return check(solution.model, t, x, u, du, lambda time: solution.sample(np.array([time]))[1][0])


def certify_peer(model: Ocp, peer: PeerResult) -> Certificate:
    """The certificate of rockit's solution of `model` on its control grid, its controls held on each interval."""
    t = peer.t
    x = np.hstack([peer.x, np.tile(peer.parameters, (len(t), 1))])
    du = np.gradient(peer.u, t, axis=0) if len(t) > 1 else np.zeros_like(peer.u)

    def held(time: float) -> np.ndarray:
        return peer.u[min(int(np.searchsorted(t, time, side="right")) - 1, len(t) - 1)]

    return check(model, t, x, peer.u, du, held)


def check(model: Ocp, t: np.ndarray, x: np.ndarray, u: np.ndarray, du: np.ndarray,
          control: Callable[[float], np.ndarray], rtol: float = 1e-10, atol: float = 1e-10) -> Certificate:
    """The certificate of a solution of `model` given at times t (points,) as x (points, states + parameters), u and
    u̇ (points, controls), with `control` its control at any time (user units)."""
    held = [*model.states, *model.parameters]
    rate = ca.Function("rate", [stacked([v.symbol for v in held]), stacked([v.symbol for v in model.controls]),
                                model.t], [ca.vertcat(
        *(model.derivatives[v.name] for v in model.states), ca.DM.zeros(sum(v.size for v in model.parameters)))])
    rhs = lambda time, state: np.asarray(rate(state, control(time), time)).ravel()  # noqa: E731
    integrated = solve_ivp(rhs, (t[0], t[-1]), x[0], method="LSODA", t_eval=t, rtol=rtol, atol=atol)
    error = np.abs(integrated.y.T - x) if integrated.success else np.full_like(x, np.inf)
    state_error = float(np.max(error / (1.0 + np.max(np.abs(x), axis=0))))

    values = {**columns(held, x), **columns(model.controls, u)}
    excesses = {f"bound of {v.name}": _excess(values[v.name], v.lower, v.upper) for v in model.variables}
    real = [v.symbol for v in model.variables]
    rates = [model.rate(v.symbol) for v in model.controls]
    arguments = [values[v.name] for v in model.variables] + list(columns(model.controls, du).values())
    for number, row in enumerate(model.path):
        function = ca.Function("row", [*real, *rates, model.t], [row.expr])
        rows = np.asarray(function.map(len(t))(*(a.T for a in arguments), t[None, :])).T
        excesses[f"path row {number}"] = _excess(rows, row.lower, row.upper)
    for where, rows, index in (("at_start", model.start, 0), ("at_end", model.end, -1)):
        for number, row in enumerate(rows):
            function = ca.Function("row", [*real, model.T], [row.expr])
            value = np.asarray(function(*(a[index] for a in arguments[:len(real)]), t[-1])).ravel()
            excesses[f"{where} row {number}"] = _excess(value[None, :], row.lower, row.upper)
    worst = max(excesses, key=excesses.get)
    return Certificate(state_error, float(np.max(error)), excesses[worst], worst,
                       state_error <= STATE_TOLERANCE and excesses[worst] <= PATH_TOLERANCE)


def _excess(values: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> float:
    """The largest relative excess of `values` (points, k) over [lower, upper] (k,), 0 inside."""
    with np.errstate(invalid="ignore"):
        below = np.where(np.isfinite(lower), (lower - values) / (1.0 + np.abs(lower)), 0.0)
        above = np.where(np.isfinite(upper), (values - upper) / (1.0 + np.abs(upper)), 0.0)
    return float(max(np.max(below, initial=0.0), np.max(above, initial=0.0)))
