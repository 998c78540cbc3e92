"""LGR node families (LGR_START: s = −1 collocated, s = +1 not; LGR: its mirror image) against numpy's Legendre
series, scipy's Gauss–Jacobi rule and the Padé approximants of e^z that are their stability functions."""

import math

import numpy as np
import pytest
from numpy.polynomial import Legendre
from scipy.special import roots_jacobi

from ocpkit.errors import OptionError
from ocpkit.transcription.lgr import (
    LGR,
    LGR_START,
    LegendreGaussRadau,
    lgr_barycentric_weights,
    lgr_collocated,
    lgr_points,
    lgr_quadrature_weights,
)

RNG = np.random.default_rng(11)
NS = [1, 2, 5, 12, 40]


def radau_polynomial(n: int) -> Legendre:
    """q = P_{n−1} + P_n, whose roots are the n LGR points."""
    return Legendre(np.eye(n + 1)[n - 1] + np.eye(n + 1)[n])


@pytest.mark.parametrize("n", NS)
def test_points_are_the_roots_of_p_n_minus_1_plus_p_n_with_exact_ends(n):
    s = lgr_points(n)
    assert s.shape == (n + 1,) and s[0] == 1.0 and s[-1] == -1.0
    assert np.all(np.diff(s) < 0)
    q = radau_polynomial(n)
    assert np.all(np.abs(q(s[1:]) / q.deriv()(s[1:])) < 1e-15)  # Newton distance to the nearest root
    assert q(1.0) == pytest.approx(2.0)  # point 0 is not one of them


@pytest.mark.parametrize("n", [2, 5, 12, 40])
def test_interior_points_and_weights_match_gauss_jacobi_0_1(n):
    # weight (1 − s)^0 (1 + s)^1: the node at s = −1 factored out; (α, β) = (1, 0) would be the mirrored set
    x, w = roots_jacobi(n - 1, 0, 1)
    np.testing.assert_allclose(lgr_points(n)[-2:0:-1], x, rtol=0, atol=1e-15)
    # scipy's (Golub–Welsch) weights are only ~3e-13 relative near the ends at n = 40; ours are ~1e-14
    np.testing.assert_allclose(lgr_quadrature_weights(n)[-2:0:-1], w / (1 + x), rtol=1e-12)


@pytest.mark.parametrize("n", NS)
def test_quadrature_is_exact_to_degree_2n_minus_2(n):
    s, w = lgr_points(n), lgr_quadrature_weights(n)
    assert w[0] == 0.0 and np.all(w[1:] > 0)
    assert w.sum() == pytest.approx(2.0, abs=1e-14)
    for k in range(2 * n - 1):
        assert w @ s**k == pytest.approx((1 - (-1) ** (k + 1)) / (k + 1), abs=1e-14)  # ∫_{-1}^{1} s^k ds


@pytest.mark.parametrize("n", NS)
def test_quadrature_misses_a_degree_2n_minus_1_polynomial(n):
    # f = q² / (1 + s) = (1 + s) p², p = q / (1 + s) = P^(0,1)_{n−1}, vanishes at all n collocation points,
    # yet ∫ f = 2/n. A monomial s^(2n−1) would show it too, but its error (∝ 4^(−n)) drowns in round-off for
    # large n.
    f = radau_polynomial(n) ** 2 // Legendre([1.0, 1.0])
    assert f.degree() == 2 * n - 1
    assert f.integ()(1.0) - f.integ()(-1.0) == pytest.approx(2 / n, rel=1e-12)
    assert lgr_quadrature_weights(n) @ f(lgr_points(n)) == pytest.approx(0.0, abs=1e-10)


@pytest.mark.parametrize("n", NS)
def test_barycentric_weights_match_the_product_formula(n):
    s = lgr_points(n)
    generic = 1.0 / np.prod(s[:, None] - s[None, :] + np.eye(n + 1), axis=1)
    lam = lgr_barycentric_weights(n)
    np.testing.assert_allclose(lam / lam[0], generic / generic[0], rtol=1e-12)


