"""Sequential convex programming (`scp`) in the style of TrajOpt (Schulman et al. 2014): a sequence of convex
subproblems on a box trust region, an exact ℓ1 penalty for the constraints, and an outer loop that raises
the penalty until the constraints hold.

Subproblem. At an iterate w_k (inside the bounds) the step d (n_w,) and slacks t (n_g,) solve the QP

    minimize    ∇f(w_k)·d + ½ dᵀ H d + ρ Σ t
    subject to  lbg − t ≤ g(w_k) + J d ≤ ubg + t   (finite sides only),   t ≥ 0,
                max(lbx − w_k, −Δ s) ≤ d ≤ min(ubx − w_k, Δ s),

i.e. the ℓ1 violation of the linearized constraints, weighted by the penalty ρ, plus a quadratic model of f.
J = ∂g/∂w at w_k (sparse), Δ the trust radius and s (n_w,) the per-variable scale s_i = min(ubx_i − lbx_i,
max(|w_i|, 1)): a relative trust region for unbounded variables and large values, capped by the bound width.
Variables fixed by their bounds (lbx = ubx) are masked out (zero gradient, Jacobian column and curvature).

H is the exact objective Hessian ∇²f(w_k) (CasADi AD), plus the smallest multiple δ I (δ = 1e-10 ·
scale · 100^k) for which its Cholesky factorization succeeds, so H is positive definite; on an NLP without
exact second derivatives (`nlp.exact_hessian` False) a damped BFGS approximation of ∇²f (Powell damping,
dense) stands in. Constraint curvature is left to the trust region and the second-order correction.

Acceptance. Merit φ(w) = f(w) + ρ viol(w), viol the ℓ1 norm of the constraint violation. The QP predicts
pred = φ(w_k) − [f(w_k) + ∇f·d + ½ dᵀHd + ρ viol(g + J d)]; the step is judged by r = (φ(w_k) − φ(w_k + d)) /
pred. When r < 0.75, a second-order correction is tried first: the QP again with g(w_k) replaced by g(w_k + d)
− J d (the constraint curvature along d), keeping whichever step has the larger r. r ≥ 0.1 accepts the step
(Δ doubles when r ≥ 0.75 and the step reached the trust region, halves when r < 0.25); otherwise Δ shrinks
by 4 and the QP is solved again at the same w_k.

Stopping. The merit has converged when pred ≤ tol · max(1, |φ|) or Δ < 1e-8. Then: max violation ≤ tol →
CONVERGED; else ρ grows ×10 (TrajOpt's outer penalty loop; Δ back to at least its initial value), and once ρ
reached `max_penalty` → INFEASIBLE.
Every QP solved (second-order corrections included) counts towards `max_iterations` (→ ITERATION_LIMIT);
`max_wall_time` is checked before each QP (→ TIME_LIMIT); a QP solver failure → FAILED with its message.
The result carries lam_g from the last QP's constraint duals (the ℓ1 QP's multipliers, |lam_g| ≤ ρ).

Choices (each compared on the paper cases; the figures are in docs/design-notes.md). The QP solver takes
almost all of the time.
- The QP is built once per NLP (in `prepare`) as a cvxpy Problem with Parameters (DPP), J and the Cholesky
  factor of H as *sparse* Parameters, so a QP is re-solved without canonicalizing it again; rebuilding it per
  QP costs more than the re-solve, and J as dense selection matrices times a Parameter vector of its nonzeros
  (the way without sparse Parameters) is slow to compile.
- Clarabel over OSQP: OSQP's ADMM needs far more iterations on the same QPs and still ends inaccurate.
  HiGHS rejects the semidefinite QP. Clarabel's `iterative_refinement_enable=False` (an extra option) is
  somewhat faster with unchanged results on the paper cases; the default keeps Clarabel's settings.
- H = ∇²f: its diagonal alone needs more QPs; the Lagrangian Hessian made PSD by eigenvalue clipping (a
  prototype) needs as many QPs but is dense, which makes each QP slower.
- ρ starts at 1: IPOPT's multipliers on the paper cases stay below 1, and TrajOpt's 10 makes every step
  trade objective for feasibility (far more QPs).
- The second-order correction: without it the ℓ1 merit rejects the minimum-time problems' good steps (the
  Maratos effect), and the QP count multiplies.
- The relative scale s: with the bound widths alone (1 for unbounded variables) the accelerations, which grow
  as 1/t_f², move by a fixed amount per step, and more QPs are needed.
"""

