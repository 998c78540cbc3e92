"""Solvers reached through CasADi's nlpsol: `ipopt` (interior point, exact Hessian, MUMPS), `sqpmethod`
(SQP, exact Hessian, a CasADi QP solver per step), `blocksqp` (SQP with quasi-Newton Hessian blocks) and
`fatrop` (structure-exploiting interior point, given our NLP as one stage).

All share `CasadiNlpsol`: `prepare` creates the nlpsol of one NLP (a `PreparedNlpsol`); limits and status
mapping from `solver.stats()` (`success`, `return_status`, `iter_count`, `unified_return_status`), and a
CasADi RuntimeError during a solve reported as status `failed` with its message instead of an exception.

Time limits: IPOPT and sqpmethod stop through CasADi's `iteration_callback` (`_Deadline`, checked once per
iteration), at the solver's `max_wall_time` or the one passed to `PreparedSolver.solve` for that call, and with a
`pace` as soon as that many iterations at the pace so far would not fit in the limit. The same
callback stops a diverging solve: an iterate beyond its variable bounds (lbx, ubx) by more than DIVERGED
(relative to the bound's width, at least 1 in the variable's unit; sqpmethod after a failed QP can step outside
and come back, so a small excursion is left to the check of the final iterate) is reported `failed` at once
instead of running on. blocksqp and
fatrop ignore the iteration callback and have no wall-time option, so they cannot be interrupted: an
unconverged solve that overran its limit is reported as `time_limit` after the fact.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from abc import abstractmethod
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ocpkit.errors import OptionError
from ocpkit.nlp import NLP, Stages
from ocpkit.solvers.base import (BOUND_TOLERANCE, STAGES_NEEDED, PreparedSolver, Solver, SolverResult, SolverStatus,
                                 bound_slack, time_limit)
from ocpkit.solvers.pointwise import pointwise_derivatives

_UNIFIED_STATUS = {
    "SOLVER_RET_SUCCESS": SolverStatus.CONVERGED,
    "SOLVER_RET_INFEASIBLE": SolverStatus.INFEASIBLE,
    "SOLVER_RET_LIMITED": SolverStatus.ITERATION_LIMIT,
}


def hessian_approximation(nlp: NLP) -> str:
    """The `hessian_approximation` option for this NLP: "exact" unless its derivatives stop at first order."""
    return "exact" if nlp.exact_hessian else "limited-memory"


@contextlib.contextmanager
def _silenced_stdout():
    """Send the process's standard output (file descriptor 1) to /dev/null: qpOASES prints its licence banner
    from C++ whenever a QP solver is created (sqpmethod: at set-up; blocksqp: every solve), options or not."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _last_line(exc: Exception) -> str:
    """The innermost message of a CasADi error (its last line, without the source location)."""
    line = str(exc).strip().splitlines()[-1]
    return line.split(" failed: ", 1)[-1] if "Assertion" in line else line


DIVERGED = 1.0
"""An iterate this far beyond a bound (times the bound's width, at least 1) has diverged."""


PACE_FROM = 3
"""Callback calls (the start and the iterations after it) before a pace is judged: the first ones carry the
solve's own start-up."""


