"""NLP solvers (registry `SOLVERS`, entry-point group `ocpkit.solvers`): `ipopt` through CasADi."""

from ocpkit.solvers.base import SOLVERS, Solver, SolverResult, SolverStatus

__all__ = ["SOLVERS", "Solver", "SolverResult", "SolverStatus"]
