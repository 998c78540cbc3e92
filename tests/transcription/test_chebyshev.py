"""The Chebyshev NLP: its constraints and cost evaluated on an exact polynomial motion, the shape key,
bounds and the encode/decode maps."""

from __future__ import annotations

import dataclasses

import casadi as ca
import numpy as np
import pytest
from helpers import REPO, discretize, evaluate, quintic

from ocpkit import load_scenario
from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.nlp import Refinement
from ocpkit.transcription import TRANSCRIPTIONS

PROBLEM = load_scenario(REPO / "scenarios/paper/case2.yaml")
KNOTS = 6  # a quintic has degree 5 ≤ N, so the Chebyshev interpolant reproduces it exactly


@pytest.fixture(scope="module")
def disc():
    return discretize(PROBLEM, "chebyshev", knots=KNOTS)


def checks(disc) -> int:
    """Number of check points (fixed and adaptive): columns of the lifted check q (n, checks)."""
    return disc.nlp.variables.index("q_check").shape[1]


def test_dynamics_and_collocation_hold_exactly_on_a_polynomial_motion(disc):
    nlp = disc.nlp
    w = disc.encode(quintic(PROBLEM, 2.0))
    _, g = evaluate(disc, w, PROBLEM)
    equalities = nlp.lbg == nlp.ubg
    assert equalities.sum() == (KNOTS + 1) * 3 * 6 + 3 * 6 * checks(disc)  # D Q, D Qd, dynamics; check q, qd, qdd
    assert np.abs(g[equalities]).max() < 1e-8


def test_collocation_detects_a_motion_that_is_not_a_derivative(disc):
    w = disc.encode(quintic(PROBLEM, 2.0))
    _, g0 = evaluate(disc, w, PROBLEM)
    w[disc.nlp.variables.index("qd")[0]] += 0.1  # velocity of knot 0 no longer the derivative of the position
    _, g = evaluate(disc, w, PROBLEM)
    equalities = disc.nlp.lbg == disc.nlp.ubg
    assert np.abs(g0[equalities]).max() < 1e-8 and np.abs(g[equalities]).max() > 0.05


def test_cost_is_tf_plus_weighted_jerk_integral(disc):
    tf = 2.0
    value, _ = evaluate(disc, disc.encode(quintic(PROBLEM, tf)), PROBLEM)
    delta = PROBLEM.goal - PROBLEM.start
    x = np.linspace(0, 1, 200001)
    jerk_shape = np.trapezoid((60 - 360 * x + 360 * x**2) ** 2, x)  # ∫_0^1 (d³s/dx³)² dx of the quintic
    expected = tf + PROBLEM.mu * np.sum(PROBLEM.jerk_weights * delta**2) * jerk_shape / tf**5
    assert value == pytest.approx(expected, rel=1e-6)


def test_decode_is_in_increasing_time_and_inverts_encode(disc):
    motion = quintic(PROBLEM, 2.0)
    trajectory = disc.decode(disc.encode(motion))
    assert trajectory.tf == pytest.approx(2.0)
    assert np.all(np.diff(trajectory.knots.t) > 0) and trajectory.knots.t[0] == 0.0
    assert len(trajectory.knots.t) == KNOTS + 1
    t = np.linspace(0, 2, 37)
    for key in ("q", "qd", "qdd"):  # polynomials of degree ≤ N: reproduced everywhere
        np.testing.assert_allclose(getattr(trajectory.interpolant(t), key), getattr(motion.interpolant(t), key),
                                   atol=1e-8, err_msg=key)
    np.testing.assert_allclose(trajectory.knots.tau, motion.interpolant(trajectory.knots.t).tau, atol=1e-8)


def test_bounds_pin_start_goal_rest_and_time(disc):
    lbx, ubx = disc.bounds(PROBLEM)
    w = disc.nlp.variables
    for bound in (lbx, ubx):
        np.testing.assert_allclose(w.read(bound, "q")[KNOTS], PROBLEM.start)  # knot N is t = 0
        np.testing.assert_allclose(w.read(bound, "q")[0], PROBLEM.goal)
        for part in ("qd", "qdd"):
            np.testing.assert_allclose(w.read(bound, part)[[0, KNOTS]], 0.0)
        np.testing.assert_allclose(w.read(bound, "start"), np.concatenate([PROBLEM.start, np.zeros(12)]))
        np.testing.assert_allclose(w.read(bound, "goal"), np.concatenate([PROBLEM.goal, np.zeros(12)]))
        np.testing.assert_array_equal(w.read(bound, "tf"), PROBLEM.time.min if bound is lbx else PROBLEM.time.max)
    # interior knots: the position limits as bounds, accelerations and torques free
    np.testing.assert_allclose(w.read(lbx, "q")[1:KNOTS], np.tile(PROBLEM.robot.q_lower, (KNOTS - 1, 1)))
    assert np.all(np.isinf(w.read(lbx, "qdd")[1:KNOTS])) and np.all(np.isinf(w.read(ubx, "u")))