class _Deadline(ca.Callback):
    """nlpsol iteration callback that asks the solver to stop once the deadline (time.perf_counter s) has
    passed, once its `pace` of iterations cannot end by the deadline, or (when it `watches_bounds`) the iterate has
    left its bounds; `reason` ("deadline", "pace", "bounds" or "") says which."""

    def __init__(self, n_w: int, n_g: int, n_p: int, watches_bounds: bool = True) -> None:
        ca.Callback.__init__(self)
        self.sizes = {"x": n_w, "lam_x": n_w, "g": n_g, "lam_g": n_g, "lam_p": n_p, "f": 1}
        self.watches_bounds = watches_bounds
        self.arm(np.inf, np.full(n_w, -np.inf), np.full(n_w, np.inf))
        self.construct("deadline", {})

    def arm(self, deadline: float, lbx: np.ndarray, ubx: np.ndarray, pace: int | None = None) -> None:
        """Watch one solve, from now: stop at `deadline` (time.perf_counter s), as soon as `pace` iterations at the
        pace so far would end after it, or when the iterate has diverged from [lbx, ubx] (n_w,) (module
        docstring)."""
        self.deadline, self.reason, self.pace = deadline, "", pace
        self.started, self.iterations = time.perf_counter(), 0
        slack = DIVERGED * bound_slack(lbx, ubx) / BOUND_TOLERANCE
        self.lower, self.upper = lbx - slack, ubx + slack

    def get_n_in(self) -> int:
        return ca.nlpsol_n_out()

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return ca.nlpsol_out(i)

    def get_name_out(self, i: int) -> str:
        return "stop"

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(self.sizes[ca.nlpsol_out(i)], 1)

    def _outside(self, x: np.ndarray) -> bool:
        """Whether the iterate x (n_w,) has left [lower, upper]."""
        return not np.all((x >= self.lower) & (x <= self.upper))

    def eval(self, arg: list) -> list:
        try:
            self.iterations += 1
            now = time.perf_counter()
            if self.watches_bounds and self._outside(np.asarray(arg[0]).ravel()):
                self.reason = "bounds"
            elif now > self.deadline:
                self.reason = "deadline"
            elif self.pace and self.iterations >= PACE_FROM and \
                    self.started + self.pace * (now - self.started) / self.iterations > self.deadline:
                self.reason = "pace"
        except KeyboardInterrupt:  # Ctrl-C landed in this callback: stop the solve (ocpkit.interrupt re-raises it)
            self.reason = "interrupted"
        return [1 if self.reason else 0]


_STOPPED = {"deadline": SolverStatus.TIME_LIMIT, "pace": SolverStatus.TIME_LIMIT, "bounds": SolverStatus.FAILED,
            "interrupted": SolverStatus.FAILED}
"""Our status when the `_Deadline` callback stopped the solve, by its reason."""
_STOP_MESSAGES = {"deadline": "stopped at the wall-time limit",
                  "pace": "stopped: at its pace, its iterations would not end within the wall-time limit",
                  "bounds": "stopped: iterate outside its bounds",
                  "interrupted": "stopped by Ctrl-C"}


@dataclass(frozen=True)
class PreparedNlpsol(PreparedSolver):
    """The nlpsol `function` of `nlp`, its deadline callback (for plugins that stop by callback, else None)
    and the `owner` solver whose limits and status table apply."""

    nlp: NLP
    function: ca.Function
    deadline: _Deadline | None
    owner: CasadiNlpsol

    def solve(self, guess: np.ndarray, params: np.ndarray, bounds: tuple[np.ndarray, np.ndarray],
              max_wall_time: float | None = None, pace: int | None = None) -> SolverResult:
        """See `PreparedSolver.solve`; blocksqp and fatrop cannot be stopped at `max_wall_time` nor by `pace`
        (module docstring)."""
        start = time.perf_counter()
        limit = time_limit(self.owner.max_wall_time, max_wall_time)
        if self.deadline is not None:
            self.deadline.arm(start + limit, *(np.asarray(b, dtype=float) for b in bounds), pace)
        try:
            with _silenced_stdout():
                out = self.function(x0=guess, p=params, lbx=bounds[0], ubx=bounds[1],
                                    lbg=self.nlp.lbg, ubg=self.nlp.ubg)
            stats = self.function.stats()
        except RuntimeError as exc:  # a plugin's assertion or failed evaluation: a status, not a crash
            return SolverResult.failed(guess, start, str(exc))
        wall = time.perf_counter() - start
        message = str(stats.get("return_status", stats.get("unified_return_status", "unknown")))
        stopped = self.deadline.reason if self.deadline is not None else ""
        status = _STOPPED.get(stopped) or self.owner.status(stats, message, wall > limit)
        return SolverResult(np.asarray(out["x"]).ravel(), status, self.owner.iterations(stats), wall,
                            _STOP_MESSAGES.get(stopped, message), stats,
                            np.asarray(out["lam_g"]).ravel(), np.asarray(out["lam_x"]).ravel())


