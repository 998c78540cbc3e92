"""Chebyshev–Lobatto tools against closed forms."""

import numpy as np
import pytest

from ocpkit.transcription.polynomials import (barycentric_weights, clenshaw_curtis_weights, derivative_matrix,
                                              differentiation_matrix, interpolation_matrix, lobatto_points)

RNG = np.random.default_rng(7)


def random_polynomial(degree: int) -> np.polynomial.Polynomial:
    return np.polynomial.Polynomial(RNG.normal(size=degree + 1))


@pytest.mark.parametrize("n", [2, 5, 8, 12, 13])
def test_points_are_chebyshev_lobatto_and_decreasing(n):
    s = lobatto_points(n)
    assert s[0] == 1.0 and s[-1] == -1.0
    assert np.all(np.diff(s) < 0)
    np.testing.assert_allclose(s, np.cos(np.pi * np.arange(n + 1) / n))


@pytest.mark.parametrize("n", [2, 5, 8, 12, 13])
def test_differentiation_matrix_is_exact_up_to_degree_n(n):
    s = lobatto_points(n)
    D = differentiation_matrix(n)
    for degree in range(n + 1):
        p = random_polynomial(degree)
        np.testing.assert_allclose(D @ p(s), p.deriv()(s), atol=1e-10 * (1 + np.abs(p.deriv()(s)).max()))


def test_differentiation_matrix_is_not_exact_beyond_degree_n():
    n = 6
    s = lobatto_points(n)
    assert np.abs(differentiation_matrix(n) @ s ** (n + 1) - (n + 1) * s**n).max() > 1e-3


@pytest.mark.parametrize("n", [2, 3, 8, 12, 13])
def test_clenshaw_curtis_integrates_polynomials_up_to_degree_n(n):
    w = clenshaw_curtis_weights(n)
    s = lobatto_points(n)
    for degree in range(n + 1):
        exact = (1 - (-1) ** (degree + 1)) / (degree + 1)  # ∫_{-1}^{1} s^degree ds
        assert w @ s**degree == pytest.approx(exact, abs=1e-13)
    assert np.all(w > 0)


def test_clenshaw_curtis_matches_closed_form_integral_of_exponential():
    w, s = clenshaw_curtis_weights(12), lobatto_points(12)
    assert w @ np.exp(s) == pytest.approx(np.e - 1 / np.e, rel=1e-13)


@pytest.mark.parametrize("n", [3, 8, 12])
def test_interpolation_is_exact_for_polynomials_and_at_nodes(n):
    s, t = lobatto_points(n), np.linspace(-1, 1, 101)
    p = random_polynomial(n)
    np.testing.assert_allclose(interpolation_matrix(n, t) @ p(s), p(t), atol=1e-11)
    np.testing.assert_allclose(interpolation_matrix(n, s), np.eye(n + 1), atol=0)
    np.testing.assert_allclose(derivative_matrix(n, t) @ p(s), p.deriv()(t), atol=1e-9)


def test_barycentric_weights_alternate_and_halve_at_ends():
    np.testing.assert_array_equal(barycentric_weights(4), [0.5, -1, 1, -1, 0.5])


def test_derivative_of_smooth_function_converges_exponentially():
    errors = []
    for n in (4, 8, 12, 16, 20):
        s = lobatto_points(n)
        f, df = np.exp(np.sin(2 * s)), 2 * np.cos(2 * s) * np.exp(np.sin(2 * s))
        errors.append(np.abs(differentiation_matrix(n) @ f - df).max())
    assert errors[-1] < 1e-6
    rates = np.log(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(rates > 1.5), errors  # each +4 points gains a constant factor: geometric convergence


def test_rejects_zero_intervals():
    with pytest.raises(ValueError, match="at least 1"):
        lobatto_points(0)
