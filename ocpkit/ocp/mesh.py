"""Segments that end where the optimal control switches, for the pseudospectral transcriptions.

A bang-bang, singular or constrained optimum is smooth between its switches: one polynomial across a switch
converges slowly (Gibbs), segments that end at the switches converge fast again (the idea of h-p methods, e.g.
Darby, Hager & Rao 2011). `refine` finds the switches in a solution, breaks the horizon there and solves again,
warm-started from the solution; `adapt` is a first solve and a refinement in one call."""

from __future__ import annotations

import numpy as np

from ocpkit.errors import OptionError
from ocpkit.ocp.model import Ocp
from ocpkit.ocp.solve import Solution, solve
from ocpkit.transcription import TRANSCRIPTIONS
from ocpkit.transcription.pseudospectral import Pseudospectral

AT_BOUND = 1e-3
"""A control is at a bound within this fraction of its range."""
CLOSEST = 0.02
"""Switches closer than this fraction of the horizon are one break; none this close to either end."""


def switch_times(solution: Solution) -> tuple[float, ...]:
    """Fractions τ ∈ (0, 1) of the horizon where a control with finite bounds switches, read from its knot values
    (the interpolant between them oscillates near a switch): between two knots where it reaches or leaves a
    bound, or jumps from one bound to the other (the middle of the two). A control that stays off its bounds
    switches nowhere, however far it travels."""
    tau = (solution.knot_times - solution.t0) / solution.trajectory.tf
    found = []
    for variable in solution.model.controls:
        values = np.reshape(solution.u(variable.name, solution.knot_times), (len(tau), -1))
        for k in np.flatnonzero(np.isfinite(variable.lower) & np.isfinite(variable.upper)):
            v = (values[:, k] - variable.lower[k]) / (variable.upper[k] - variable.lower[k])
            at_bound = (v < AT_BOUND) | (v > 1.0 - AT_BOUND)
            flip = np.flatnonzero(at_bound[:-1] & at_bound[1:] & (np.diff(np.sign(v - 0.5)) != 0))
            change = np.flatnonzero(at_bound[:-1] != at_bound[1:])
            found += list((tau[flip] + tau[flip + 1]) / 2) + list((tau[change] + tau[change + 1]) / 2)
    breaks: list[float] = []
    for value in sorted(b for b in found if CLOSEST < b < 1.0 - CLOSEST):
        if breaks and value - breaks[-1] < CLOSEST:
            continue
        breaks.append(value)
    return tuple(breaks)


def refine(solution: Solution, knots: int = 10, longest: float = 0.25, solver: str = "ipopt",
           solver_options: dict | None = None) -> Solution:
    """`solution`'s problem solved again with its pseudospectral transcription on segments of `knots` intervals
    each (fewer where the transcription's max_intervals needs it), broken at `switch_times(solution)` and, where
    two breaks are more than `longest` (a fraction of the horizon) apart, equally between them, from `solution`;
    the solution itself when nothing switches."""
    method = TRANSCRIPTIONS.get(solution.transcription)
    if not issubclass(method, Pseudospectral):
        raise OptionError(f"refine: {solution.transcription} has no segments to break; use chebyshev, lgl or lgr")
    switches = switch_times(solution)
    if not switches:
        return solution
    ends = (0.0, *switches, 1.0)
    breaks = tuple(float(b) for first, last in zip(ends, ends[1:])
                   for b in np.linspace(first, last, int(np.ceil((last - first) / longest)) + 1)[1:])[:-1]
    knots = min(knots, method.max_intervals // (len(breaks) + 1))  # OptionError below the family's least
    return solve(solution.model, solution.transcription, knots, solver, {"breaks": breaks}, solver_options,
                 start=solution)


def adapt(model: Ocp, transcription: str, knots: int = 40, segment_knots: int = 10, rounds: int = 1,
          solver: str = "ipopt", solver_options: dict | None = None) -> list[Solution]:
    """Solve `model` for a non-smooth optimum: on one segment of `knots` intervals (on knots // segment_knots
    equal segments of `segment_knots` when that does not converge), then `rounds` times `refine`. Every solve in
    order; the last is the answer."""
    solves = [solve(model, transcription, knots, solver, solver_options=solver_options)]
    if not solves[-1].converged:
        solves.append(solve(model, transcription, segment_knots, solver,
                            {"segments": max(1, knots // segment_knots)}, solver_options))
    for _ in range(rounds):
        refined = refine(solves[-1], segment_knots, solver=solver, solver_options=solver_options)
        if refined is solves[-1]:
            break
        solves.append(refined)
    return solves