class CasadiNlpsol(Solver):
    """A CasADi nlpsol plugin on the NLP; subclasses give the plugin name, its options and its return_status
    table. `max_wall_time` is in seconds."""

    plugin: str
    statuses: dict = {}
    """The plugin's `return_status` → our status; statuses not listed go by CasADi's unified status."""
    stops_by_callback = False
    """Whether the plugin honours nlpsol's `iteration_callback` (then used for the time limit)."""
    stays_in_bounds = False
    """Whether every iterate keeps within its variable bounds (then the callback does not check them)."""

    def __init__(self, max_iterations: int = 1000, max_wall_time: float = 60.0) -> None:
        self.max_iterations, self.max_wall_time = max_iterations, max_wall_time

    @abstractmethod
    def plugin_options(self, nlp: NLP) -> dict:
        """nlpsol options of the plugin for this NLP (limits included)."""

    def prepare(self, nlp: NLP) -> PreparedNlpsol:
        problem = {"x": nlp.x, "p": nlp.p, "f": nlp.f, "g": nlp.g}
        options = {"print_time": False, "record_time": True, "error_on_fail": False, **self.plugin_options(nlp)}
        deadline = _Deadline(nlp.x.numel(), nlp.g.numel(), nlp.p.numel(), not self.stays_in_bounds) \
            if self.stops_by_callback else None
        if deadline is not None:
            options["iteration_callback"] = deadline
        try:
            with _silenced_stdout():
                function = ca.nlpsol(self.name, self.plugin, problem, options)
        except RuntimeError as exc:  # an option or structure the plugin rejects: the caller's choice
            raise OptionError(f"{self.name} cannot be set up for this NLP: {_last_line(exc)}") from exc
        return PreparedNlpsol(nlp, function, deadline, self)

    def iterations(self, stats: dict) -> int:
        """Iterations the plugin took, from its stats."""
        return int(stats.get("iter_count") or 0)

    def status(self, stats: dict, message: str, overran: bool) -> SolverStatus:
        """Our status from the plugin's stats: its own table, then CasADi's unified status and the limits
        (`overran`: the solve took longer than its wall-time limit)."""
        if message in self.statuses:
            return self.statuses[message]
        if stats.get("success"):
            return SolverStatus.CONVERGED
        if overran:
            return SolverStatus.TIME_LIMIT
        if self.iterations(stats) >= self.max_iterations:
            return SolverStatus.ITERATION_LIMIT
        return _UNIFIED_STATUS.get(stats.get("unified_return_status"), SolverStatus.FAILED)


class Ipopt(CasadiNlpsol):
    """IPOPT (interior point) with the exact Hessian and the MUMPS linear solver.

    L-BFGS stands in when the NLP has no exact Hessian. The constraint Jacobian and the Hessian are built point
    by point where the NLP has point calls (ocpkit.solvers.pointwise: the same values, a cheaper set-up), the
    dynamics rows' through point derivatives compiled to C once per robot and machine (ocpkit.solvers.compiled) and
    the collision rows' through hand-written C (ocpkit.solvers.collision_derivatives), unless `compiled` is False;
    extra keyword options go to IPOPT verbatim (e.g. tol=1e-8). MUMPS starts without threshold pivoting
    (mumps_pivtol 0; IPOPT raises it towards mumps_pivtolmax whenever a solve comes out inaccurate) and orders the
    KKT system by approximate minimum fill (mumps_pivot_order 2, where MUMPS's automatic choice takes PORD), both
    faster on our KKT systems. The barrier parameter stays below mu_max = 10⁻³ (IPOPT's default 10⁵): the adaptive
    strategy otherwise falls back to a monotone barrier of ~0.1 on a slow iterate, which pushes a start near a
    solution far from it: t_f up towards its bound, then slowly back (figures: docs/design-notes.md)."""

    name = plugin = "ipopt"
    statuses = {
        "Solve_Succeeded": SolverStatus.CONVERGED,
        "Solved_To_Acceptable_Level": SolverStatus.CONVERGED,
        "Infeasible_Problem_Detected": SolverStatus.INFEASIBLE,
        "Maximum_Iterations_Exceeded": SolverStatus.ITERATION_LIMIT,
        "Maximum_WallTime_Exceeded": SolverStatus.TIME_LIMIT,
        "Maximum_CpuTime_Exceeded": SolverStatus.TIME_LIMIT,
    }
    stops_by_callback = True  # the wall-time limit, per call (module docstring)
    stays_in_bounds = True  # an interior point

    def __init__(self, max_iterations: int = 1000, max_wall_time: float = 60.0, compiled: bool = True,
                 **ipopt_options) -> None:
        super().__init__(max_iterations, max_wall_time)
        self.compiled = compiled
        self.options = {"linear_solver": "mumps", "print_level": 0, "sb": "yes", "tol": 1e-6,
                        "mu_strategy": "adaptive", "mumps_pivtol": 0.0, "mumps_pivot_order": 2,
                        "mu_max": 1e-3, "max_iter": max_iterations, **ipopt_options}

    def plugin_options(self, nlp: NLP) -> dict:
        derivatives = pointwise_derivatives(nlp, self.compiled) if nlp.point_calls and nlp.exact_hessian else {}
        return {"ipopt": {"hessian_approximation": hessian_approximation(nlp), **self.options}, **derivatives,
                **NO_PARAMETER_MULTIPLIERS}


