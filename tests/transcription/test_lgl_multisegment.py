"""Legendre–Gauss–Lobatto nodes against closed forms, the K-segment grid, and the pseudospectral NLP of the
Chebyshev, LGL and LGR families on one and several segments: exactness on polynomial motions, encode/decode, the
cost's closed form, the adaptive slots, and the paper cases end to end."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from helpers import REPO, discretize, evaluate, monomial, polynomial_motion
from numpy.polynomial import Legendre, Polynomial

import ocpkit
from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.errors import OptionError
from ocpkit.nlp import Refinement
from ocpkit.transcription.chebyshev import Chebyshev
from ocpkit.transcription.lgl import LGL, LegendreGaussLobatto, lgl_points, lgl_weights
from ocpkit.transcription.lgr import LegendreGaussRadau
from ocpkit.transcription.polynomials import CHEBYSHEV
from ocpkit.transcription.pseudospectral import Grid

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
CASES = sorted((REPO / "scenarios/paper").glob("case*.yaml"))
RNG = np.random.default_rng(3)
TF = 2.0
N = 6  # intervals per segment: every quintic is exact on every segment (one LGL segment needs N ≥ 6)
# name → (transcription class, segments, collocated points per segment) of the NLPs under test: Lobatto families
# impose D X = h F at all N + 1 points, Radau at all but one end (so a joint column is collocated once, not twice)
SETUPS = {"lgl": (LegendreGaussLobatto, 1, N + 1), "lgl-2": (LegendreGaussLobatto, 2, N + 1),
          "chebyshev-3": (Chebyshev, 3, N + 1), "lgr": (LegendreGaussRadau, 1, N),
          "lgr-3": (LegendreGaussRadau, 3, N), "lgr-start-3": (LegendreGaussRadau, 3, N)}
OPTIONS = {"lgr-start-3": {"collocate": "start"}}
PAPER = {"lgl": (8, 1), "chebyshev": (8, 2), "lgr": (16, 1)}  # transcription → (knots, segments) for the paper cases


def random_polynomial(degree: int) -> Polynomial:
    return Polynomial(RNG.normal(size=degree + 1))


# -- LGL nodes ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("n", [2, 3, 8, 12, 21])
def test_lgl_points_are_the_roots_of_one_minus_s2_times_legendre_slope(n):
    s = lgl_points(n)
    expected = np.concatenate([[1.0], np.sort(Legendre.basis(n).deriv().roots())[::-1], [-1.0]])
    np.testing.assert_allclose(s, expected, atol=1e-13)
    np.testing.assert_allclose(s, -s[::-1], atol=1e-15)  # symmetric


@pytest.mark.parametrize("n", [2, 3, 8, 12, 21])
def test_lgl_differentiation_is_exact_up_to_degree_n_with_the_closed_form_diagonal(n):
    s, D = lgl_points(n), LGL.differentiation(n)
    for degree in range(n + 1):
        p = random_polynomial(degree)
        np.testing.assert_allclose(D @ p(s), p.deriv()(s), atol=1e-10 * (1 + np.abs(p.deriv()(s)).max()))
    np.testing.assert_allclose(np.diag(D), np.r_[n * (n + 1) / 4, np.zeros(n - 1), -n * (n + 1) / 4], atol=1e-9)
    assert np.abs(D @ s ** (n + 1) - (n + 1) * s**n).max() > 1e-6  # not beyond degree n


@pytest.mark.parametrize("n", [2, 3, 8, 12, 21])
def test_lgl_quadrature_is_exact_up_to_degree_2n_minus_1_only(n):
    s, w = lgl_points(n), lgl_weights(n)
    for degree in range(2 * n):
        p = random_polynomial(degree)
        assert w @ p(s) == pytest.approx(p.integ()(1.0) - p.integ()(-1.0), abs=1e-12 * (1 + np.abs(p.coef).sum()))
    assert n > 12 or abs(w @ s ** (2 * n) - 2 / (2 * n + 1)) > 1e-10  # not degree 2n (too close to see beyond 12)


@pytest.mark.parametrize("n", [2, 3, 8, 12, 21])
def test_lgl_interpolation_is_exact_up_to_degree_n(n):
    s, x = lgl_points(n), np.linspace(-1, 1, 41)
    p = random_polynomial(n)
    np.testing.assert_allclose(LGL.interpolation(n, x) @ p(s), p(x), atol=1e-11 * np.abs(p.coef).sum())
    np.testing.assert_allclose(LGL.derivative(n, x) @ p(s), p.deriv()(x), atol=1e-9 * np.abs(p.coef).sum())


# -- the K-segment grid ------------------------------------------------------------------------------------
@pytest.mark.parametrize("family", [CHEBYSHEV, LGL], ids=lambda f: f.name)
def test_grid_knots_and_piecewise_interpolation(family):
    grid = Grid(family, N, 3)
    knots = grid.knots
    assert len(knots) == 3 * N + 1 and knots[0] == 1.0 and knots[-1] == -1.0 and np.all(np.diff(knots) < 0)
    np.testing.assert_allclose(knots[[N, 2 * N]], [1 / 3, -1 / 3], atol=1e-15)  # the joints
    pieces = [random_polynomial(N) for _ in range(3)]  # an arbitrary polynomial per segment, first in time first
    segment_of = lambda x: np.clip(np.floor((1 - x) * 3 / 2).astype(int), 0, 2)
    f = lambda x: np.choose(segment_of(x), [pieces[2](x), pieces[1](x), pieces[0](x)])
    values = f(knots)
    values[[N, 2 * N]] = [pieces[2](1 / 3), pieces[1](-1 / 3)]  # a joint column holds the earlier-column segment's
    x = np.linspace(-1, 1, 61)
    interior = np.abs(np.abs(x) - 1 / 3) > 1e-9
    L, _ = grid.matrices(x[interior & (x > 1 / 3)])  # the last segment in time is exact whatever the others
    np.testing.assert_allclose(L @ values, pieces[2](x[interior & (x > 1 / 3)]), atol=1e-10)
    smooth = random_polynomial(N)
    L, Ld = grid.matrices(x)
    np.testing.assert_allclose(L @ smooth(knots), smooth(x), atol=1e-10 * np.abs(smooth.coef).sum())
    np.testing.assert_allclose(Ld @ smooth(knots), smooth.deriv()(x) / 3, atol=1e-9 * np.abs(smooth.coef).sum())


# -- the NLP ----------------------------------------------------------------------------------------------
@functools.cache
def build(setup: str):
    method, segments, _ = SETUPS[setup]
    return discretize(PROBLEM, method.name, knots=N, segments=segments, **OPTIONS.get(setup, {}))


@pytest.fixture(scope="module", params=list(SETUPS))
def setup(request):
    return request.param


@pytest.fixture(scope="module")
def disc(setup):
    return build(setup)


def columns(disc) -> int:
    """Knot columns KN + 1 (joints shared), as the grid says."""
    return disc.grid.K * N + 1


def test_equalities_vanish_exactly_on_motions_of_degree_n(setup, disc):
    _, K, collocated = SETUPS[setup]
    nlp, equalities = disc.nlp, disc.nlp.lbg == disc.nlp.ubg
    checks = nlp.variables.index("q_check").shape[1]
    assert disc.grid.K == K and nlp.variables.index("X").shape == (columns(disc), 24)
    # D Q, D Qd at the collocated points of every segment; dynamics once per column; lifted check q, qd, qdd
    assert equalities.sum() == 6 * (2 * K * collocated + (K * N + 1) + 3 * checks)
    for shape in (monomial(N), Polynomial([0.0, 0.3, -0.2, 0.9, 0.4, -0.3])):
        _, g = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, shape)), PROBLEM)
        assert np.abs(g[equalities]).max() < 1e-9, shape
    _, g = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, monomial(N + 1))), PROBLEM)
    assert np.abs(g[equalities]).max() > 1e-7  # one degree more and the defects show (small on short segments)


@pytest.mark.parametrize("collocate, column", [("start", 0), ("end", -1)])
def test_radau_leaves_the_slope_at_its_other_end_free(collocate, column):
    """LGR imposes D X = h F at every point but one end (t_f when it collocates the start, the start when it
    collocates the end), LGL at every point: perturbing q̇ there on the same motion changes the same equality rows
    on both grids but for the two defects there, which only LGL has."""
    motion = polynomial_motion(PROBLEM, TF, Polynomial([0.0, 0.3, -0.2, 0.9, 0.4, -0.3]))
    changed = {}
    for setup, options in (("lgl", {}), ("lgr", {"collocate": collocate})):
        disc = discretize(PROBLEM, setup, knots=N, **options)
        w = disc.encode(motion)
        _, g0 = evaluate(disc, w, PROBLEM)
        w[disc.nlp.variables.index("qd")[column, 2]] += 0.1  # column 0 is t = t_f, the last the start
        _, g1 = evaluate(disc, w, PROBLEM)
        equalities = disc.nlp.lbg == disc.nlp.ubg
        changed[setup] = np.abs(g1 - g0)[equalities] > 1e-6
        assert np.abs(g0[equalities]).max() < 1e-9
    # q̇ there enters the q-defect (D Q)_i − h q̇_i at that point only, the q̇-defects (D Q̇)_i − h q̈_i at every
    # collocated point, and that knot's dynamics (the same on both grids: the same state). LGL has the q- and
    # q̇-defects there that LGR leaves out: exactly two rows more.
    assert changed["lgr"].sum() >= N  # the q̇-defects at the N collocated points
    assert changed["lgl"].sum() - changed["lgr"].sum() == 2


def test_cost_is_tf_plus_the_exact_jerk_integral(disc):
    """q of degree ≤ N = 5: the squared jerk has degree ≤ 4, within every family's exact degree (Clenshaw–Curtis
    N, LGL 2N − 1, LGR 2N − 2)."""
    delta = PROBLEM.goal - PROBLEM.start
    for shape in (monomial(5), Polynomial([0.0, 0.5, 0.0, 0.5, -0.2, 0.1])):
        value, _ = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, shape)), PROBLEM)
        third = shape.deriv(3)
        expected = TF + PROBLEM.mu * np.sum(PROBLEM.jerk_weights * delta**2) * (third * third).integ()(1.0) / TF**5
        assert value == pytest.approx(expected, rel=1e-9), shape


@pytest.mark.parametrize("n", [6, 9])
def test_lgr_cost_is_the_exact_jerk_integral_for_motions_of_degree_n(n):
    """On one LGR segment of n intervals, a random q of degree n has a squared jerk of degree 2n − 6, within the
    2n − 2 that LGR quadrature integrates exactly (point t_f weighs 0)."""
    disc = discretize(PROBLEM, "lgr", knots=n)
    delta = PROBLEM.goal - PROBLEM.start
    shape = Polynomial(np.r_[0.0, RNG.normal(size=n)])
    value, _ = evaluate(disc, disc.encode(polynomial_motion(PROBLEM, TF, shape)), PROBLEM)
    third = shape.deriv(3)
    expected = TF + PROBLEM.mu * np.sum(PROBLEM.jerk_weights * delta**2) * (third * third).integ()(1.0) / TF**5
    assert value == pytest.approx(expected, rel=1e-9)


def test_decode_inverts_encode_and_reproduces_motions_of_degree_n(disc):
    motion = polynomial_motion(PROBLEM, TF, Polynomial([0.0, 0.3, -0.2, 0.9, 0.4, -0.3]))
    w = disc.encode(motion)
    trajectory = disc.decode(w)
    assert trajectory.knots.t[0] == 0.0 and trajectory.tf == pytest.approx(TF)
    assert np.all(np.diff(trajectory.knots.t) > 0) and len(trajectory.knots.t) == columns(disc)
    t = np.linspace(0, TF, 37)
    for key in ("q", "qd", "qdd"):
        np.testing.assert_allclose(getattr(trajectory.interpolant(t), key), getattr(motion.interpolant(t), key),
                                   atol=1e-8, err_msg=key)
    np.testing.assert_allclose(trajectory.knots.tau, motion.interpolant(trajectory.knots.t).tau, atol=1e-8)
    np.testing.assert_allclose(disc.encode(trajectory), w, atol=1e-9)  # and encode inverts decode on the grid


def test_check_fractions_move_the_adaptive_slots_into_their_segment(disc):
    count, p = columns(disc), disc.nlp.parameters
    values = disc.parameters(PROBLEM, Refinement(np.array([0.1])))
    rows = p.read(values, "adaptive_rows")  # slot by slot, (slots, columns)
    assert rows.shape == (4, count)
    assert rows[0].sum() == pytest.approx(1.0) and not np.allclose(rows[0], rows[1])
    assert np.all(rows[0, : count - N - 1] == 0.0)  # the 0.1 t_f slot sits in the first segment in time
    # and interpolates there: L(σ) applied to the knot times gives the slot's time
    sigma = disc.grid.knots
    assert rows[0] @ sigma == pytest.approx(2 * 0.1 - 1, abs=1e-12)
    np.testing.assert_array_equal(rows[1:], p.read(disc.parameters(PROBLEM), "adaptive_rows")[1:])


def test_bounds_pin_start_goal_rest_and_time(disc):
    lbx, ubx = disc.bounds(PROBLEM)
    w = disc.nlp.variables
    for bound in (lbx, ubx):
        q = w.read(bound, "q")  # column 0 at t_f, the last at t = 0
        np.testing.assert_allclose(q[-1], PROBLEM.start)
        np.testing.assert_allclose(q[0], PROBLEM.goal)
        for part in ("qd", "qdd"):
            np.testing.assert_allclose(w.read(bound, part)[[0, -1]], 0.0)
        np.testing.assert_allclose(w.read(bound, "start")[:6], PROBLEM.start)
        np.testing.assert_allclose(w.read(bound, "goal")[:6], PROBLEM.goal)
    np.testing.assert_array_equal(w.read(lbx, "tf"), PROBLEM.time.min)
    np.testing.assert_array_equal(w.read(ubx, "tf"), PROBLEM.time.max)
    assert np.all(np.isinf(w.read(lbx, "q_check")))  # limits at checks are path rows, not bounds


def test_segments_and_family_are_part_of_the_shape_key():
    dynamics, constraints = make_dynamics("casadi", PROBLEM.robot), make_constraints(PROBLEM)
    keys = {m(knots=N, segments=K).shape_key(dynamics, constraints)
            for m in (Chebyshev, LegendreGaussLobatto, LegendreGaussRadau) for K in (1, 2)}
    assert len(keys) == 6


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES, ids=lambda p: p.stem)
@pytest.mark.parametrize("name", list(PAPER))
def test_paper_case_is_verified(name, case):
    problem = ocpkit.load_scenario(case)
    knots, segments = PAPER[name]
    result = ocpkit.plan(problem, transcription=name, knots=knots, transcription_options={"segments": segments})
    assert result.status == "verified", result.verification.summary()
    assert problem.velocity_lower_bound() < result.trajectory.tf < 3.0


@pytest.mark.parametrize("family", [CHEBYSHEV, LGL], ids=lambda f: f.name)
def test_unequal_segments_end_at_their_breaks_and_interpolate_exactly(family):
    grid = Grid(family, N, 3, breaks=(0.2, 0.9))  # segments of 0.2, 0.7 and 0.1 of the horizon
    knots = grid.knots
    np.testing.assert_allclose(knots[[0, N, 2 * N, 3 * N]], [1.0, 0.8, -0.6, -1.0], atol=1e-15)
    assert np.all(np.diff(knots) < 0)
    np.testing.assert_allclose(grid.scale(np.arange(3)), [2 / 0.2, 2 / 1.4, 2 / 0.4])
    smooth, x = random_polynomial(N), np.linspace(-1, 1, 61)
    L, Ld = grid.matrices(x)
    np.testing.assert_allclose(L @ smooth(knots), smooth(x), atol=1e-10 * np.abs(smooth.coef).sum())
    ds_dsigma = grid.scale(grid.segment_of(x))  # d/ds on each point's own segment
    np.testing.assert_allclose(Ld @ smooth(knots), smooth.deriv()(x) / ds_dsigma, atol=1e-9 * np.abs(smooth.coef).sum())
    np.testing.assert_array_equal(grid.segment_of(np.array([0.9, 0.8, 0.0, -0.6, -0.7])), [0, 1, 1, 2, 2])


def test_equal_segments_keep_their_closed_form():
    equal = Grid(CHEBYSHEV, N, 3)
    assert equal.scale(1) == 3 and not equal.breaks
    np.testing.assert_allclose(Grid(CHEBYSHEV, N, 3, breaks=(1 / 3, 2 / 3)).knots, equal.knots, atol=1e-15)


@pytest.mark.parametrize("options, message", [
    ({"breaks": (0.5, 0.3)}, "increase strictly"),
    ({"breaks": (0.0, 0.5)}, "increase strictly"),
    ({"breaks": (0.5, 1.0)}, "increase strictly"),
    ({"breaks": (0.5,), "segments": 3}, "disagrees"),
    ({"knots": 65}, "per segment"),
])
def test_bad_breaks_and_knots_are_refused_by_name(options, message):
    with pytest.raises(OptionError, match=message):
        Chebyshev(**{"knots": 8, **options})


def test_a_robot_refuses_breaks():
    with pytest.raises(OptionError, match="breaks are for"):
        discretize(PROBLEM, "chebyshev", knots=N, breaks=(0.5,))
