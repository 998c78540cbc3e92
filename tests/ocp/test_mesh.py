"""`ocpkit.ocp.mesh`: segments broken at the control's switches, against the double integrator's closed form
(one switch at half the horizon, T* = 2), and the warm start it rests on."""

from __future__ import annotations

import numpy as np
import pytest

from ocpkit.errors import OptionError
from ocpkit.ocp import solve
from ocpkit.ocp.mesh import adapt, refine, switch_times
from ocpkit.problems import CLASSICS

BANG_BANG = CLASSICS["double-integrator"]


@pytest.fixture(scope="module")
def coarse():
    return solve(BANG_BANG.build(), "chebyshev", 40)


def test_the_switch_is_found_at_half_the_horizon(coarse):
    breaks = switch_times(coarse)
    assert breaks and all(abs(b - 0.5) < 0.02 for b in breaks)


def test_segments_ending_at_the_switch_beat_one_polynomial(coarse):
    error = lambda s: abs(s.objective - BANG_BANG.optimum) / BANG_BANG.optimum  # noqa: E731
    refined = refine(coarse, knots=10)
    breaks = refined.discretization.grid.breaks
    assert refined.converged and set(switch_times(coarse)) <= set(breaks) and np.diff((0, *breaks, 1)).max() <= 0.25
    assert error(refined) < error(coarse) / 5 and error(refined) < 1e-4
    assert refined.knots == 10 and refined.transcription == "chebyshev"


def test_nothing_to_refine_without_a_switch():
    smooth = solve(CLASSICS["brachistochrone"].build(), "lgr", 12)
    assert switch_times(smooth) == () and refine(smooth) is smooth


def test_a_mesh_transcription_is_refused(coarse):
    mesh = solve(BANG_BANG.build(), "trapezoidal", 20)
    with pytest.raises(OptionError, match="no segments"):
        refine(mesh)


def test_a_warm_start_begins_at_the_solution_and_stays_there(coarse):
    w = coarse.discretization.encode(coarse.trajectory)  # the start `solve(start=...)` takes
    np.testing.assert_allclose(w, coarse.result.w, atol=1e-9)
    again = solve(BANG_BANG.build(), "chebyshev", 40, start=coarse)
    assert again.converged and again.iterations <= coarse.iterations
    assert again.objective == pytest.approx(coarse.objective, rel=1e-8)


def test_adapt_refines_once_and_falls_back_to_equal_segments():
    solves = adapt(BANG_BANG.build(), "lgr", 40, segment_knots=10)
    assert len(solves) == 2 and solves[0].segments == 1 and solves[1].segments > 1
    assert abs(solves[-1].objective - BANG_BANG.optimum) < abs(solves[0].objective - BANG_BANG.optimum)
    stopped = adapt(BANG_BANG.build(), "lgr", 40, segment_knots=10, rounds=0, solver_options={"max_iter": 3})
    assert [s.segments for s in stopped] == [1, 4] and not stopped[0].converged
