"""The local collocation transcriptions, trapezoidal and Hermite–Simpson: exactness on the motions each method
represents, the interpolant through the knots, encode/decode, the cost's closed form, the refinement's
moved checks, and the paper cases end to end."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from helpers import REPO, discretize, evaluate, monomial, polynomial_motion
from numpy.polynomial import Polynomial

import ocpkit
from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.nlp import Refinement
from ocpkit.transcription import TRANSCRIPTIONS

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
CASES = sorted((REPO / "scenarios/paper").glob("case*.yaml"))
TF = 2.0
# name, intervals N, the highest polynomial degree the method is exact for (q(t) of that degree)
METHODS = {"trapezoidal": (6, 2), "hermite-simpson": (4, 3)}
PAPER_KNOTS = {"trapezoidal": 40, "hermite-simpson": 10}  # trapezoidal at 20 fails the qd_consistency check


@functools.cache
def build(name: str):
    return discretize(PROBLEM, name, knots=METHODS[name][0])


@pytest.fixture(scope="module", params=list(METHODS))
def method(request):
    name = request.param
    return name, *METHODS[name], build(name)


def test_equalities_vanish_exactly_on_the_motions_the_method_represents(method):
    _, N, degree, disc = method
    nlp = disc.nlp
    equalities = nlp.lbg == nlp.ubg
    points = N + 1 + N * disc.midpoints  # dynamics at every collocation point
    defects = 2 * N * (1 + disc.midpoints)  # q and q̇: trapezoid (+ Hermite interpolation) per interval
    assert equalities.sum() == 6 * (points + defects + N)  # + the lifted q of one check per interval
    for shape in (monomial(degree), Polynomial([0.0, 0.3, -0.2, 0.9][: degree + 1])):
        _, g = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, shape)), PROBLEM)
        assert np.abs(g[equalities]).max() < 1e-9, shape
    _, g = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, monomial(degree + 1))), PROBLEM)
    assert np.abs(g[equalities]).max() > 1e-5  # one degree more and the defects show


def test_moved_checks_keep_the_equalities_exact(method):
    _, N, degree, disc = method
    nlp, layout = disc.nlp, disc.nlp.variables
    w = disc.encode(polynomial_motion(PROBLEM, TF, monomial(degree)))
    moved = Refinement(np.array([0.3, 0.61, 0.97]))
    check_at = nlp.parameters.read(disc.parameters(PROBLEM, moved), "check_at")
    assert np.count_nonzero(check_at != 0.5) == 3
    _, g = evaluate(disc, w, PROBLEM, moved)
    assert np.abs(g[nlp.lbg == nlp.ubg]).max() > 1e-5  # the checks encoded at σ = ½ are off the moved ones
    relifted = disc.relifted(w, moved)  # encode sampled the checks at their default σ; lift them to the moved ones
    checks = layout.index("q_check")  # (N, n)
    for k in range(N):  # by hand: the motion at each moved check
        np.testing.assert_allclose(relifted[checks[k]],
                                   disc.decode(w).interpolant(np.array([TF * (k + check_at[k]) / N])).q[0], atol=1e-12)
    np.testing.assert_array_equal(np.delete(relifted, checks), np.delete(w, checks))  # nothing else changes
    _, g = evaluate(disc, relifted, PROBLEM, moved)
    assert np.abs(g[nlp.lbg == nlp.ubg]).max() < 1e-9


def test_check_fractions_move_the_check_of_their_interval(method):
    _, N, _, disc = method
    p = disc.nlp.parameters
    default, moved = (p.read(disc.parameters(PROBLEM, r), "check_at")
                      for r in (Refinement(), Refinement(np.array([0.55, 0.6]))))
    assert default.shape == (N,)
    np.testing.assert_array_equal(default, 0.5)
    k = int(0.55 * N)  # both fractions fall in interval k; the newest (first) wins
    assert moved[k] == pytest.approx(0.55 * N - k)
    np.testing.assert_array_equal(np.delete(moved, k), 0.5)


def test_interpolant_passes_through_the_knots_and_decode_inverts_encode(method):
    _, N, _, disc = method
    layout = disc.nlp.variables
    motion = polynomial_motion(PROBLEM, TF, Polynomial([0.0, 0.0, 3.0, -2.0]))  # smoothstep: not exact for all
    w = disc.encode(motion)
    free = np.ones(len(w), dtype=bool)
    free[layout.index("tf")] = False
    w[free] += 0.01 * np.random.default_rng(0).standard_normal(free.sum())  # defects no longer hold
    trajectory = disc.decode(w)
    t = TF * np.arange(N + 1) / N
    np.testing.assert_allclose(trajectory.knots.t, t, atol=1e-15)
    for key in ("q", "qd", "qdd"):
        knots = layout.read(w, key)  # (N + 1, n), knot 0 at t = 0
        np.testing.assert_allclose(getattr(trajectory.interpolant(t), key), knots, atol=1e-12)
        np.testing.assert_allclose(getattr(trajectory.interpolant(t[1:] - 1e-12), key), knots[1:],
                                   atol=1e-9, err_msg=f"{key} from the left")
    roundtrip = disc.decode(disc.encode(motion))
    for key in ("q", "qd", "qdd", "tau"):
        np.testing.assert_allclose(getattr(roundtrip.knots, key), getattr(motion.interpolant(t), key), atol=1e-9)


def test_interpolant_reproduces_the_exact_motions_everywhere(method):
    _, _, degree, disc = method
    motion = polynomial_motion(PROBLEM, TF, Polynomial([0.0, 0.3, -0.2, 0.9][: degree + 1]))
    t = np.linspace(0, TF, 29)
    decoded = disc.decode(disc.encode(motion)).interpolant(t)
    for key in ("q", "qd", "qdd"):
        np.testing.assert_allclose(getattr(decoded, key), getattr(motion.interpolant(t), key), atol=1e-9, err_msg=key)


def test_cost_is_tf_plus_the_exact_jerk_integral(method):
    """The quadrature is exact for every jerk the interpolant represents: constant (q cubic) for trapezoidal's
    piecewise-linear q̈, linear (q quartic) for Hermite–Simpson's piecewise-quadratic q̈."""
    name, _, _, disc = method
    delta = PROBLEM.goal - PROBLEM.start
    shapes = [monomial(3), Polynomial([0.0, 0.5, 0.0, 0.5])] + ([monomial(4)] if name == "hermite-simpson" else [])
    for shape in shapes:
        value, _ = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, shape)), PROBLEM)
        third = shape.deriv(3)
        jerk_shape = (third * third).integ()(1.0)  # ∫_0^1 (d³p/dx³)² dx
        expected = TF + PROBLEM.mu * np.sum(PROBLEM.jerk_weights * delta**2) * jerk_shape / TF**5
        assert value == pytest.approx(expected, rel=1e-9), shape


