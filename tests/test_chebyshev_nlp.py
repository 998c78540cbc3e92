"""The Chebyshev NLP: its constraints and cost evaluated on an exact polynomial motion, the shape key,
bounds and the encode/decode maps."""

from __future__ import annotations

import dataclasses

import casadi as ca
import numpy as np
import pytest
from helpers import REPO
from test_verify import quintic

from ocpkit import load_scenario
from ocpkit.transcription import TRANSCRIPTIONS
from ocpkit.transcription.base import Refinement

PROBLEM = load_scenario(REPO / "scenarios/paper/case2.yaml")
KNOTS = 6  # a quintic has degree 5 ≤ N, so the Chebyshev interpolant reproduces it exactly


@pytest.fixture(scope="module")
def nlp():
    return TRANSCRIPTIONS.get("chebyshev")(knots=KNOTS).build(PROBLEM, "casadi")


def evaluate(nlp, w, problem=PROBLEM):
    f = ca.Function("nlp", [nlp.x, nlp.p], [nlp.f, nlp.g])
    value, g = f(w, nlp.parameters(problem))
    return float(value), np.asarray(g).ravel()


def test_dynamics_and_collocation_hold_exactly_on_a_polynomial_motion(nlp):
    w = nlp.encode(quintic(PROBLEM, 2.0))
    _, g = evaluate(nlp, w)
    equalities = nlp.lbg == nlp.ubg
    assert equalities.sum() == (KNOTS + 1) * 3 * 6 + 6 * nlp.n_checks  # D Q, D Qd, dynamics; check-point q
    assert np.abs(g[equalities]).max() < 1e-8


def test_collocation_detects_a_motion_that_is_not_a_derivative(nlp):
    w = nlp.encode(quintic(PROBLEM, 2.0))
    w[6:12] += 0.1  # velocity of knot 0 no longer the derivative of the position polynomial
    _, g = evaluate(nlp, w)
    assert np.abs(g[nlp.lbg == nlp.ubg]).max() > 0.05


def test_cost_is_tf_plus_weighted_jerk_integral(nlp):
    tf = 2.0
    value, _ = evaluate(nlp, nlp.encode(quintic(PROBLEM, tf)))
    delta = PROBLEM.goal - PROBLEM.start
    x = np.linspace(0, 1, 200001)
    jerk_shape = np.trapezoid((60 - 360 * x + 360 * x**2) ** 2, x)  # ∫_0^1 (d³s/dx³)² dx of the quintic
    expected = tf + PROBLEM.mu * np.sum(PROBLEM.jerk_weights * delta**2) * jerk_shape / tf**5
    assert value == pytest.approx(expected, rel=1e-6)


def test_decode_is_in_increasing_time_and_inverts_encode(nlp):
    motion = quintic(PROBLEM, 2.0)
    trajectory = nlp.decode(nlp.encode(motion))
    assert trajectory.tf == pytest.approx(2.0)
    assert np.all(np.diff(trajectory.knots.t) > 0) and trajectory.knots.t[0] == 0.0
    t = np.linspace(0, 2, 37)
    for key in ("q", "qd", "qdd"):  # polynomials of degree ≤ N: reproduced everywhere
        np.testing.assert_allclose(getattr(trajectory.interpolant(t), key), getattr(motion.interpolant(t), key),
                                   atol=1e-8, err_msg=key)
    np.testing.assert_allclose(trajectory.knots.tau, motion.interpolant(trajectory.knots.t).tau, atol=1e-8)


def test_bounds_pin_start_goal_rest_and_time(nlp):
    lbx, ubx = nlp.bounds(PROBLEM)
    columns = lambda v: v[: 4 * 6 * (KNOTS + 1)].reshape(KNOTS + 1, 24)  # noqa: E731  knot by knot
    for bound in (lbx, ubx):
        np.testing.assert_allclose(columns(bound)[KNOTS, :6], PROBLEM.start)  # knot N is t = 0
        np.testing.assert_allclose(columns(bound)[0, :6], PROBLEM.goal)
        np.testing.assert_allclose(columns(bound)[[0, KNOTS], 6:18], 0.0)
    assert (lbx[-1], ubx[-1]) == (PROBLEM.time.min, PROBLEM.time.max)


def test_same_shape_for_moved_obstacles_new_shape_for_more():
    chebyshev = TRANSCRIPTIONS.get("chebyshev")(knots=KNOTS)
    moved = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=PROBLEM.scene.obstacle_centers + [0.0, 0.05, 0.0]))
    more = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=np.vstack([PROBLEM.scene.obstacle_centers] * 2),
        obstacle_radii=np.tile(PROBLEM.scene.obstacle_radii, 2)))
    assert chebyshev.shape_key(moved, "casadi") == chebyshev.shape_key(PROBLEM, "casadi")
    assert chebyshev.shape_key(more, "casadi") != chebyshev.shape_key(PROBLEM, "casadi")


def test_moved_obstacle_changes_the_parameters_not_the_nlp(nlp):
    moved = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=PROBLEM.scene.obstacle_centers + [0.0, 0.3, 0.0]))
    w = nlp.encode(quintic(PROBLEM, 2.0))
    assert not np.allclose(evaluate(nlp, w, moved)[1], evaluate(nlp, w)[1])


def test_check_fractions_move_the_adaptive_slots(nlp):
    default, moved = nlp.parameters(PROBLEM), nlp.parameters(PROBLEM, Refinement(np.array([0.5])))
    assert default.shape == moved.shape and not np.allclose(default, moved)


def test_extra_margin_tightens_the_clearance_rows(nlp):
    w = nlp.encode(quintic(PROBLEM, 2.0))
    f = ca.Function("g", [nlp.x, nlp.p], [nlp.g])
    g0 = np.asarray(f(w, nlp.parameters(PROBLEM))).ravel()
    g1 = np.asarray(f(w, nlp.parameters(PROBLEM, Refinement(extra_margin=0.02)))).ravel()
    one_sided = np.isinf(nlp.ubg)  # clearance ≥ 0 rows (two-sided workspace rows are rescaled instead)
    changed = ~np.isclose(g0, g1) & one_sided
    assert changed.any() and np.all(g1[changed] < g0[changed])
