"""NLP solvers (registry `SOLVERS`, entry-point group `ocpkit.solvers`), all behind the `Solver` interface
(base.py): `ipopt`, `sqpmethod`, `blocksqp`, `fatrop` (CasADi nlpsol, casadi_nlpsol.py), `scipy-slsqp`,
`scipy-trust-constr` (scipy_minimize.py), `pyomo` (pyomo_nlp.py) and `scp` (scp.py)."""

from ocpkit.solvers.base import SOLVERS, PreparedSolver, Solver, SolverResult, SolverStatus, bound_slack

__all__ = ["SOLVERS", "PreparedSolver", "Solver", "SolverResult", "SolverStatus", "bound_slack"]
