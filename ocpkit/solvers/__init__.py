"""NLP solvers (registry `SOLVERS`): `ipopt` through CasADi."""

from ocpkit.solvers import casadi_nlpsol  # noqa: F401  (registers the built-in solvers)
from ocpkit.solvers.base import SOLVERS, Solver, SolverResult, SolverStatus

__all__ = ["SOLVERS", "Solver", "SolverResult", "SolverStatus"]