NO_PARAMETER_MULTIPLIERS = {"no_nlp_grad": True, "calc_lam_p": False}
"""nlpsol options: no multipliers of the parameters p (nothing reads them), so nlpsol does not build the reverse
derivative of the whole NLP (`nlp_grad`), most of its construction on a large NLP (figures: docs/design-notes.md)."""

_QPSOL_QUIET = {"qpoases": {"printLevel": "none"}, "osqp": {"osqp": {"verbose": False}}}
"""Per QP solver: options that silence it (all also get error_on_fail False: a failed QP ends the SQP)."""


class SqpMethod(CasadiNlpsol):
    """CasADi's SQP (`sqpmethod`) with exact Hessian (L-BFGS when the NLP has none) and line search.

    `qpsol` names the QP solver: qpoases (dense active set, the default: it handles the indefinite
    Hessians of nonconvex NLPs, where osqp's convex ADMM diverges), osqp (sparse ADMM: faster on the paper
    cases, where it converges), proxqp (hits the time limit on the paper cases),
    hpipm (needs a stage-wise OCP structure that our NLPs lack: refused with an OptionError).
    `convexify_strategy` ("regularize", "eigen-clip", "eigen-reflect") convexifies the Lagrangian Hessian:
    off (None) by default, as the paper cases converge without it, "regularize" stalls case 2 at the
    iteration limit and "eigen-clip" with osqp fails in the first QP. The time limit is checked between SQP
    iterations, so one long QP (qpoases' first, cold-started, or one on a diverging iterate; figures:
    docs/design/moved-from-code.md) can overrun it; an iterate that leaves its bounds (after a failed QP) stops
    the solve at once (module docstring). Extra keyword options go to sqpmethod verbatim."""

    name = plugin = "sqpmethod"
    statuses = {
        "Solve_Succeeded": SolverStatus.CONVERGED,
        "Maximum_Iterations_Exceeded": SolverStatus.ITERATION_LIMIT,
    }
    stops_by_callback = True

    def __init__(self, max_iterations: int = 200, max_wall_time: float = 60.0, qpsol: str = "qpoases",
                 convexify_strategy: str | None = None, tol: float = 1e-6, **sqp_options) -> None:
        super().__init__(max_iterations, max_wall_time)
        qp_options = {"error_on_fail": False, **_QPSOL_QUIET.get(qpsol, {})}
        self.options = {"qpsol": qpsol, "qpsol_options": qp_options, "max_iter": max_iterations, "tol_pr": tol,
                        "tol_du": tol, "print_header": False, "print_iteration": False, "print_status": False,
                        **sqp_options}
        if convexify_strategy is not None:
            self.options["convexify_strategy"] = convexify_strategy

    def plugin_options(self, nlp: NLP) -> dict:
        return {"hessian_approximation": hessian_approximation(nlp), **self.options}


