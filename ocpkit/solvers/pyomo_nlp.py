"""The `pyomo` solver: the NLP as a Pyomo model, solved by ripopt (pyomo-ripopt's interior-point solver, run
through Pyomo's AMPL .nl/.sol interface as the `ripopt` SolverFactory plugin).

Translation (once per NLP, in `prepare`, which returns it in a `PreparedRipopt`): the instructions of the SX
function (w, p) ↦ (f, g) are read as a DAG (CasADi's work-vector slots are reused, so every operand is
resolved to the instruction that wrote it) and replayed with Pyomo operations (`_UNARY`, `_BINARY`; any other
operation is an OptionError naming it).
w becomes the indexed Var `w` (n_w,), p the mutable Param `p` (n_p,), g the Constraint `g` (n_g,) with the
NLP's lbg/ubg. A query then only sets p, the bounds (lbx == ubx fixes the variable, which the .nl writer
turns into a constant), the starting point, and solves. An NLP lifted to MX around a Python callback (the
`pinocchio` dynamics backend) has no SX graph and is refused with an OptionError.

Shared subexpressions: the .nl format stores expression trees, so a DAG node used twice is written twice
unless it is a named Pyomo Expression (an .nl "defined variable"). Written as plain trees the dynamics blow
the .nl file up many times over, and writing it dominates; with every shared node (used more than once) named
it stays small. ripopt, however, expands defined variables back into one tree per constraint
and takes its Hessian by one forward-over-reverse sweep per variable of that tree, so the dynamics
constraints make every Hessian slow. So a shared node whose expanded tree exceeds `lift_above` nodes is
lifted instead: an auxiliary Var `lifted[i]` with the equality `defines[i]` (lifted[i] == its expression),
started at its value in the starting point; smaller shared nodes stay named Expressions. Lifting all shared
nodes makes ripopt's KKT solves the bottleneck instead, so the default `lift_above` sits in between: it gives
the fastest solves of the thresholds tried (figures: docs/design-notes.md). The lifted problem has the same
solutions and the same multipliers of g. A lifted node that depends on fixed variables only (e.g. the
dynamics at a rest knot) is fixed at its value for the query: left free, its defining equality has one free
variable, and ripopt then could end "optimal" with that equality grossly violated.

Status, from ripopt's message (the .sol file's, which follows IPOPT's wording): `_STATUSES`, anything else
is `failed` (then the starting point is returned: Pyomo does not load a solution with an error status), as
is a ripopt run that ends abnormally. Iterations and ripopt's diagnostics (in `stats`) are read from its
output, which is captured, never printed; Pyomo's warnings are captured as well. Temporary files (.nl,
.sol, log) live in a Pyomo tempfile context that is released after every solve, failed or not.

Limits: `max_iterations` is ripopt's max_iter, `max_wall_time` (s) its max_wall_time, which ripopt checks
between iterations (the .nl write comes before its clock starts). One iteration can take long (a diverging
run can overrun the limit by far), so the ripopt process is also killed max(1 s, 1 %) after the limit (Pyomo's
subprocess timeout): `time_limit` too, with the starting point.

Multipliers: lam_g (n_g,) from the `dual` import Suffix; ripopt's constraint duals already follow CasADi's
sign convention (checked against IPOPT in the tests); constraints the .nl writer drops (constant after
fixing) get 0. ripopt reports no bound multipliers, so lam_x is None.
"""

from __future__ import annotations

import io
import operator
import subprocess
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np
import pyomo.environ as pyo
import pyomo_ripopt  # noqa: F401  (registers the "ripopt" SolverFactory plugin)
from pyomo.common.errors import ApplicationError
from pyomo.common.log import LoggingIntercept
from pyomo.common.tempfiles import TempfileManager
from pyomo.opt import SolverResults
from pyomo.opt import SolverStatus as PyomoStatus

from ocpkit.errors import OptionError
from ocpkit.nlp import NLP
from ocpkit.solvers.base import PreparedSolver, Solver, SolverResult, SolverStatus, time_limit
from ocpkit.solvers.casadi_nlpsol import hessian_approximation

