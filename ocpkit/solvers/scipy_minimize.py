"""Solvers from scipy.optimize.minimize fed with the NLP's CasADi functions: `scipy-slsqp` (SLSQP, dense
quasi-Newton SQP) and `scipy-trust-constr` (trust-region interior point / equality SQP with sparse
constraint Jacobian and the exact Lagrangian Hessian, BFGS updates on an NLP without second derivatives).

Variables fixed by their bounds (lbx == ubx: boundary conditions) are taken out of the problem that SciPy
sees (trust-constr turns bounds into barrier constraints and cannot handle empty intervals); the others
form z (n_z,) = w[free]. Constraints lbg ≤ g ≤ ubg split into equalities (lbg == ubg) and the finite
sides of the rest.

Limits: `max_iterations` is SciPy's `maxiter`; the time limit is checked by the per-iteration callback,
which raises StopIteration once `max_wall_time` (s; or the one passed to `solve`) has passed (SciPy then ends
with status 99 for SLSQP, 3 for trust-constr), so it is honoured to within one iteration.
"""

from __future__ import annotations

import time
from abc import abstractmethod
from dataclasses import dataclass

import numpy as np
import scipy.optimize as so

from ocpkit.nlp import NLP
from ocpkit.solvers.base import PreparedSolver, Solver, SolverResult, SolverStatus, time_limit
from ocpkit.solvers.nlp_functions import NLPFunctions


class _Reduced:
    """The NLP in the free variables z for one query: w = w_fixed with w[free] = z; p fixed."""

    def __init__(self, functions: NLPFunctions, params: np.ndarray, lbx: np.ndarray, ubx: np.ndarray) -> None:
        self.fn, self.params = functions, params
        self.free = lbx < ubx
        self.w = np.where(self.free, 0.0, lbx)

    def full(self, z: np.ndarray) -> np.ndarray:
        """w (n_w,) from z (n_z,)."""
        w = self.w.copy()
        w[self.free] = z
        return w

    def f(self, z: np.ndarray) -> float:
        return float(self.fn.f(self.full(z), self.params))

    def grad_f(self, z: np.ndarray) -> np.ndarray:
        return np.asarray(self.fn.grad_f(self.full(z), self.params)).ravel()[self.free]

    def g(self, z: np.ndarray) -> np.ndarray:
        return np.asarray(self.fn.g(self.full(z), self.params)).ravel()

    def jac_g(self, z: np.ndarray):
        """∂g/∂z as a scipy.sparse CSC matrix (n_g × n_z)."""
        return self.fn.jac_g(self.full(z), self.params).sparse()[:, self.free]

    def objective_hessian(self):
        """minimize's `hess`: z ↦ ∇²f (scipy.sparse, n_z × n_z), or BFGS updates when there is no exact one."""
        if self.fn.hess_f is None:
            return so.BFGS()
        return lambda z: self.fn.hess_f(self.full(z), self.params).sparse()[self.free][:, self.free]

    def constraint_hessian(self):
        """NonlinearConstraint's `hess`: (z, v) ↦ ∇²(vᵀg) (scipy.sparse, n_z × n_z), or BFGS updates."""
        if self.fn.hess_vg is None:
            return so.BFGS()
        return lambda z, v: self.fn.hess_vg(self.full(z), self.params, v).sparse()[self.free][:, self.free]


class _Clock:
    """minimize callback: raises StopIteration after `limit` s from construction."""

    def __init__(self, limit: float) -> None:
        self.deadline = time.perf_counter() + limit

    def __call__(self, *args) -> None:
        if time.perf_counter() > self.deadline:
            raise StopIteration


@dataclass(frozen=True)
class PreparedMinimize(PreparedSolver):
    """The CasADi `functions` of `nlp` and the `owner` solver whose method and options apply."""

    nlp: NLP
    functions: NLPFunctions
    owner: ScipyMinimize

    def solve(self, guess: np.ndarray, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              max_wall_time: float | None = None, pace: int | None = None) -> SolverResult:
        owner = self.owner
        lbx, ubx = (np.asarray(b, dtype=float) for b in bounds)
        reduced = _Reduced(self.functions, np.asarray(params, dtype=float), lbx, ubx)
        free = reduced.free
        z0 = np.clip(np.asarray(guess, dtype=float), lbx, ubx)[free]
        start = time.perf_counter()
        try:
            result = so.minimize(reduced.f, z0, method=owner.method, jac=reduced.grad_f,
                                 hess=reduced.objective_hessian() if owner.hessians else None,
                                 bounds=so.Bounds(lbx[free], ubx[free]),
                                 constraints=owner.constraints(self.nlp, reduced), options=owner.options,
                                 callback=_Clock(time_limit(owner.max_wall_time, max_wall_time)))
        except (RuntimeError, ValueError, np.linalg.LinAlgError) as exc:  # failed evaluation or factorization
            return SolverResult.failed(guess, start, f"{type(exc).__name__}: {exc}")
        wall = time.perf_counter() - start
        status = owner.statuses.get(int(result.status), SolverStatus.FAILED)
        return SolverResult(reduced.full(result.x), status, int(getattr(result, "nit", 0)), wall,
                            str(result.message), {"status": int(result.status), "nfev": result.nfev})