from __future__ import annotations

import time
import warnings
from abc import ABC, abstractmethod
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from ocpkit.nlp import NLP
from ocpkit.solvers.base import PreparedSolver, Solver, SolverResult, SolverStatus, time_limit
from ocpkit.solvers.nlp_functions import NLPFunctions

ACCEPT, POOR, GOOD = 0.1, 0.25, 0.75
"""Ratio thresholds: accept a step, halve Δ below POOR, double it above GOOD (and try the correction below)."""
EXPAND, SHRINK_POOR, SHRINK_REJECTED = 2.0, 0.5, 0.25
MIN_RADIUS, MAX_RADIUS = 1e-8, 100.0
PENALTY_GROWTH = 10.0
SOLVED = {cp.OPTIMAL, cp.OPTIMAL_INACCURATE}


@dataclass(frozen=True)
class _Point:
    """The NLP at w (n_w,): f, ∇f (n_w,), g (n_g,), J = ∂g/∂w (sparse n_g × n_w, CasADi's pattern) and the
    ℓ1 and maximum constraint violation."""

    w: np.ndarray
    f: float
    grad: np.ndarray
    g: np.ndarray
    jac: sp.csc_matrix
    violation: float
    max_violation: float

    def merit(self, rho: float) -> float:
        """φ = f + ρ · ℓ1 violation."""
        return self.f + rho * self.violation


def _violations(g: np.ndarray, lbg: np.ndarray, ubg: np.ndarray) -> np.ndarray:
    """Per-constraint violation max(0, lbg − g, g − ubg) (n_g,)."""
    return np.maximum(0.0, np.maximum(lbg - g, g - ubg))


class _Evaluator:
    """The NLP's functions for one query (parameters p fixed): w ↦ _Point."""

    def __init__(self, functions: NLPFunctions, params: np.ndarray, lbg: np.ndarray, ubg: np.ndarray) -> None:
        self.fn, self.params, self.lbg, self.ubg = functions, params, lbg, ubg

    def __call__(self, w: np.ndarray) -> _Point:
        g = np.asarray(self.fn.g(w, self.params)).ravel()
        violations = _violations(g, self.lbg, self.ubg)
        return _Point(w, float(self.fn.f(w, self.params)), np.asarray(self.fn.grad_f(w, self.params)).ravel(), g,
                      self.fn.jac_g(w, self.params).sparse(), float(violations.sum()), float(violations.max(initial=0)))


def _hessian_pattern(functions: NLPFunctions, n_w: int) -> np.ndarray:
    """Where H may be nonzero (n_w × n_w bool): ∇²f's sparsity, or everywhere for the BFGS approximation."""
    if functions.hess_f is None:
        return np.ones((n_w, n_w), dtype=bool)
    pattern = np.zeros((n_w, n_w), dtype=bool)
    pattern[functions.hess_f.sparsity_out(0).get_triplet()] = True
    return pattern


def _factor_pattern(hessian_pattern: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) of R's nonzeros, R upper triangular with RᵀR = H for any H with this symmetric pattern
    (n × n bool) plus the diagonal: the fill of a Cholesky factorization in the natural order, read off the
    factor of a random diagonally dominant matrix with the pattern."""
    n = len(hessian_pattern)
    pattern = hessian_pattern | hessian_pattern.T | np.eye(n, dtype=bool)
    values = np.where(pattern, np.random.default_rng(0).uniform(0.1, 1.0, (n, n)), 0.0)
    symmetric = values + values.T + 2 * n * np.eye(n)
    return np.nonzero(np.triu(np.linalg.cholesky(symmetric).T) != 0)


def _cholesky_upper(hessian: np.ndarray) -> np.ndarray:
    """R (n × n upper triangular) with RᵀR = H + δ I for the smallest δ = 1e-10 · scale · 100^k (k = 0, ..., 10)
    that makes H + δ I positive definite, scale = 1 + max |H_ii|; LinAlgError if none does (H not finite)."""
    scale = 1.0 + np.abs(np.diag(hessian)).max(initial=0)
    for k in range(11):
        try:
            return np.linalg.cholesky(hessian + 1e-10 * scale * 100.0 ** k * np.eye(len(hessian))).T
        except np.linalg.LinAlgError:
            continue
    raise np.linalg.LinAlgError("no multiple of the identity up to 1e10 · scale makes the Hessian positive definite")


class _Curvature(ABC):
    """The quadratic model H (n_w × n_w) of the objective's curvature."""

    @abstractmethod
    def matrix(self, point: _Point) -> np.ndarray:
        """H (dense n_w × n_w) at `point`."""

    @abstractmethod
    def update(self, old: _Point, new: _Point) -> None:
        """Learn from an accepted step old → new."""


