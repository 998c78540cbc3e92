"""Solve an `Ocp` with rockit (KU Leuven MECO, `pip install rockit-meco`), an independent peer to check ocpkit's
own transcriptions against.

The translation, one `Ocp` declaration to rockit's (rockit's variables are MX; the `Ocp`'s SX expressions are
wrapped in a `casadi.Function` of (x, u, p, T, u̇, t) and called on rockit's symbols):

- a state, control or parameter → rockit `state`, `control` (piecewise constant) or `variable` (one optimized
  value), of the same size and scale; a control whose rate `ocp.rate(u)` is used → a rockit state whose derivative
  is a new piecewise-constant control, the rate (rockit's own `control(order=1)`);
- bounds and `subject_to` rows → path constraints on rockit's control grid, at t_f only where they involve no
  control (`include_last="auto"`: rockit's controls have no value there);
- fixed start and end values, `at_start` and `at_end` rows → `at_t0`, `at_tf`; `minimize_end` → `at_tf`,
  `minimize_integral` → `integral` (rockit's integrator: RK4 for multiple shooting, the collocation polynomial for
  direct collocation);
- free T → `FreeTime(T_guess)`, `T_bounds` as constraints; guesses → `set_initial`, the same as
  ocpkit's (`Variable.guess_at`).

IPOPT solves the NLP, silent; a failed solve is returned with IPOPT's status, not raised.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.errors import OptionError
from ocpkit.ocp.model import Ocp, stacked

METHODS = ("multiple-shooting", "direct-collocation")
IPOPT_OPTIONS = {"expand": True, "print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes"}


@dataclass(frozen=True)
class PeerResult:
    """rockit's solution: the objective as the `Ocp` states it, t_f (s), IPOPT's return status ("Solve_Succeeded"
    when converged) and iteration count, the wall time of `solve` (s, transcription included), and the solution on
    rockit's control grid: t (points,), x (points, n_x), u (points, n_u; the last interval's value repeated at t_f),
    parameters (n_p,). Columns follow the declaration order, vector variables flattened."""

    objective: float
    T: float
    status: str
    iterations: int
    wall_time: float
    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    parameters: np.ndarray

    @property
    def success(self) -> bool:
        return self.status == "Solve_Succeeded"


def solve_with_rockit(ocp: Ocp, method: str = "multiple-shooting", intervals: int = 50) -> PeerResult:
    """Solve `ocp` with rockit's `method` ("multiple-shooting": one RK4 step per interval; "direct-collocation":
    Radau, degree 4) on `intervals` uniform control intervals (module docstring for the translation)."""
    if ocp.t0_bounds != (0.0, 0.0):
        raise OptionError(f"{ocp.name}: the rockit peer translates problems that start at t = 0 only")
    if method not in METHODS:
        raise OptionError(f"{ocp.name}: unknown rockit method {method!r}; known: {', '.join(METHODS)}")
    if intervals < 1:
        raise OptionError(f"{ocp.name}: intervals must be ≥ 1, got {intervals}")
    try:
        import rockit
    except ImportError as exc:
        raise OptionError("rockit is not installed: pip install ocpkit[peers]") from exc
    ocp.check()
    peer = rockit.Ocp(T=ocp.T_fixed if ocp.T_fixed is not None else rockit.FreeTime(ocp.T_guess))
    states = [peer.state(v.size, scale=_column(v.scale)) for v in ocp.states]
    controls, rates = [], []
    for v in ocp.controls:
        if v.name in ocp.rates:
            controls.append(peer.state(v.size, scale=_column(v.scale)))
            rates.append(peer.control(v.size))
            peer.set_der(controls[-1], rates[-1])
        else:
            controls.append(peer.control(v.size, scale=_column(v.scale)))
    parameters = [peer.variable(v.size, scale=_column(v.scale)) for v in ocp.parameters]
    call = _caller(ocp, states, controls, parameters, peer.T, rates, peer.t)

    rhs, offset = call(ca.vertcat(*(ocp.derivatives[v.name] for v in ocp.states))), 0
    for variable, symbol in zip(ocp.states, states):
        peer.set_der(symbol, rhs[offset:offset + variable.size])
        offset += variable.size
    for variables, symbols in ((ocp.states, states), (ocp.controls, controls)):
        for variable, symbol in zip(variables, symbols):
            _bound(peer.subject_to, symbol, variable.lower, variable.upper, include_last="auto")
            peer.set_initial(symbol, _initial(variable, peer.t / ocp.T_guess))
    for variable, symbol in zip(ocp.parameters, parameters):
        _bound(peer.subject_to, symbol, variable.lower, variable.upper)
        peer.set_initial(symbol, _column(variable.guess))
    for row in ocp.path:
        _bound(peer.subject_to, call(row.expr), row.lower, row.upper, include_last="auto")
    for variable, symbol in zip(ocp.states, states):
        _fix(peer.subject_to, peer.at_t0(symbol), variable.start)
        _fix(peer.subject_to, peer.at_tf(symbol), variable.end)
    for rows, at in ((ocp.start, peer.at_t0), (ocp.end, peer.at_tf)):
        for row in rows:
            _bound(peer.subject_to, at(call(row.expr)), row.lower, row.upper)
    if ocp.T_fixed is None:
        _bound(peer.subject_to, peer.T, np.array(ocp.T_bounds[:1]), np.array(ocp.T_bounds[1:]))

    terms = [at(call(expr)) for expr, at in ((ocp.mayer, peer.at_tf), (ocp.lagrange, peer.integral))
             if not expr.is_zero()]
    objective = sum(terms[1:], terms[0]) if terms else ca.MX(0)
    peer.add_objective(objective)
    peer.solver("ipopt", IPOPT_OPTIONS)
    peer.method(rockit.MultipleShooting(N=intervals) if method == "multiple-shooting"
                else rockit.DirectCollocation(N=intervals))

    start = time.perf_counter()
    try:
        solution = peer.solve()
    except RuntimeError:  # IPOPT did not converge: keep its last iterate and status
        solution = peer.non_converged_solution
    wall_time = time.perf_counter() - start
    t, x = _sample(solution, states)
    u = _sample(solution, controls)[1] if controls else np.zeros((len(t), 0))
    values = [np.ravel(solution.value(p)) for p in parameters]
    stats = solution.stats
    return PeerResult(objective=float(solution.value(objective)), T=float(solution.value(peer.T)),
                      status=str(stats["return_status"]), iterations=int(stats["iter_count"]),
                      wall_time=wall_time, t=t, x=x, u=u,
                      parameters=np.concatenate(values).astype(float) if values else np.zeros(0))


def _caller(ocp: Ocp, states: list, controls: list, parameters: list, T: ca.MX, rates: list, t: ca.MX):
    """A function: expr (SX of the `Ocp`'s symbols) → the same expression on rockit's MX symbols."""
    rate_symbols = [ocp.rates[v.name] for v in ocp.controls if v.name in ocp.rates]
    sx = [stacked([v.symbol for v in family]) for family in (ocp.states, ocp.controls, ocp.parameters)]
    sx += [ocp.T, stacked(rate_symbols), ocp.t]
    mx = [ca.vertcat(*family) if family else ca.MX(0, 1) for family in (states, controls, parameters)]
    mx += [T, ca.vertcat(*rates) if rates else ca.MX(0, 1), t]

    def call(expr: ca.SX) -> ca.MX:  # over the arguments expr uses only: a Function call depends on all its inputs
        used = [i for i, symbol in enumerate(sx) if symbol.numel() and ca.depends_on(expr, symbol)]
        return ca.Function("expr", [sx[i] for i in used], [expr])(*(mx[i] for i in used))
    return call


def _initial(variable, tau: ca.MX) -> ca.MX:
    """ocpkit's guess of `variable` (`Variable.guess_at`) as an expression of rockit's τ = t/T_guess: a piecewise
    linear table (rockit's numeric initial values fail for direct collocation)."""
    grid = np.linspace(0.0, 1.0, 101)
    table = ca.interpolant(f"guess_{variable.name}", "linear", [grid], variable.guess_at(grid).ravel())
    return table(tau)


def _column(values: np.ndarray) -> ca.DM:
    return ca.DM(np.asarray(values, dtype=float).reshape(-1, 1))


def _bound(subject_to, expr: ca.MX, lower: np.ndarray, upper: np.ndarray, **options) -> None:
    """lower ≤ expr ≤ upper for the finite sides, as equalities where lower = upper, one constraint per kind."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    low, high = np.isfinite(lower), np.isfinite(upper)
    kinds = {"equal": low & high & (lower == upper), "both": low & high & (lower != upper),
             "lower": low & ~high, "upper": ~low & high}
    for kind, mask in kinds.items():
        index = np.flatnonzero(mask).tolist()
        if not index:
            continue
        part, lo, hi = expr[index], _column(lower[index]), _column(upper[index])
        if kind == "equal":
            subject_to(part == lo, **options)
        elif kind == "both":
            subject_to(lo <= (part <= hi), **options)
        elif kind == "lower":
            subject_to(part >= lo, **options)
        else:
            subject_to(part <= hi, **options)


def _fix(subject_to, expr: ca.MX, values: np.ndarray) -> None:
    """expr == values where values are not NaN (a fixed start or end)."""
    index = np.flatnonzero(~np.isnan(values)).tolist()
    if index:
        subject_to(expr[index] == _column(values[index]))


def _sample(solution, symbols: list) -> tuple[np.ndarray, np.ndarray]:
    """(t (points,), values (points, total size)) of declared symbols on rockit's control grid."""
    t, values = solution.sample(ca.vertcat(*symbols), grid="control")
    t = np.asarray(t, dtype=float)
    return t, np.asarray(values, dtype=float).reshape(len(t), -1)

