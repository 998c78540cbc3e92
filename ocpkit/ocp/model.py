"""The public description of an optimal control problem: `Ocp`, on CasADi symbols (in the spirit of rockit's
`Ocp`, smaller).

    minimize    Φ(x(t_f), p, t_f) + ∫ L(x, u, u̇, p, t) dt  (`minimize_end`, `minimize_integral`)
    subject to  ẋ = f(x, u, p, t)                           (`set_der`, one per state)
                lower ≤ h(x, u, u̇, p, t) ≤ upper  on [0, t_f] (`subject_to`; bounds of `state`, `control`)
                lower ≤ b(x(0), p) ≤ upper,  lower ≤ e(x(t_f), p, t_f) ≤ upper   (`at_start`, `at_end`)
                t_f fixed (`Ocp(T=...)`) or free within bounds

States, controls and parameters are column symbols; `ocp.rate(u)` is u̇, readable in path constraints and the
running cost; `ocp.t` is the time, readable in the dynamics, the path and the running cost; `ocp.T` is t_f,
readable at the end. The initial time is 0. Units are the user's. Nothing here discretizes: `solve`
(ocpkit.ocp.solve) hands the problem to a transcription.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.errors import OptionError

INF = float("inf")
Guess = float | list | Callable[[np.ndarray], np.ndarray] | None
"""A variable's guess: a value (one or `size` numbers), a function of τ = t/t_f ∈ [0, 1], or None (a default)."""
RESERVED = re.compile(r"(X|M|E|tf|t0|start|goal|check_at|mu|margin|limit_scale|(knot|mid|end|tf)\d+)")
"""Names the transcriptions give parts of the NLP's vectors themselves."""


@dataclass(frozen=True)
class Variable:
    """One declared state, control or parameter: its symbol (size, 1), bounds (size,), guess (size,) or a function
    of τ = t/t_f, scale (size,)
    (the transcription's variable is the value divided by it), fixed values at the start and end (NaN: free)."""

    name: str
    symbol: ca.SX
    lower: np.ndarray
    upper: np.ndarray
    guess: np.ndarray | Callable[[np.ndarray], np.ndarray]
    scale: np.ndarray
    start: np.ndarray
    end: np.ndarray

    @property
    def size(self) -> int:
        return self.symbol.numel()

    def guess_at(self, tau: np.ndarray) -> np.ndarray:
        """The guess (points, size) at normalized times τ = t/t_f (points,): the guess function, or the line from
        the start to the end value where they are fixed (the constant guess elsewhere)."""
        tau = np.asarray(tau, dtype=float)
        if callable(self.guess):
            return np.asarray(self.guess(tau), dtype=float).reshape(len(tau), self.size)
        first, last = (np.where(np.isnan(fixed), self.guess, fixed) for fixed in (self.start, self.end))
        return first + np.outer(tau, last - first)


@dataclass(frozen=True)
class Row:
    """lower ≤ expr ≤ upper, expr a column (k, 1), bounds (k,)."""

    expr: ca.SX
    lower: np.ndarray
    upper: np.ndarray