class _ExactCurvature(_Curvature):
    """H = ∇²f from CasADi."""

    def __init__(self, functions: NLPFunctions, params: np.ndarray) -> None:
        self.hess_f, self.params = functions.hess_f, params

    def matrix(self, point: _Point) -> np.ndarray:
        return np.asarray(self.hess_f(point.w, self.params))

    def update(self, old: _Point, new: _Point) -> None:
        pass


class _DampedBfgs(_Curvature):
    """Powell-damped BFGS approximation of ∇²f from accepted steps (dense); B₀ = I rescaled by yᵀy / sᵀy at
    the first update (Nocedal & Wright, eq. 6.20 and procedure 18.2)."""

    def __init__(self, n: int) -> None:
        self.hessian, self.updated = np.eye(n), False

    def matrix(self, point: _Point) -> np.ndarray:
        return self.hessian

    def update(self, old: _Point, new: _Point) -> None:
        s, y = new.w - old.w, new.grad - old.grad
        if not self.updated and s @ y > 0:
            self.hessian *= (y @ y) / (s @ y)
        bs = self.hessian @ s
        curvature = s @ bs
        if curvature <= 0:
            return
        theta = 1.0 if s @ y >= 0.2 * curvature else 0.8 * curvature / (curvature - s @ y)
        r = theta * y + (1 - theta) * bs
        self.hessian += np.outer(r, r) / (s @ r) - np.outer(bs, bs) / curvature
        self.updated = True