_UNARY: dict[int, Callable] = {
    ca.OP_ASSIGN: lambda a: a, ca.OP_NEG: operator.neg, ca.OP_SQ: lambda a: a ** 2, ca.OP_TWICE: lambda a: 2 * a,
    ca.OP_INV: lambda a: 1 / a, ca.OP_FABS: abs, ca.OP_SQRT: pyo.sqrt, ca.OP_EXP: pyo.exp, ca.OP_LOG: pyo.log,
    ca.OP_SIN: pyo.sin, ca.OP_COS: pyo.cos, ca.OP_TAN: pyo.tan, ca.OP_ASIN: pyo.asin, ca.OP_ACOS: pyo.acos,
    ca.OP_ATAN: pyo.atan, ca.OP_SINH: pyo.sinh, ca.OP_COSH: pyo.cosh, ca.OP_TANH: pyo.tanh,
    ca.OP_ASINH: pyo.asinh, ca.OP_ACOSH: pyo.acosh, ca.OP_ATANH: pyo.atanh,
}
_BINARY: dict[int, Callable] = {
    ca.OP_ADD: operator.add, ca.OP_SUB: operator.sub, ca.OP_MUL: operator.mul, ca.OP_DIV: operator.truediv,
    ca.OP_POW: operator.pow, ca.OP_CONSTPOW: operator.pow,
    ca.OP_FMIN: lambda a, b: (a + b - abs(a - b)) / 2,  # exactly min(a, b): e.g. a row's capped margin
    ca.OP_FMAX: lambda a, b: (a + b + abs(a - b)) / 2,  # exactly max(a, b): e.g. a box's outside excess
}
_LEAVES = (ca.OP_INPUT, ca.OP_CONST)
_OP_NAMES = {getattr(ca, name): name for name in dir(ca) if name.startswith("OP_")}

_STATUSES = {
    "Optimal Solution Found": SolverStatus.CONVERGED,
    "Solved To Acceptable Level": SolverStatus.CONVERGED,
    "Infeasible Problem Detected": SolverStatus.INFEASIBLE,
    "Converged to a point of local infeasibility": SolverStatus.INFEASIBLE,
    "Maximum Number of Iterations Exceeded": SolverStatus.ITERATION_LIMIT,
    "Maximum CPU Time Exceeded": SolverStatus.TIME_LIMIT,  # ripopt's max_wall_time, worded as IPOPT's
}
"""ripopt's .sol message → our status; any other message is `failed`."""
_LOADED = (PyomoStatus.ok, PyomoStatus.warning)
"""Pyomo's solver statuses with which it loads a solution (ripopt's error codes, 500 and up, have none)."""


@dataclass(frozen=True)
class _Dag:
    """The instructions of an SX function as a DAG, one entry per instruction k: operation code `ops[k]`,
    the instructions whose results it takes `args[k]`, and for OP_INPUT / OP_OUTPUT the (input or output
    index, nonzero) it reads or writes `slots[k]`; `constants` holds the values of the OP_CONST ones."""

    ops: list[int]
    args: list[tuple[int, ...]]
    slots: dict[int, tuple[int, int]]
    constants: dict[int, float]

    @classmethod
    def of(cls, fn: ca.Function) -> _Dag:
        ops, args, slots, constants = [], [], {}, {}
        writer: dict[int, int] = {}  # work-vector slot → the instruction that last wrote it
        for k in range(fn.n_instructions()):
            op, inputs, outputs = fn.instruction_id(k), fn.instruction_input(k), fn.instruction_output(k)
            ops.append(op)
            args.append(() if op in _LEAVES else tuple(writer[slot] for slot in inputs))
            if op == ca.OP_CONST:
                constants[k] = fn.instruction_constant(k)
            if op in (ca.OP_INPUT, ca.OP_OUTPUT):
                slots[k] = tuple(inputs if op == ca.OP_INPUT else outputs)
            if op != ca.OP_OUTPUT:
                writer[outputs[0]] = k
        return cls(ops, args, slots, constants)

    def unsupported(self) -> list[str]:
        """Names of the operations that have no Pyomo translation."""
        known = set(_UNARY) | set(_BINARY) | set(_LEAVES) | {ca.OP_OUTPUT}
        return sorted(_OP_NAMES.get(op, f"op code {op}") for op in set(self.ops) - known)

    def shared_nodes(self, lift_above: float) -> tuple[list[int], list[int]]:
        """(lifted, named): the operations used more than once, split by the size of their expanded
        expression tree (leaves and lifted nodes count 1): larger than `lift_above` nodes → lifted."""
        uses = Counter(j for operands in self.args for j in operands)
        size = [1] * len(self.ops)
        lifted, named = [], []
        for k, op in enumerate(self.ops):
            if op in _LEAVES or op == ca.OP_OUTPUT:
                continue
            size[k] = 1 + sum(size[j] for j in self.args[k])
            if uses[k] > 1 and size[k] > lift_above:
                lifted.append(k)
                size[k] = 1
            elif uses[k] > 1:
                named.append(k)
        return lifted, named


def _bound(value: float) -> float | None:
    """A Pyomo bound: None for an infinite one."""
    return float(value) if np.isfinite(value) else None


def _bounds(values: np.ndarray) -> list[float | None]:
    """Pyomo bounds (None where infinite) of an array of bounds."""
    return [_bound(v) for v in values]


def _constraint(lower: float | None, body, upper: float | None):
    """The Pyomo constraint lower ≤ body ≤ upper, skipped when body is a number (nothing to solve for)."""
    return pyo.Constraint.Skip if isinstance(body, float) else (lower, body, upper)