class Ocp:
    """An optimal control problem under construction (module docstring). `T` fixes t_f (s); without it t_f is
    free in `T_bounds` and starts from `T_guess`. `t0` is the initial time (s): a number, or (lower, upper) for a
    free one, then the parameter "t0" (its guess `t0_guess`, else the middle of its bounds)."""

    def __init__(self, T: float | None = None, T_bounds: tuple[float, float] = (0.0, INF), T_guess: float | None = None,
                 name: str = "ocp", t0: float | tuple[float, float] = 0.0, t0_guess: float | None = None) -> None:
        if T is not None and not T > 0:
            raise OptionError(f"{name}: T must be > 0 (s), got {T}")
        lower, upper = map(float, T_bounds)
        if not 0 <= lower < upper:
            raise OptionError(f"{name}: T_bounds must satisfy 0 ≤ lower < upper, got {T_bounds}")
        self.T_fixed, self.T_bounds, self.name = T, (lower, upper), name
        self.T_guess = float(T if T is not None else T_guess if T_guess is not None else
                             (lower + upper) / 2 if np.isfinite(upper) else max(lower, 1.0))
        self.states, self.controls, self.parameters = [], [], []
        self.derivatives, self.path, self.start, self.end = {}, [], [], []
        self.mayer, self.lagrange = ca.SX(0), ca.SX(0)
        self._T = ca.SX.sym("T")
        self._t = ca.SX.sym("t")
        self._rates: dict[str, ca.SX] = {}
        self.t0_bounds = _t0_bounds(t0, name)
        free = self.t0_bounds[0] < self.t0_bounds[1]
        self._t0 = self._declare(self.parameters, "t0", 1, *self.t0_bounds, None, None, t0_guess, 1.0) if free \
            else ca.SX(self.t0_bounds[0])
        self.t0_guess = float(t0_guess if t0_guess is not None else np.mean(self.t0_bounds))
        if not self.T_guess > self.t0_guess:
            raise OptionError(f"{name}: T_guess must be after t0's guess, got {self.T_guess} and {self.t0_guess}")

    # -- declarations ----------------------------------------------------------------------------------
    def state(self, name: str, size: int = 1, lower: float | list = -INF, upper: float | list = INF,
              start: float | list | None = None, end: float | list | None = None, guess: Guess = None,
              scale: float | list = 1.0) -> ca.SX:
        """A state x (size, 1) with bounds on [0, t_f], optional fixed values at the start and the end, a guess
        (a value, or a function of the normalized time τ = t/t_f (points,) ↦ (points,) or (points, size); by
        default the line from the start to the end value where they are fixed, else the middle of finite bounds,
        else 0) and a scale."""
        return self._declare(self.states, self._free(name), size, lower, upper, start, end, guess, scale)

    def control(self, name: str, size: int = 1, lower: float | list = -INF, upper: float | list = INF,
                guess: Guess = None, scale: float | list = 1.0) -> ca.SX:
        """A control u (size, 1) with bounds, guess and scale; the transcription interpolates it as its own
        polynomial, so `rate(u)` is defined."""
        return self._declare(self.controls, self._free(name), size, lower, upper, None, None, guess, scale)

    def parameter(self, name: str, size: int = 1, lower: float | list = -INF, upper: float | list = INF,
                  guess: float | list | None = None, scale: float | list = 1.0) -> ca.SX:
        """A parameter p (size, 1), constant in time and optimized within its bounds."""
        return self._declare(self.parameters, self._free(name), size, lower, upper, None, None, guess, scale)

    def _free(self, name: str) -> str:
        """`name` if a user's variable may have it; OptionError otherwise."""
        if not name.isidentifier() or RESERVED.fullmatch(name):
            raise OptionError(f"{self.name}: {name!r} cannot name a variable (an identifier, not one of the NLP's "
                              "own names X, M, E, tf, t0, start, goal, knot0, ...)")
        return name

    def _declare(self, family: list[Variable], name: str, size: int, lower, upper, start, end, guess,
                 scale) -> ca.SX:
        if name in {v.name for v in self.variables}:
            raise OptionError(f"{self.name}: a variable named {name!r} is already declared")
        if size < 1:
            raise OptionError(f"{self.name}: {name}: size must be ≥ 1, got {size}")
        vector = lambda value, what: _vector(value, size, f"{self.name}: {name}.{what}")  # noqa: E731
        lo, hi, sc = vector(lower, "lower"), vector(upper, "upper"), vector(scale, "scale")
        if np.any(lo > hi):
            raise OptionError(f"{self.name}: {name}: lower > upper")
        if np.any(sc <= 0):
            raise OptionError(f"{self.name}: {name}.scale must be > 0")
        fixed = [np.full(size, np.nan) if v is None else vector(v, what) for v, what in ((start, "start"),
                                                                                      (end, "end"))]
        if callable(guess):
            guess_value = guess
        elif guess is None:
            known = [v for v in fixed if not np.any(np.isnan(v))]
            finite = np.isfinite(lo) & np.isfinite(hi)
            middle = np.where(finite, (np.where(finite, lo, 0) + np.where(finite, hi, 0)) / 2, np.clip(0.0, lo, hi))
            guess_value = np.mean(known, axis=0) if known else middle
        else:
            guess_value = vector(guess, "guess")
        variable = Variable(name, ca.SX.sym(name, size), lo, hi, guess_value, sc, *fixed)
        family.append(variable)
        return variable.symbol

    @property
    def variables(self) -> list[Variable]:
        return [*self.states, *self.controls, *self.parameters]

    @property
    def t0(self) -> ca.SX:
        """The initial time (s): the parameter "t0" when free, else its value; readable wherever `T` is."""
        return self._t0

    @property
    def t(self) -> ca.SX:
        """Time t ∈ [0, t_f] (s) as a symbol, for `set_der`, `subject_to` and `minimize_integral`."""
        return self._t

    @property
    def T(self) -> ca.SX:
        """t_f (s) as a symbol, for `at_end` and `minimize_end` (fixed or free)."""
        return self._T

    @property
    def rates(self) -> dict[str, ca.SX]:
        """Control name → the symbol of its rate, for the controls whose `rate` was asked for."""
        return dict(self._rates)

    def rate(self, control: ca.SX) -> ca.SX:
        """u̇ of a declared control, as a symbol for `subject_to` and `minimize_integral`."""
        variable = self._find(control, self.controls, "rate() takes a declared control")
        if variable.name not in self._rates:
            self._rates[variable.name] = ca.SX.sym(f"d{variable.name}", variable.size)
        return self._rates[variable.name]

    def set_der(self, state: ca.SX, rhs: ca.SX | float) -> None:
        """ẋ = rhs for a declared state (rhs: expression of states, controls, parameters and `t`; same size)."""
        variable = self._find(state, self.states, "set_der() takes a declared state")
        rhs = ca.SX(rhs) if not isinstance(rhs, ca.SX) else rhs
        if rhs.numel() != variable.size:
            raise OptionError(f"{self.name}: der({variable.name}) has {rhs.numel()} values, the state "
                              f"{variable.size}")
        self.derivatives[variable.name] = ca.reshape(rhs, variable.size, 1)

    def subject_to(self, expr: ca.SX, lower: float | list = -INF, upper: float | list = INF) -> None:
        """lower ≤ expr ≤ upper on the whole of [0, t_f] (states, controls, rates, parameters, `t`)."""
        self.path.append(self._row(expr, lower, upper, "subject_to"))

    def at_start(self, expr: ca.SX, lower: float | list = -INF, upper: float | list = INF) -> None:
        """lower ≤ expr ≤ upper at t = 0 (states and parameters there)."""
        self.start.append(self._row(expr, lower, upper, "at_start"))

    def at_end(self, expr: ca.SX, lower: float | list = -INF, upper: float | list = INF) -> None:
        """lower ≤ expr ≤ upper at t = t_f (states, parameters and `T` there)."""
        self.end.append(self._row(expr, lower, upper, "at_end"))

    def minimize_end(self, expr: ca.SX | float) -> None:
        """Add a Mayer term Φ(x(t_f), p, t_f) (use `T` for t_f: `minimize_end(ocp.T)` is minimum time)."""
        self.mayer = self.mayer + self._scalar(expr, "minimize_end")

    def minimize_integral(self, expr: ca.SX | float) -> None:
        """Add a Lagrange term ∫ L(x, u, u̇, p, t) dt."""
        self.lagrange = self.lagrange + self._scalar(expr, "minimize_integral")

    # -- checks ----------------------------------------------------------------------------------------
    def check(self) -> None:
        """OptionError naming what is missing: a state, a control or a derivative."""
        if not self.states:
            raise OptionError(f"{self.name}: declare at least one state")
        missing = [v.name for v in self.states if v.name not in self.derivatives]
        if missing:
            raise OptionError(f"{self.name}: no set_der() for the state(s) {', '.join(missing)}")

    def _find(self, symbol: ca.SX, family: list[Variable], message: str) -> Variable:
        for variable in family:
            if ca.is_equal(variable.symbol, symbol):
                return variable
        raise OptionError(f"{self.name}: {message}")

    def _row(self, expr, lower, upper, what: str) -> Row:
        expr = ca.vec(ca.SX(expr) if not isinstance(expr, ca.SX) else expr)
        k = expr.numel()
        lo, hi = _vector(lower, k, f"{self.name}: {what}.lower"), _vector(upper, k, f"{self.name}: {what}.upper")
        if np.any(lo > hi):
            raise OptionError(f"{self.name}: {what}: lower > upper")
        return Row(expr, lo, hi)

    def _scalar(self, expr, what: str) -> ca.SX:
        expr = ca.SX(expr) if not isinstance(expr, ca.SX) else expr
        if expr.numel() != 1:
            raise OptionError(f"{self.name}: {what} takes a scalar, got {expr.numel()} values")
        return expr