@contextmanager
def _cvxpy_quiet() -> Iterator[None]:
    """Without two cvxpy warnings: that a sparse Parameter is read densely (its `solve` does so when checking
    that every Parameter has a value; the QP data are still built from the sparse values), and that a
    solution "may be inaccurate" (OPTIMAL_INACCURATE steps are used: the merit test judges them)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Reading from a sparse CVXPY expression", RuntimeWarning)
        warnings.filterwarnings("ignore", "Solution may be inaccurate", UserWarning)
        yield


class _Subproblem:
    """The convex QP of one NLP (see the module docstring) as a cvxpy Problem with Parameters: the
    model (∇f, J, the Cholesky factor R of H, ρ) is set once per linearization, the constant term g and the
    trust-region box per solve. Parameters: ∇f (n_w,), J (n_g × n_w, sparse), R (n_w × n_w, sparse upper
    triangular), ρ ≥ 0, the finite sides lbg − g and ubg − g, and the box lo, hi (n_w,)."""

    def __init__(self, jac_pattern: tuple[np.ndarray, np.ndarray], factor_pattern: tuple[np.ndarray, np.ndarray],
                 lbg: np.ndarray, ubg: np.ndarray, n_w: int) -> None:
        n_g = len(lbg)
        self.lbg, self.ubg = lbg, ubg
        self.jac_pattern, self.factor_pattern = jac_pattern, factor_pattern
        self.lower_rows, self.upper_rows = np.flatnonzero(np.isfinite(lbg)), np.flatnonzero(np.isfinite(ubg))
        self.d, t = cp.Variable(n_w), cp.Variable(n_g, nonneg=True)
        self.grad, self.rho = cp.Parameter(n_w), cp.Parameter(nonneg=True)
        self.jac = cp.Parameter((n_g, n_w), sparsity=jac_pattern)
        self.factor = cp.Parameter((n_w, n_w), sparsity=factor_pattern)
        self.lower, self.upper = cp.Parameter(len(self.lower_rows)), cp.Parameter(len(self.upper_rows))
        self.lo, self.hi = cp.Parameter(n_w), cp.Parameter(n_w)
        linear = self.jac @ self.d
        self.below = linear[self.lower_rows] + t[self.lower_rows] >= self.lower
        self.above = linear[self.upper_rows] - t[self.upper_rows] <= self.upper
        objective = self.grad @ self.d + 0.5 * cp.sum_squares(self.factor @ self.d) + self.rho * cp.sum(t)
        self.problem = cp.Problem(cp.Minimize(objective), [self.below, self.above, self.d >= self.lo,
                                                           self.d <= self.hi])

    def compile(self, qp_solver: str) -> None:
        """Canonicalize now (cvxpy caches the map from parameters to the QP's data)."""
        with _cvxpy_quiet():
            self.problem.get_problem_data(qp_solver)

    def set_model(self, grad: np.ndarray, jac: sp.csc_matrix, factor: np.ndarray, rho: float) -> None:
        """∇f (n_w,), J (n_g × n_w, in `jac_pattern`), R (dense n_w × n_w, read in `factor_pattern`) and ρ."""
        self.grad.value, self.rho.value = grad, rho
        self.jac.value_sparse = sp.coo_array((jac.data, self.jac_pattern), shape=jac.shape)
        self.factor.value_sparse = sp.coo_array((factor[self.factor_pattern], self.factor_pattern),
                                                shape=factor.shape)

    def solve(self, g: np.ndarray, lo: np.ndarray, hi: np.ndarray, qp_solver: str,
              options: dict) -> tuple[np.ndarray, np.ndarray]:
        """The step d (n_w,) and lam_g (n_g,) for constant term g (n_g,) and box lo ≤ d ≤ hi (n_w,); raises
        cp.error.SolverError when the QP solver fails."""
        self.lower.value, self.upper.value = (self.lbg - g)[self.lower_rows], (self.ubg - g)[self.upper_rows]
        self.lo.value, self.hi.value = lo, hi
        with _cvxpy_quiet():
            self.problem.solve(solver=qp_solver, **options)
        if self.problem.status not in SOLVED:
            raise cp.error.SolverError(f"{qp_solver} ended with status {self.problem.status}")
        lam_g = np.zeros(len(self.lbg))
        lam_g[self.upper_rows] += self.above.dual_value
        lam_g[self.lower_rows] -= self.below.dual_value
        return np.asarray(self.d.value), lam_g


@dataclass
class _Settings:
    """The solver's options (see `SequentialConvex`)."""

    max_iterations: int
    max_wall_time: float
    tol: float
    qp_solver: str
    penalty: float
    max_penalty: float
    trust_radius: float
    qp_options: dict


@dataclass(frozen=True)
class _Model:
    """The subproblem's model at `point`: the trust-region scale s (n_w,) and H's factor R."""

    point: _Point
    scale: np.ndarray
    factor: np.ndarray
    """R (dense n_w × n_w upper triangular): the subproblem's H is RᵀR."""


class _Run:
    """One solve: the iteration state (iterate, penalty ρ, radius Δ, counters) and its steps."""

    def __init__(self, prepared: PreparedScp, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
                 curvature: _Curvature, max_wall_time: float) -> None:
        nlp, settings = prepared.nlp, prepared.settings
        self.subproblem, self.settings, self.curvature = prepared.subproblem, settings, curvature
        self.lbx, self.ubx = (np.asarray(b, dtype=float) for b in bounds)
        self.free = self.lbx < self.ubx
        self.evaluate = _Evaluator(prepared.functions, params, np.asarray(nlp.lbg, float), np.asarray(nlp.ubg, float))
        self.rho, self.radius = settings.penalty, settings.trust_radius
        self.deadline = time.perf_counter() + max_wall_time
        self.qps, self.accepted, self.corrections = 0, 0, 0
        self.lam_g: np.ndarray | None = None

    def limit(self) -> SolverStatus | None:
        """TIME_LIMIT or ITERATION_LIMIT when another QP is not allowed, else None."""
        if time.perf_counter() > self.deadline:
            return SolverStatus.TIME_LIMIT
        if self.qps >= self.settings.max_iterations:
            return SolverStatus.ITERATION_LIMIT
        return None

    def model(self, point: _Point) -> _Model:
        """Set the subproblem's model at `point` (fixed variables masked out) and the trust-region scale."""
        subproblem, mask = self.subproblem, self.free.astype(float)
        factor = _cholesky_upper(self.curvature.matrix(point) * np.outer(mask, mask))
        jac = point.jac.copy()
        jac.data *= mask[subproblem.jac_pattern[1]]
        subproblem.set_model(point.grad * mask, jac, factor, self.rho)
        scale = np.minimum(self.ubx - self.lbx, np.maximum(np.abs(point.w), 1.0))
        return _Model(point, scale, factor)

    def step(self, model: _Model, g: np.ndarray) -> np.ndarray:
        """The QP's step d (n_w,) with constant term g (n_g,) in the current trust region; fixed variables'
        entries are 0 and w + d stays inside the bounds."""
        w, reach = model.point.w, self.radius * model.scale
        lo = np.where(self.free, np.maximum(self.lbx - w, -reach), -1.0)
        hi = np.where(self.free, np.minimum(self.ubx - w, reach), 1.0)
        self.qps += 1
        d, self.lam_g = self.subproblem.solve(g, lo, hi, self.settings.qp_solver, self.settings.qp_options)
        return np.where(self.free, np.clip(d, lo, hi), 0.0)

    def predicted(self, model: _Model, d: np.ndarray) -> float:
        """φ(w) − model merit at w + d: the reduction the QP promises."""
        point, ev = model.point, self.evaluate
        linear = _violations(point.g + point.jac @ d, ev.lbg, ev.ubg).sum()
        return self.rho * (point.violation - linear) - point.grad @ d - 0.5 * np.sum((model.factor @ d) ** 2)

    def ratio(self, model: _Model, trial: _Point, predicted: float) -> float:
        """Actual over predicted merit reduction."""
        return (model.point.merit(self.rho) - trial.merit(self.rho)) / predicted

    def corrected(self, model: _Model, d: np.ndarray, trial: _Point, predicted: float) -> tuple[_Point, float]:
        """The better of `trial` and its second-order correction (the QP with g(w + d) − J d), by ratio."""
        ratio = self.ratio(model, trial, predicted)
        if ratio >= GOOD or self.limit() is not None:
            return trial, ratio
        self.corrections += 1
        lam_g = self.lam_g
        other = self.evaluate(model.point.w + self.step(model, trial.g - model.point.jac @ d))
        other_ratio = self.ratio(model, other, predicted)
        if other_ratio > ratio:
            return other, other_ratio
        self.lam_g = lam_g
        return trial, ratio

    def resize(self, model: _Model, trial: _Point, ratio: float) -> None:
        """Δ after a step with this ratio."""
        reached = np.any(np.abs(trial.w - model.point.w) >= 0.99 * self.radius * model.scale)
        if ratio < ACCEPT:
            self.radius *= SHRINK_REJECTED
        elif ratio >= GOOD and reached:
            self.radius = min(EXPAND * self.radius, MAX_RADIUS)
        elif ratio < POOR:
            self.radius *= SHRINK_POOR

    def converged(self, point: _Point, predicted: float) -> bool:
        """Whether the merit cannot be reduced further at this penalty."""
        return predicted <= self.settings.tol * max(1.0, abs(point.merit(self.rho))) or self.radius < MIN_RADIUS

    def raise_penalty(self) -> None:
        """ρ ×10 (at most `max_penalty`); Δ back to at least its initial value, as it may have collapsed."""
        self.rho = min(PENALTY_GROWTH * self.rho, self.settings.max_penalty)
        self.radius = max(self.radius, self.settings.trust_radius)

    def run(self, guess: np.ndarray) -> tuple[_Point, SolverStatus, str]:
        """Iterate from `guess` (clipped into the bounds) to a status; returns the last iterate."""
        point = self.evaluate(np.clip(guess, self.lbx, self.ubx))
        model = None
        while (status := self.limit()) is None:
            if model is None:
                model = self.model(point)
            d = self.step(model, point.g)
            predicted = self.predicted(model, d)
            if self.converged(point, predicted):
                if point.max_violation <= self.settings.tol:
                    return point, SolverStatus.CONVERGED, f"converged: predicted merit reduction {predicted:.1e}"
                if self.rho >= self.settings.max_penalty:
                    return point, SolverStatus.INFEASIBLE, f"infeasible: violation {point.max_violation:.1e} " \
                                                           f"at penalty {self.rho:g}"
                self.raise_penalty()
                model = None
                continue
            trial, ratio = self.corrected(model, d, self.evaluate(point.w + d), predicted)
            self.resize(model, trial, ratio)
            if ratio >= ACCEPT:
                self.curvature.update(point, trial)
                point, model, self.accepted = trial, None, self.accepted + 1
        return point, status, f"{status.value} after {self.qps} subproblems"

    def failed(self, guess: np.ndarray, start: float, message: str) -> SolverResult:
        """The FAILED result (w = the guess) of a solve that began at `start` (time.perf_counter s)."""
        return SolverResult(np.asarray(guess, dtype=float), SolverStatus.FAILED, self.qps,
                            time.perf_counter() - start, message)

    def stats(self, point: _Point) -> dict:
        """Counters and final state for SolverResult.stats."""
        return {"subproblems": self.qps, "accepted_steps": self.accepted, "corrections": self.corrections,
                "penalty": self.rho, "trust_radius": self.radius, "max_violation": point.max_violation,
                "objective": point.f}


@dataclass(frozen=True)
class PreparedScp(PreparedSolver):
    """The CasADi `functions` of `nlp`, its compiled convex `subproblem` and the solver's `settings`."""

    nlp: NLP
    functions: NLPFunctions
    subproblem: _Subproblem
    settings: _Settings

    def solve(self, guess: np.ndarray, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              max_wall_time: float | None = None, pace: int | None = None) -> SolverResult:
        params = np.asarray(params, dtype=float)
        curvature = _ExactCurvature(self.functions, params) if self.functions.hess_f is not None \
            else _DampedBfgs(self.nlp.x.numel())
        start = time.perf_counter()
        run = _Run(self, params, bounds, curvature,
                   time_limit(self.settings.max_wall_time, max_wall_time))
        try:
            point, status, message = run.run(np.asarray(guess, dtype=float))
        except cp.error.SolverError as exc:
            return run.failed(guess, start, f"QP solver failed: {exc}")
        except (RuntimeError, ValueError, np.linalg.LinAlgError) as exc:  # a failed evaluation or factorization
            return run.failed(guess, start, f"{type(exc).__name__}: {exc}")
        return SolverResult(point.w, status, run.qps, time.perf_counter() - start, message, run.stats(point),
                            run.lam_g)


class SequentialConvex(Solver):
    """Sequential convex programming (TrajOpt style): an ℓ1 penalty and a box trust region.

    Second-order corrections keep good steps (see the module docstring). `max_iterations` counts convex
    subproblems; `max_wall_time` is in seconds; `tol` bounds the constraint violation and the relative predicted
    merit reduction at convergence; `qp_solver` is a cvxpy solver name; `penalty` is the initial ρ,
    `max_penalty` its cap, `trust_radius` the initial Δ (relative to the scale s); extra keyword options go to
    cvxpy's `solve` (the QP solver's settings)."""

    name = "scp"

    def __init__(self, max_iterations: int = 300, max_wall_time: float = 60.0, tol: float = 1e-6,
                 qp_solver: str = "CLARABEL", penalty: float = 1.0, max_penalty: float = 1e4,
                 trust_radius: float = 0.1, **qp_options) -> None:
        self.settings = _Settings(max_iterations, max_wall_time, tol, qp_solver, penalty, max_penalty, trust_radius,
                                  qp_options)

    def prepare(self, nlp: NLP) -> PreparedScp:
        functions = NLPFunctions.build(nlp, objective_hessian=nlp.exact_hessian, constraint_hessian=False)
        n_w = nlp.x.numel()
        hessian_pattern = _hessian_pattern(functions, n_w)
        jac_pattern = tuple(np.asarray(i) for i in functions.jac_g.sparsity_out(0).get_triplet())
        subproblem = _Subproblem(jac_pattern, _factor_pattern(hessian_pattern), np.asarray(nlp.lbg, float),
                                 np.asarray(nlp.ubg, float), n_w)
        subproblem.compile(self.settings.qp_solver)
        return PreparedScp(nlp, functions, subproblem, self.settings)