class _PyomoNlp:
    """The Pyomo model of one NLP (see the module docstring) and the CasADi function that gives the
    lifted nodes' values (n_lifted,) at (w, p), to start them consistently."""

    def __init__(self, nlp: NLP, lift_above: float) -> None:
        fn = ca.Function("nlp", [nlp.x, nlp.p], [ca.densify(nlp.f), ca.densify(nlp.g)])
        dag = _Dag.of(fn)
        if unsupported := dag.unsupported():
            raise OptionError(f"pyomo cannot translate the CasADi operation(s) {', '.join(unsupported)} of this "
                              "NLP; use a CasADi solver such as ipopt instead")
        lifted, named = dag.shared_nodes(lift_above)
        self.lifted_values = ca.Function("lifted", [nlp.x, nlp.p], [fn.instructions_sx()[lifted]])
        self.lifted_inputs = ca.DM(self.lifted_values.sparsity_jac(0, 0), 1.0).sparse()  # (n_lifted, n_w) pattern
        m = self.model = pyo.ConcreteModel()
        m.w = pyo.Var(range(nlp.x.numel()))
        m.p = pyo.Param(range(nlp.p.numel()), mutable=True, initialize=0.0)
        m.lifted = pyo.Var(range(len(lifted)))
        m.defines = pyo.Constraint(range(len(lifted)))
        m.shared = pyo.Expression(range(len(named)))
        f, g = self._replay(dag, nlp.g.numel(), dict(zip(lifted, m.lifted.values())),
                            dict(zip(named, m.shared.values())))
        m.f = pyo.Objective(expr=f)
        bounds = list(zip(_bounds(nlp.lbg), g, _bounds(nlp.ubg)))
        m.g = pyo.Constraint(range(nlp.g.numel()), rule=lambda _, j: _constraint(*bounds[j]))
        m.dual = pyo.Suffix(direction=pyo.Suffix.IMPORT)

    def _replay(self, dag: _Dag, n_g: int, lifted: dict[int, pyo.Var],
                named: dict[int, pyo.Expression]) -> tuple[object, list]:
        """Pyomo expressions of f and g (n_g,) by replaying `dag` on the model's w and p; lifted nodes get
        their defining constraint, named nodes their Expression."""
        inputs = (self.model.w, self.model.p)
        outputs: tuple[list, list] = ([0.0], [0.0] * n_g)
        value: dict[int, object] = {}
        for k, op in enumerate(dag.ops):
            if op == ca.OP_INPUT:
                which, nz = dag.slots[k]
                value[k] = inputs[which][nz]
            elif op == ca.OP_CONST:
                value[k] = dag.constants[k]
            elif op == ca.OP_OUTPUT:
                which, nz = dag.slots[k]
                outputs[which][nz] = value[dag.args[k][0]]
            else:
                operands = [value[j] for j in dag.args[k]]
                expression = _UNARY[op](*operands) if op in _UNARY else _BINARY[op](*operands)
                value[k] = self._node(k, expression, lifted, named)
        return outputs[0][0], outputs[1]

    def _node(self, k: int, expression, lifted: dict[int, pyo.Var], named: dict[int, pyo.Expression]):
        """What the parents of instruction k refer to: its lifted Var, its named Expression, or the
        expression itself."""
        if k in lifted:
            self.model.defines[len(self.model.defines)] = lifted[k] == expression
            return lifted[k]
        if k in named:
            named[k].set_value(expression)
            return named[k]
        return expression

    def load(self, guess: np.ndarray, params: np.ndarray, lbx: np.ndarray, ubx: np.ndarray) -> None:
        """Set one query's numbers: p (n_p,), bounds and starting point of w (n_w,), with w fixed where
        lbx == ubx, and the lifted nodes' values at that point."""
        m = self.model
        for param, value in zip(m.p.values(), params):
            param.set_value(float(value))
        start = np.where(lbx == ubx, lbx, guess)
        for var, value, lower, upper in zip(m.w.values(), start, _bounds(lbx), _bounds(ubx)):
            if lower is not None and lower == upper:
                var.fix(lower)
            else:
                var.unfix()
                var.setlb(lower)
                var.setub(upper)
                var.set_value(float(value), skip_validation=True)
        values = np.asarray(self.lifted_values(start, params)).ravel()
        determined = self.lifted_inputs @ (lbx != ubx).astype(float) == 0  # depends on fixed w only
        for var, value, fixed in zip(m.lifted.values(), values, determined):
            var.set_value(float(value), skip_validation=True)
            var.fixed = bool(fixed)

    def solution(self) -> tuple[np.ndarray, np.ndarray]:
        """(w (n_w,), lam_g (n_g,)) as loaded into the model."""
        m = self.model
        w = np.array([var.value for var in m.w.values()], dtype=float)
        lam_g = [m.dual.get(m.g[j], 0.0) if j in m.g else 0.0 for j in m.g.index_set()]
        return w, np.array(lam_g, dtype=float)