class BlockSqp(CasadiNlpsol):
    """blockSQP (Janka et al.) via CasADi: SQP with damped BFGS Hessian blocks and a filter line search.

    Runs without HSL: CasADi's blockSQP defaults to qpOASES' Schur-complement QP, which needs the HSL
    `ma27` linear solver; we use the dense qpOASES QP (`schur` off, `linsol` "ldl"), which also means BFGS
    instead of SR1 updates. It cannot take an NLP without second derivatives (a callback dynamics backend):
    CasADi's blocksqp differentiates the constraint Jacobian at set-up even for BFGS (an OptionError from
    `prepare`). It has no time limit (see the module docstring) and reports no iteration count:
    we count its gradient-and-Jacobian evaluations, one per SQP iteration. Extra keyword options go to
    blocksqp verbatim."""

    name = plugin = "blocksqp"

    def __init__(self, max_iterations: int = 500, max_wall_time: float = 60.0, tol: float = 1e-6,
                 **blocksqp_options) -> None:
        super().__init__(max_iterations, max_wall_time)
        self.options = {"linsol": "ldl", "schur": False, "hess_update": 2, "max_iter": max_iterations,
                        "opttol": tol, "nlinfeastol": tol, "print_header": False, "print_iteration": False,
                        "print_maxit_reached": False, **blocksqp_options}

    def plugin_options(self, nlp: NLP) -> dict:
        return self.options

    def iterations(self, stats: dict) -> int:
        return int(stats.get("n_call_nlp_gf_jg", 0))


class Fatrop(CasadiNlpsol):
    """fatrop (structure-exploiting interior point) with exact Hessian, given the NLP's stage structure.

    fatrop wants a stage-wise OCP: w = [x_0, u_0, ..., x_N], gap-closing rows x_{k+1} − F(x_k, u_k) = 0, every
    other row and objective term reading one stage (ocpkit.nlp.Stages). A staged NLP (the mesh transcriptions
    with `staged=True`, which `ocpkit.build` asks for by itself) is handed over with that structure (manual
    mode), and fatrop's Riccati recursion runs stage by stage. An NLP without it (pseudospectral: the
    differentiation matrix couples every knot with every other) runs only when asked with `single_stage=True`:
    one stage (N = 0) whose "controls" are all of w and whose stage rows are all of g, one dense factorization per
    iteration, far slower than IPOPT on the same NLP. It needs the exact Hessian: an NLP without one (a callback
    dynamics backend) is refused with an OptionError. Extra keyword options go to fatrop verbatim."""

    name = plugin = "fatrop"
    statuses = {"0": SolverStatus.CONVERGED}
    needs_stages = True

    def __init__(self, max_iterations: int = 1000, max_wall_time: float = 60.0, tol: float = 1e-6,
                 single_stage: bool = False, **fatrop_options) -> None:
        super().__init__(max_iterations, max_wall_time)
        self.single_stage = single_stage
        self.options = {"print_level": 0, "max_iter": max_iterations, "tol": tol, **fatrop_options}

    def plugin_options(self, nlp: NLP) -> dict:
        if not nlp.exact_hessian:
            raise OptionError("fatrop needs the exact Hessian, and this NLP's dynamics backend gives first "
                              "derivatives only; use a symbolic backend (casadi, casadi-rnea) or another solver")
        if not nlp.stages and not self.single_stage:
            raise OptionError(STAGES_NEEDED.format(solver=self.name, what="this NLP"))
        equality = [bool(e) for e in np.asarray(nlp.lbg) == np.asarray(nlp.ubg)]
        structure = _stages(nlp.stages) if nlp.stages else _single_stage(nlp)
        return {"structure_detection": "manual", **structure, "equality": equality, "fatrop": self.options}


def _stages(stages: Stages) -> dict:
    """fatrop's stage options (N, nx, nu, ng) for an NLP with this stage structure (ocpkit.nlp.Stages): N
    intervals, N + 1 stages."""
    return {"N": len(stages.nx) - 1, "nx": list(stages.nx), "nu": list(stages.nu), "ng": list(stages.ng)}


def _single_stage(nlp: NLP) -> dict:
    """fatrop's stage options (N, nx, nu, ng) for `nlp` as one stage: no states, all of w (n_w) as its controls
    and all of g (n_g) as its stage constraints."""
    return {"N": 0, "nx": [0], "nu": [nlp.x.numel()], "ng": [nlp.g.numel()]}