@pytest.mark.parametrize("n", NS)
@pytest.mark.parametrize("family", [LGR, LGR_START], ids=["end", "start"])
def test_differentiation_is_exact_to_degree_n_at_all_points(n, family):
    s, D = family.points(n), family.differentiation(n)
    for degree in sorted({0, 1, n // 2, n}):
        p = Legendre(RNG.normal(size=degree + 1))
        exact = p.deriv()(s)
        np.testing.assert_allclose(D @ p(s), exact, rtol=0, atol=1e-12 * (1 + np.abs(exact).max()))


@pytest.mark.parametrize("n", NS)
@pytest.mark.parametrize("family", [LGR, LGR_START], ids=["end", "start"])
def test_interpolation_reproduces_degree_n_polynomials(n, family):
    s, t = family.points(n), RNG.uniform(-1, 1, size=50)
    p = Legendre(RNG.normal(size=n + 1))
    np.testing.assert_allclose(family.interpolation(n, t) @ p(s), p(t), rtol=0, atol=1e-12)
    np.testing.assert_allclose(family.interpolation(n, s), np.eye(n + 1), atol=0)


@pytest.mark.parametrize("n", NS)
def test_only_point_0_is_not_collocated(n):
    assert lgr_collocated(n).tolist() == [False] + [True] * n


@pytest.mark.parametrize("n", NS)
def test_the_default_family_is_the_mirror_image(n):
    np.testing.assert_array_equal(LGR.points(n), -lgr_points(n)[::-1])
    np.testing.assert_array_equal(LGR.quadrature_weights(n), lgr_quadrature_weights(n)[::-1])
    assert LGR.collocation_mask(n).tolist() == [True] * n + [False]  # the start (s = −1, the last point) is not


def pade(p: int, q: int, z: float) -> float:
    """The (p, q) Padé approximant of e^z (numerator degree p, denominator q), closed form."""
    def series(m: int, sign: int) -> float:
        return sum(math.factorial(p + q - j) * math.factorial(m) / (math.factorial(p + q) * math.factorial(j)
                   * math.factorial(m - j)) * (sign * z) ** j for j in range(m + 1))
    return series(p, 1) / series(q, -1)


def step(family, n: int, z: float) -> float:
    """x at the segment's end after collocating x' = λ x from x = 1 at its start, z = λ × (segment duration)."""
    D, mask = family.differentiation(n), family.collocation_mask(n)
    rows = (D - (z / 2) * np.eye(n + 1))[mask]  # D X = h λ X at the collocated points, h = duration / 2
    free = rows[:, :-1]  # the last point (s = −1, the start) has x = 1
    return float(np.linalg.solve(free, -rows[:, -1])[0])


@pytest.mark.parametrize("n", [1, 2, 5, 9])
def test_stability_functions_are_the_pade_approximants(n):
    """Collocating the end gives the (n − 1, n) Padé approximant of e^z (Radau IIA), collocating the start the
    (n, n − 1) one: both exact to order 2n − 1, but only the first decays where hλ → −∞."""
    for z in (-0.3, 0.7, -5.0, -50.0):
        assert step(LGR, n, z) == pytest.approx(pade(n - 1, n, z), rel=1e-9, abs=1e-12)
        assert step(LGR_START, n, z) == pytest.approx(pade(n, n - 1, z), rel=1e-9)
    assert abs(step(LGR, n, -1e4)) < 1e-3 < 1.0 < abs(step(LGR_START, n, -1e4))


def test_rejects_an_unknown_end():
    with pytest.raises(OptionError, match="collocate"):
        LegendreGaussRadau(collocate="middle")


def test_rejects_fewer_than_one_interval():
    with pytest.raises(ValueError):
        lgr_points(0)