def test_torque_rate_is_bounded_by_the_one_sided_slopes_at_the_knots():
    """Hermite–Simpson's du/dσ is linear on an interval: u = 0, a, 4a at σ = 0, ½, 1 has slopes 0, 4a, 8a, so the
    knot's row with the slope into it is the one to see a rate limit that 4a meets and 8a breaks."""
    disc, k, joint = build("hermite-simpson"), 1, 0
    nlp, layout = disc.nlp, disc.nlp.variables
    r, N, n = PROBLEM.robot, disc.N, PROBLEM.robot.n
    w = disc.encode(polynomial_motion(PROBLEM, 10.0, monomial(3)))  # slow: tiny torque rates of its own
    _, base = evaluate(disc, w, PROBLEM)
    h = 10.0 / N
    knot_u, mid_u = layout.index("u")[:, joint], layout.index("M")[:, 3 * n + joint]

    def violated(end_rate: float) -> np.ndarray:
        """Torque-rate rows (dτ/ds − limit ≤ 0, the only rows bounded by (−∞, 0]) that newly break their bound
        when the slope into knot k+1 is end_rate × the rate limit."""
        a = end_rate * h * r.taud_max[joint] / (8 * r.tau_max[joint])
        step = w.copy()
        step[knot_u[k + 1:]] += 4 * a
        step[mid_u[k]] += a
        step[mid_u[k + 1:]] += 4 * a
        _, g = evaluate(disc, step, PROBLEM)
        rate_rows = np.isneginf(nlp.lbg) & (nlp.ubg == 0.0)
        return rate_rows & (g > 1e-9) & (base <= 1e-9)

    assert not violated(0.9).any()
    assert violated(1.5).sum() == 1


def test_bounds_pin_start_goal_rest_and_time(method):
    _, N, _, disc = method
    layout = disc.nlp.variables
    lbx, ubx = disc.bounds(PROBLEM)
    for bound in (lbx, ubx):
        q = layout.read(bound, "q")  # knot by knot, knot 0 at t = 0
        np.testing.assert_allclose(q[0], PROBLEM.start)
        np.testing.assert_allclose(q[N], PROBLEM.goal)
        for part in ("qd", "qdd"):
            np.testing.assert_allclose(layout.read(bound, part)[[0, N]], 0.0)
        others = np.ones(layout.size, dtype=bool)
        others[layout.index("X")] = others[layout.index("tf")] = False
        assert others.sum() == layout.size - 24 * (N + 1) - 1
        assert np.all(np.isinf(bound[others]))  # midpoints and checks: limits are path constraints
    np.testing.assert_array_equal(layout.read(lbx, "tf"), [PROBLEM.time.min])  # one t_f, unstaged
    np.testing.assert_array_equal(layout.read(ubx, "tf"), [PROBLEM.time.max])


def shape_key(transcription, problem):
    return transcription.shape_key(make_dynamics("casadi", problem.robot), make_constraints(problem))


def test_shape_key_ignores_moved_obstacles_and_names_the_method(method):
    name, N, _, _ = method
    transcription = TRANSCRIPTIONS.get(name)(knots=N)
    moved = dataclasses.replace(PROBLEM, scene=dataclasses.replace(
        PROBLEM.scene, obstacle_centers=PROBLEM.scene.obstacle_centers + [0.0, 0.05, 0.0]))
    assert shape_key(transcription, moved) == shape_key(transcription, PROBLEM)
    others = [shape_key(TRANSCRIPTIONS.get(other)(knots=N), PROBLEM) for other in METHODS if other != name]
    others.append(shape_key(TRANSCRIPTIONS.get(name)(knots=N, staged=True), PROBLEM))
    assert shape_key(transcription, PROBLEM) not in others


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=lambda p: p.stem)
@pytest.mark.parametrize("name", list(PAPER_KNOTS))
def test_paper_case_is_verified(name, case):
    problem = ocpkit.load_scenario(case)
    result = ocpkit.plan(problem, transcription=name, knots=PAPER_KNOTS[name])
    assert result.status == "verified", result.verification.summary()
    assert problem.velocity_lower_bound() < result.trajectory.tf < 3.0