class ScipyMinimize(Solver):
    """scipy.optimize.minimize with one method; subclasses give the method, how constraints are passed
    and the meaning of SciPy's status codes. `max_wall_time` is in seconds; `options` go to minimize's
    `options` verbatim."""

    method: str
    hessians = False
    statuses: dict[int, SolverStatus]

    def __init__(self, max_iterations: int = 500, max_wall_time: float = 60.0, **options) -> None:
        self.max_iterations, self.max_wall_time = max_iterations, max_wall_time
        self.options = {"maxiter": max_iterations, **options}

    def prepare(self, nlp: NLP) -> PreparedMinimize:
        exact = self.hessians and nlp.exact_hessian
        return PreparedMinimize(nlp, NLPFunctions.build(nlp, exact, exact), self)

    @abstractmethod
    def constraints(self, nlp: NLP, reduced: _Reduced) -> list:
        """The constraints lbg ≤ g ≤ ubg in the form this method takes."""


class ScipySlsqp(ScipyMinimize):
    """SciPy's SLSQP (Kraft): a dense SQP with BFGS updates.

    Equalities and the finite sides of the inequalities go in as dense constraint blocks. `ftol` (objective
    change) is its stopping tolerance."""

    name, method = "scipy-slsqp", "SLSQP"
    statuses = {0: SolverStatus.CONVERGED, 4: SolverStatus.INFEASIBLE, 9: SolverStatus.ITERATION_LIMIT,
                99: SolverStatus.TIME_LIMIT}

    def __init__(self, max_iterations: int = 500, max_wall_time: float = 60.0, ftol: float = 1e-9,
                 **options) -> None:
        super().__init__(max_iterations, max_wall_time, ftol=ftol, **options)

    def constraints(self, nlp: NLP, reduced: _Reduced) -> list:
        lbg, ubg = np.asarray(nlp.lbg, dtype=float), np.asarray(nlp.ubg, dtype=float)
        eq = lbg == ubg
        lower, upper = ~eq & np.isfinite(lbg), ~eq & np.isfinite(ubg)
        # g ≥ lbg and ubg ≥ g as c(z) ≥ 0, stacked; their Jacobian rows with the matching signs
        sign = np.concatenate([np.ones(lower.sum()), -np.ones(upper.sum())])
        offset = np.concatenate([lbg[lower], ubg[upper]])
        rows = np.concatenate([np.flatnonzero(lower), np.flatnonzero(upper)])
        blocks = [{"type": "eq", "fun": lambda z: reduced.g(z)[eq] - lbg[eq],
                   "jac": lambda z: reduced.jac_g(z)[eq].toarray()},
                  {"type": "ineq", "fun": lambda z: sign * (reduced.g(z)[rows] - offset),
                   "jac": lambda z: sign[:, None] * reduced.jac_g(z)[rows].toarray()}]
        return [block for block, size in zip(blocks, (eq.sum(), len(rows))) if size]


class ScipyTrustConstr(ScipyMinimize):
    """SciPy's trust-constr: a trust-region interior point with exact Hessians by CasADi AD.

    It gets the sparse constraint Jacobian and the exact Hessians of f and of vᵀg. `gtol`/`xtol` are its
    tolerances (on the Lagrangian gradient and the trust radius); ending on either counts as converged, as SciPy
    itself reports it."""

    name, method = "scipy-trust-constr", "trust-constr"
    hessians = True
    statuses = {0: SolverStatus.ITERATION_LIMIT, 1: SolverStatus.CONVERGED, 2: SolverStatus.CONVERGED,
                3: SolverStatus.TIME_LIMIT}

    def __init__(self, max_iterations: int = 1000, max_wall_time: float = 60.0, gtol: float = 1e-6,
                 xtol: float = 1e-10, **options) -> None:
        super().__init__(max_iterations, max_wall_time, gtol=gtol, xtol=xtol, **options)

    def constraints(self, nlp: NLP, reduced: _Reduced) -> list:
        return [so.NonlinearConstraint(reduced.g, nlp.lbg, nlp.ubg, jac=reduced.jac_g,
                                       hess=reduced.constraint_hessian())]