def stacked(symbols: list[ca.SX]) -> ca.SX:
    """The symbols one above the other (a column; (0, 1) for none)."""
    return ca.vertcat(*symbols) if symbols else ca.SX(0, 1)


def columns(variables: list[Variable], values: np.ndarray) -> dict[str, np.ndarray]:
    """Variable name → its columns (points, size) of `values` (points, Σ sizes), whose columns follow `variables`."""
    edges = np.cumsum([0, *(v.size for v in variables)])
    return {v.name: values[:, a:b] for v, a, b in zip(variables, edges[:-1], edges[1:])}


def _t0_bounds(t0: float | tuple[float, float], name: str) -> tuple[float, float]:
    """(lower, upper) of the initial time: equal for a fixed one; OptionError unless finite and ordered."""
    bounds = np.asarray(t0, dtype=float).ravel()
    if bounds.size not in (1, 2) or not np.all(np.isfinite(bounds)) or bounds[0] > bounds[-1]:
        raise OptionError(f"{name}: t0 must be a number or (lower, upper) with lower ≤ upper, got {t0}")
    return float(bounds[0]), float(bounds[-1])


def _vector(value, size: int, what: str) -> np.ndarray:
    """`value` (a number or `size` numbers) as a float array (size,); OptionError naming `what` otherwise."""
    array = np.asarray(value, dtype=float).ravel()
    if array.size == 1:
        return np.full(size, float(array[0]))
    if array.size != size:
        raise OptionError(f"{what}: expected 1 or {size} values, got {array.size}")
    return array
