"""Any optimal control problem: describe it with `Ocp` (CasADi symbols), `solve` it with any registered
transcription and NLP solver, `certify` the solution by re-integrating its controls."""

from ocpkit.ocp.model import Ocp
from ocpkit.ocp.solve import Solution, solve

__all__ = ["Ocp", "Solution", "solve"]
