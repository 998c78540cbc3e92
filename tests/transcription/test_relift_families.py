"""A refinement round's relift on both OCP families (the robot's and the path-timing baseline's) for every
transcription: the round runs and starts from the chain's own values at the moved check slots."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.nlp import Refinement
from ocpkit.path_spline import PathSpline
from ocpkit.planner.build_cache import build
from ocpkit.planner.refinement import solve_refined
from ocpkit.solvers import SolverResult, SolverStatus
from ocpkit.transcription.ocp import PathTimingOCP, RobotOCP

CASE2 = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
TIMING = ("state-limits", "torque", "torque-rate")
MOVED = Refinement(np.array([0.37, 0.81]))


class AtTheGuess:
    """A solver that 'converges' at once to the guess it is given, clipped into the bounds, and records it."""

    def __init__(self) -> None:
        self.starts: list[np.ndarray] = []

    def solve(self, guess, parameters, bounds, max_wall_time=None, pace=None):
        self.starts.append(np.array(guess))
        return SolverResult(np.clip(guess, *bounds), SolverStatus.CONVERGED, 1, 0.0, "converged")


def discretization(transcription: str, family: str):
    """The discretization of case 2 with 6 intervals for the robot OCP or the timing of a bent path."""
    if family == "robot":
        return build(CASE2, transcription, 6, constraints=("state-limits", "torque")).discretization
    middle = (CASE2.start + CASE2.goal) / 2 + 0.3
    waypoints = np.stack([CASE2.start, middle, CASE2.goal])
    path = PathSpline.fit(np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))]),
                          waypoints)
    ocp = PathTimingOCP(CASE2.robot, path)
    return build(CASE2, transcription, 6, constraints=TIMING, ocp=ocp).discretization.with_ocp(ocp)


@pytest.mark.parametrize("family", ["robot", "path-timing"])
@pytest.mark.parametrize("transcription", ["chebyshev", "lgl", "lgr", "trapezoidal", "hermite-simpson"])
def test_a_refinement_round_relifts_the_checks_of_either_family(transcription, family, monkeypatch):
    monkeypatch.setattr(sys.modules["ocpkit.planner.refinement"], "next_refinement", lambda *_: MOVED)
    disc = discretization(transcription, family)
    w = np.clip(disc.initial_guess(CASE2), *disc.bounds(CASE2))
    solver = AtTheGuess()
    refined = solve_refined(disc, solver, CASE2, w, rounds=1)
    assert refined.rounds == 1 and len(solver.starts) == 2
    layout = disc.nlp.variables
    first = disc.ocp.parts[0][0]  # "q" for a robot, "s" for the path timing
    lifted = layout.read(solver.starts[1], f"{first}_check")  # (m, checks) or (intervals, m): m chain values each
    assert (CASE2.robot.n if isinstance(disc.ocp, RobotOCP) else 1) in lifted.shape
    assert not np.allclose(solver.starts[1], solver.starts[0])  # the round moved the checks
    if family == "path-timing":
        assert np.all((lifted > -1e-9) & (lifted < 1 + 1e-9))  # path parameters s, not joint angles