def _message(results: SolverResults) -> str:
    """ripopt's message without its "ripopt <version>: " prefix (Pyomo escapes its colons as \\x3a)."""
    return str(results.solver.message).replace("\\x3a", ":").partition(": ")[2]


def _diagnostics(log: str) -> dict[str, str]:
    """The "key: value" lines of ripopt's diagnostics block in its output (iterations, wall_time, ...)."""
    block = log.partition("--- ripopt diagnostics ---")[2].partition("--- end diagnostics ---")[0]
    return dict(line.split(": ", 1) for line in block.splitlines() if ": " in line)


@dataclass(frozen=True)
class PreparedRipopt(PreparedSolver):
    """`nlp` translated to a Pyomo model (`translation`) and the `owner` solver whose options apply."""

    nlp: NLP
    translation: _PyomoNlp
    owner: PyomoRipopt

    def solve(self, guess: np.ndarray, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              max_wall_time: float | None = None, pace: int | None = None) -> SolverResult:
        guess = np.asarray(guess, dtype=float)
        self.translation.load(guess, np.asarray(params, dtype=float), *(np.asarray(b, dtype=float) for b in bounds))
        limit = time_limit(self.owner.max_wall_time, max_wall_time)
        options = {"hessian_approximation": hessian_approximation(self.nlp), **self.owner.options,
                   "max_wall_time": limit}
        start = time.perf_counter()
        try:
            results, log = self.owner.run(self.translation.model, options, limit)
        except subprocess.TimeoutExpired:
            wall = time.perf_counter() - start
            return SolverResult(guess, SolverStatus.TIME_LIMIT, 0, wall, f"ripopt killed after {wall:.1f} s")
        except (ApplicationError, OSError, ValueError) as exc:  # ripopt ended abnormally or wrote no solution
            return SolverResult.failed(guess, start, f"{type(exc).__name__}: {exc}")
        wall = time.perf_counter() - start
        message, stats = _message(results), _diagnostics(log)
        w, lam_g = self.translation.solution() if results.solver.status in _LOADED else (guess, None)
        return SolverResult(w, _STATUSES.get(message, SolverStatus.FAILED), int(stats.get("iterations", 0)), wall,
                            message, {"solve_result_num": results.solver.id, **stats}, lam_g)


class PyomoRipopt(Solver):
    """ripopt (interior point, exact Hessian by its own AD) on the NLP translated to a Pyomo model.

    ripopt differentiates the .nl expressions itself, and takes L-BFGS when the NLP has no second derivatives
    (see the module docstring). `lift_above` is the tree size above which a shared subexpression becomes an
    auxiliary variable; `max_wall_time` is in seconds; extra keyword options go to ripopt verbatim (e.g.
    tol=1e-8, mu_strategy="monotone")."""

    name = "pyomo"

    def __init__(self, max_iterations: int = 1000, max_wall_time: float = 60.0, lift_above: float = 300.0,
                 **ripopt_options) -> None:
        self.max_iterations, self.max_wall_time, self.lift_above = max_iterations, max_wall_time, lift_above
        self.options = {"print_level": 0, "tol": 1e-6, "max_iter": max_iterations,
                        "max_wall_time": max_wall_time, **ripopt_options}
        self._ripopt = pyo.SolverFactory("ripopt")

    def prepare(self, nlp: NLP) -> PreparedRipopt:
        if isinstance(nlp.x, ca.MX):
            raise OptionError("pyomo translates symbolic SX graphs, and this NLP is MX: its dynamics backend "
                              "evaluates through a callback; use an SX backend (dynamics 'casadi' or 'casadi-rnea') "
                              "or a CasADi solver such as ipopt instead")
        return PreparedRipopt(nlp, _PyomoNlp(nlp, self.lift_above), self)

    def run(self, model: pyo.ConcreteModel, options: dict, max_wall_time: float) -> tuple[SolverResults, str]:
        """Solve `model` with ripopt quietly; (Pyomo's results, ripopt's output). The solution is loaded
        into the model unless ripopt reports an error status. ripopt is killed (subprocess.TimeoutExpired)
        once it overruns `max_wall_time` (s) by max(1 s, 1 %). Temporary files are removed on return."""
        with LoggingIntercept(io.StringIO(), "pyomo"), TempfileManager as tempfiles:
            log = tempfiles.create_tempfile(suffix="_ripopt.log")
            results = self._ripopt.solve(model, options=options, logfile=log, load_solutions=False,
                                         timelimit=max_wall_time)
            if results.solver.status in _LOADED:
                model.solutions.load_from(results)
            with open(log, encoding="utf-8") as output:
                return results, output.read()
