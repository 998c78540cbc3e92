"""Active-set screening of collision rows (ocpkit.planner.screening, SphereCollision.screened / missing)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from ocpkit.constraints import make_constraints
from ocpkit.constraints.collision import SphereCollision
from ocpkit.formats.scenario import load_scenario
from ocpkit.geometry.clearances import clearances, sphere_centers_batch
from ocpkit.planner.build_cache import clear_builds, layout, shape
from ocpkit.planner.options import SimultaneousOptions
from ocpkit.planner.screening import (CROWDED_DISTANCE, CROWDED_ROWS, SCREEN_DISTANCE, line_samples, missing,
                                     screenable_rows, screened, worth_screening)
from ocpkit.planner.simultaneous import END_CHECK_CLEARANCE, _checked_near_the_ends, plan_simultaneous
from ocpkit.solvers import SolverStatus
from ocpkit.transcription.pseudospectral import long_interval_midpoints
from tests.helpers import REPO

PANDA = load_scenario(REPO / "scenarios/mbm/panda/table_pick/0001.yaml")
PAPER = load_scenario(REPO / "scenarios/paper/case2.yaml")
PLAN_OPTIONS = SimultaneousOptions(transcription="chebyshev")


def test_screening_keeps_exactly_the_terms_close_to_some_configuration():
    full = SphereCollision(PANDA)
    near = line_samples(PANDA)
    kept = full.screened(PANDA, near, 0.2)
    c = clearances(PANDA.robot, PANDA.scene, sphere_centers_batch(PANDA.robot, near))
    assert np.array_equal(kept.pair_mask, full.pair_mask & (c.self_pairs.min(axis=0) < 0.2))
    assert np.array_equal(kept.obstacle_mask, full.obstacle_mask & (c.obstacles.min(axis=0) < 0.2))
    assert 0 < kept.term_count < full.term_count / 2  # far fewer rows, but not none
    assert kept.shape() != full.shape()  # a screened build is a different build
    assert full.term_count == len(full.pairs) + full.obstacle_mask.sum()  # no workspace in MBM scenes


def test_missing_counts_the_left_out_terms_near_other_configurations():
    near = line_samples(PANDA)
    kept = SphereCollision(PANDA).screened(PANDA, near, 0.2)
    assert kept.missing(PANDA, near, 0.1) == 0  # everything within 0.2 m there is kept
    rng = np.random.default_rng(0)
    elsewhere = rng.uniform(PANDA.robot.q_lower, PANDA.robot.q_upper, (50, PANDA.robot.n))
    c = clearances(PANDA.robot, PANDA.scene, sphere_centers_batch(PANDA.robot, elsewhere))
    close = (c.self_pairs.min(axis=0) < 0.1) & kept.pair_mask.__invert__() & SphereCollision(PANDA).pair_mask
    assert kept.missing(PANDA, elsewhere, 0.1) >= close.sum() > 0


def test_a_crowded_nlp_is_screened_tighter_and_rebuilt_sooner():
    near = line_samples(PANDA)
    wide = screenable_rows(make_constraints(PANDA, screen=(near, SCREEN_DISTANCE)))
    assert wide > CROWDED_ROWS  # an MBM Panda problem keeps hundreds of terms a point at 0.2 m
    crowded = screened(PANDA, ("collision",), near)
    assert crowded[0].screened_at == CROWDED_DISTANCE
    assert crowded[0].term_count == SphereCollision(PANDA).screened(PANDA, near, CROWDED_DISTANCE).term_count < wide
    sparse = screened(PAPER, ("collision",), line_samples(PAPER))
    assert sparse[0].screened_at == SCREEN_DISTANCE  # the paper's cases keep a handful: the wide screen
    assert screenable_rows(sparse) <= CROWDED_ROWS
    rng = np.random.default_rng(0)
    elsewhere = rng.uniform(PANDA.robot.q_lower, PANDA.robot.q_upper, (50, PANDA.robot.n))
    assert missing(PANDA, crowded, elsewhere) == crowded[0].missing(PANDA, elsewhere, CROWDED_DISTANCE / 2) > 0
    assert missing(PANDA, crowded, near) == 0


def test_constraints_with_any_collision_terms_are_worth_screening():
    assert worth_screening(make_constraints(PANDA))
    assert worth_screening(make_constraints(PAPER))  # the paper's robot screens too
    assert not worth_screening(make_constraints(PAPER, ("state-limits", "torque", "torque-rate")))


def test_other_constraints_are_not_screened():
    made = make_constraints(PANDA, screen=(line_samples(PANDA), 0.2))
    unscreened = make_constraints(PANDA)
    assert [c.shape() for c in made[:-1]] == [c.shape() for c in unscreened[:-1]]


@pytest.mark.slow
def test_a_screened_plan_is_verified_on_every_term():
    plan = plan_simultaneous(PAPER, fallbacks=(), screen=True)
    assert plan.status == "verified"  # verification checks every term, screened or not
    assert plan.stats.screening.rows_per_point < SphereCollision(PAPER).term_count


def test_every_knot_interval_is_checked_when_asked():
    points = np.cos(np.pi * np.arange(13) / 12)  # Chebyshev–Lobatto, N = 12
    long_only, every = long_interval_midpoints(points), long_interval_midpoints(points, every=True)
    assert len(every) == 12 and len(long_only) == 8  # sin θ ≥ ½ keeps the middle 8 of 12
    assert set(np.round(long_only, 12)) <= set(np.round(every, 12))
    assert np.all((every[:-1] - points[1:-1]) * (every[1:] - points[1:-1]) < 0)  # one between each pair of knots


def test_a_plan_checks_near_the_ends_when_an_end_is_close_to_contact_unless_told_otherwise():
    assert PANDA.end_clearances.smallest() < END_CHECK_CLEARANCE  # MBM's goal on the table
    assert _checked_near_the_ends(PANDA, PLAN_OPTIONS).transcription_options == {"end_checks": True}
    assert PAPER.end_clearances.smallest() >= END_CHECK_CLEARANCE
    assert _checked_near_the_ends(PAPER, PLAN_OPTIONS) is PLAN_OPTIONS  # the paper's ends are clear of everything
    told = dataclasses.replace(PLAN_OPTIONS, transcription_options={"end_checks": False})
    assert _checked_near_the_ends(PANDA, told) is told
    mesh = dataclasses.replace(PLAN_OPTIONS, transcription="trapezoidal")
    assert _checked_near_the_ends(PANDA, mesh) is mesh  # a mesh transcription has no such option


def test_a_guess_near_left_out_rows_is_screened_with_them_before_the_rows_are_built(monkeypatch):
    """The guess is encoded on the shape without constraints; the rows are built once, screened by the line and
    the guess, and one solver prepared for them."""
    import ocpkit.planner.simultaneous as simultaneous

    steps, screened_by = [], []
    real_layout, real_shape, real_prepare, real_near = simultaneous.layout, simultaneous.shape, \
        simultaneous.prepare, simultaneous._near_left_out
    monkeypatch.setattr(simultaneous, "layout", lambda *a, **k: steps.append("layout") or real_layout(*a, **k))
    monkeypatch.setattr(simultaneous, "shape", lambda *a, **k: steps.append("shape") or screened_by.append(
        k["near"]) or real_shape(*a, **k))
    monkeypatch.setattr(simultaneous, "prepare", lambda *a, **k: steps.append("prepare") or real_prepare(*a, **k))

    def near_for_the_guess(problem, constraints, motion):  # the guess comes near rows left out, as if
        if steps == ["layout"]:
            return line_samples(problem) + 0.05
        return real_near(problem, constraints, motion)

    monkeypatch.setattr(simultaneous, "_near_left_out", near_for_the_guess)
    clear_builds()
    plan = plan_simultaneous(PANDA, fallbacks=(), screen=True, knots=6, refinements=0,
                             solver_options={"max_iterations": 2})
    assert steps[:3] == ["layout", "shape", "prepare"]  # one shape and one solver, for the line and the guess
    assert len(screened_by[0]) == 2 * len(line_samples(PANDA))
    np.testing.assert_allclose(screened_by[0][len(line_samples(PANDA)):], line_samples(PANDA) + 0.05)
    setup = plan.stats.timing.setup
    assert setup["graph"] > 0 and setup["solver"] > 0
    assert plan.stats.setup_time == pytest.approx(setup["graph"] + setup["solver"] + setup["compile"])


def test_the_guess_is_encoded_on_the_shape_without_constraints_as_on_the_screened_one():
    """The layout's variables are the screened shape's, so a guess encodes and decodes alike on both."""
    clear_builds(parts=True)
    grid, built = layout(PANDA, knots=6)
    screened = shape(PANDA, knots=6, near=line_samples(PANDA)).discretization
    assert not grid.constraints and screened.constraints
    assert grid.nlp.variables.size == screened.nlp.variables.size
    w = screened.initial_guess(PANDA)
    np.testing.assert_array_equal(grid.initial_guess(PANDA), w)
    times = np.linspace(0.0, screened.decode(w).tf, 7)
    np.testing.assert_array_equal(grid.decode(w).interpolant(times).q, screened.decode(w).interpolant(times).q)
    assert built > 0 and layout(PANDA, knots=6) == (grid, 0.0)  # kept for the robot's later plans
    clear_builds()
    assert layout(PANDA, knots=6) == (grid, 0.0)  # the builds go, the parts a robot's builds share stay
    clear_builds(parts=True)
    assert layout(PANDA, knots=6)[0] is not grid


@pytest.mark.parametrize("status, prepared", [(SolverStatus.ITERATION_LIMIT, 2), (SolverStatus.TIME_LIMIT, 1)])
def test_an_unverified_solve_near_left_out_rows_is_rebuilt_unless_it_was_stopped_by_time(monkeypatch, status,
                                                                                         prepared):
    """A solve stopped by its pace hands the rung's time on: a rebuild with more rows would only iterate slower."""
    import ocpkit.planner.simultaneous as simultaneous

    steps, real_prepare, real_solve = [], simultaneous.prepare, simultaneous.solve_refined
    monkeypatch.setattr(simultaneous, "prepare", lambda *a, **k: steps.append("prepare") or real_prepare(*a, **k))
    monkeypatch.setattr(simultaneous, "_widened", lambda problem, options, constraints, near, motion:
                        None if steps.count("prepare") != 1 else  # once, after the first solve
                        (simultaneous._shape(problem, options, np.vstack([near, line_samples(problem) + 0.05])),
                         near))

    def stopped(*args, **kwargs):
        refined = real_solve(*args, **kwargs)
        return dataclasses.replace(refined, result=dataclasses.replace(refined.result, status=status))

    monkeypatch.setattr(simultaneous, "solve_refined", stopped)
    clear_builds()
    plan = plan_simultaneous(PANDA, fallbacks=(), screen=True, knots=6, refinements=0,
                             solver_options={"max_iterations": 2})
    assert not plan.ok and steps.count("prepare") == prepared
