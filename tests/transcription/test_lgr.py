"""LGR node family (flipped Radau: s = −1 collocated, s = +1 not) against numpy's Legendre series and scipy's
Gauss–Jacobi rule."""

import numpy as np
import pytest
from numpy.polynomial import Legendre
from scipy.special import roots_jacobi

from ocpkit.transcription.lgr import (
    LGR,
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
def test_differentiation_is_exact_to_degree_n_at_all_points(n):
    s, D = lgr_points(n), LGR.differentiation(n)
    for degree in sorted({0, 1, n // 2, n}):
        p = Legendre(RNG.normal(size=degree + 1))
        exact = p.deriv()(s)
        np.testing.assert_allclose(D @ p(s), exact, rtol=0, atol=1e-12 * (1 + np.abs(exact).max()))


@pytest.mark.parametrize("n", NS)
def test_interpolation_reproduces_degree_n_polynomials(n):
    s, t = lgr_points(n), RNG.uniform(-1, 1, size=50)
    p = Legendre(RNG.normal(size=n + 1))
    np.testing.assert_allclose(LGR.interpolation(n, t) @ p(s), p(t), rtol=0, atol=1e-12)
    np.testing.assert_allclose(LGR.interpolation(n, s), np.eye(n + 1), atol=0)


@pytest.mark.parametrize("n", NS)
def test_only_point_0_is_not_collocated(n):
    assert lgr_collocated(n).tolist() == [False] + [True] * n


def test_rejects_fewer_than_one_interval():
    with pytest.raises(ValueError):
        lgr_points(0)