def shape_key(transcription, problem):
    return transcription.shape_key(make_dynamics("casadi", problem.robot), make_constraints(problem))


def test_same_shape_for_moved_obstacles_new_shape_for_more():
    chebyshev = TRANSCRIPTIONS.get("chebyshev")(knots=KNOTS)
    moved = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=PROBLEM.scene.obstacle_centers + [0.0, 0.05, 0.0]))
    more = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=np.vstack([PROBLEM.scene.obstacle_centers] * 2),
        obstacle_radii=np.tile(PROBLEM.scene.obstacle_radii, 2)))
    assert shape_key(chebyshev, moved) == shape_key(chebyshev, PROBLEM)
    assert shape_key(chebyshev, more) != shape_key(chebyshev, PROBLEM)
    assert shape_key(TRANSCRIPTIONS.get("chebyshev")(knots=KNOTS + 1), PROBLEM) != shape_key(chebyshev, PROBLEM)


def test_moved_obstacle_changes_the_parameters_not_the_nlp(disc):
    moved = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=PROBLEM.scene.obstacle_centers + [0.0, 0.3, 0.0]))
    p = disc.nlp.parameters
    np.testing.assert_allclose(p.read(disc.parameters(moved), "collision.obstacle_center"),
                               moved.scene.obstacle_centers)
    w = disc.encode(quintic(PROBLEM, 2.0))
    assert not np.allclose(evaluate(disc, w, moved)[1], evaluate(disc, w, PROBLEM)[1])


def test_check_fractions_move_the_adaptive_slots(disc):
    default, moved = disc.parameters(PROBLEM), disc.parameters(PROBLEM, Refinement(np.array([0.5])))
    assert default.shape == moved.shape and not np.allclose(default, moved)
    p = disc.nlp.parameters
    changed = ~np.isclose(default, moved)
    assert changed[p.index("adaptive_rows")[0]].any()  # slot 0 moved ...
    np.testing.assert_array_equal(p.read(default, "adaptive_rows")[1:], p.read(moved, "adaptive_rows")[1:])
    # ... to t_f / 2, σ = 0, where the interpolation row reproduces the middle knot (N even)
    np.testing.assert_allclose(p.read(moved, "adaptive_rows")[0], np.eye(KNOTS + 1)[KNOTS // 2], atol=1e-14)


def test_relifted_moves_the_lifted_checks_with_the_slots_and_nothing_else(disc):
    nlp, layout = disc.nlp, disc.nlp.variables
    w = disc.encode(quintic(PROBLEM, 2.0))
    moved = Refinement(np.array([0.37, 0.81]))
    _, g = evaluate(disc, w, PROBLEM, moved)
    assert np.abs(g[nlp.lbg == nlp.ubg]).max() > 1e-3  # lifted where the slots were, not where they are
    relifted = disc.relifted(w, moved)
    _, g = evaluate(disc, relifted, PROBLEM, moved)
    assert np.abs(g[nlp.lbg == nlp.ubg]).max() < 1e-8
    lifted = np.concatenate([layout.index(f"{part}_check").ravel() for part, _ in disc.ocp.lifted])
    np.testing.assert_array_equal(np.delete(relifted, lifted), np.delete(w, lifted))
    np.testing.assert_allclose(disc.relifted(w, Refinement()), w, atol=1e-12)  # the default slots: as encoded


def test_extra_margin_tightens_the_clearance_rows(disc):
    nlp = disc.nlp
    w = disc.encode(quintic(PROBLEM, 2.0))
    f = ca.Function("g", [nlp.x, nlp.p], [nlp.g])
    g0 = np.asarray(f(w, disc.parameters(PROBLEM))).ravel()
    g1 = np.asarray(f(w, disc.parameters(PROBLEM, Refinement(extra_margin=0.02)))).ravel()
    one_sided = np.isinf(nlp.ubg)  # clearance ≥ 0 rows (two-sided workspace rows are rescaled instead)
    changed = ~np.isclose(g0, g1) & one_sided
    assert changed.any() and np.all(g1[changed] < g0[changed])
