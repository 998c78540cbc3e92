"""Solvers reached through CasADi's nlpsol: `ipopt` (interior point, exact Hessian, MUMPS)."""

from __future__ import annotations

import time

import casadi as ca
import numpy as np

from ocpkit.solvers.base import Solver, SolverResult, SolverStatus
from ocpkit.transcription.base import NLP

_IPOPT_STATUS = {
    "Solve_Succeeded": SolverStatus.CONVERGED,
    "Solved_To_Acceptable_Level": SolverStatus.CONVERGED,
    "Infeasible_Problem_Detected": SolverStatus.INFEASIBLE,
    "Maximum_Iterations_Exceeded": SolverStatus.ITERATION_LIMIT,
    "Maximum_WallTime_Exceeded": SolverStatus.TIME_LIMIT,
    "Maximum_CpuTime_Exceeded": SolverStatus.TIME_LIMIT,
}


class Ipopt(Solver):
    """IPOPT with exact Hessian by CasADi AD and the MUMPS linear solver; extra keyword options go to
    IPOPT verbatim (e.g. tol=1e-8)."""

    name = "ipopt"

    def __init__(self, max_iterations: int = 1000, max_wall_time: float = 60.0, **ipopt_options) -> None:
        self.options = {"hessian_approximation": "exact", "linear_solver": "mumps", "print_level": 0,
                        "sb": "yes", "tol": 1e-6, "mu_strategy": "adaptive", "max_iter": max_iterations,
                        "max_wall_time": max_wall_time, **ipopt_options}
        self._prepared: dict[tuple, ca.Function] = {}

    def prepare(self, nlp: NLP) -> None:
        if nlp.shape_key not in self._prepared:
            problem = {"x": nlp.x, "p": nlp.p, "f": nlp.f, "g": nlp.g}
            options = {"ipopt": self.options, "print_time": False, "error_on_fail": False}
            self._prepared[nlp.shape_key] = ca.nlpsol("ipopt", "ipopt", problem, options)

    def solve(self, nlp: NLP, guess: np.ndarray, params: np.ndarray,
              bounds: tuple[np.ndarray, np.ndarray]) -> SolverResult:
        self.prepare(nlp)
        solver = self._prepared[nlp.shape_key]
        start = time.perf_counter()
        out = solver(x0=guess, p=params, lbx=bounds[0], ubx=bounds[1], lbg=nlp.lbg, ubg=nlp.ubg)
        wall = time.perf_counter() - start
        stats = solver.stats()
        message = stats.get("return_status", "unknown")
        return SolverResult(np.asarray(out["x"]).ravel(), _IPOPT_STATUS.get(message, SolverStatus.FAILED),
                            int(stats.get("iter_count", 0)), wall, message, stats)


