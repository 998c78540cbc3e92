"""Chebyshev–Lobatto polynomial tools on the normalized interval s ∈ [-1, 1].

Knot i sits at s_i = cos(iπ/N), i = 0..N, so knot 0 is s = 1 (t = t_f) and knot N is s = -1 (t = 0),
with t = t_f (s + 1) / 2. References: Trefethen, *Spectral Methods in MATLAB* (cheb, clencurt) and
Berrut & Trefethen, *Barycentric Lagrange Interpolation*, SIAM Review 46 (2004).
"""

from __future__ import annotations

import numpy as np


def lobatto_points(n: int) -> np.ndarray:
    """Chebyshev–Lobatto points s_i = cos(iπ/n), shape (n+1,), decreasing from 1 to -1."""
    if n < 1:
        raise ValueError(f"need at least 1 interval, got n={n}")
    return np.cos(np.pi * np.arange(n + 1) / n)


def barycentric_weights(n: int) -> np.ndarray:
    """Barycentric weights of the Chebyshev–Lobatto points, shape (n+1,): (-1)^j, halved at both ends."""
    w = (-1.0) ** np.arange(n + 1)
    w[[0, -1]] *= 0.5
    return w


def differentiation_matrix(n: int) -> np.ndarray:
    """D, shape (n+1, n+1), with (D f)_i = f'(s_i) exactly for every polynomial f of degree ≤ n."""
    s = lobatto_points(n)
    c = np.ones(n + 1)
    c[[0, -1]] = 2.0
    c *= (-1.0) ** np.arange(n + 1)
    ds = s[:, None] - s[None, :] + np.eye(n + 1)
    d = np.outer(c, 1.0 / c) / ds
    d -= np.diag(d.sum(axis=1))  # negative-sum trick: rows of D annihilate constants
    return d


def clenshaw_curtis_weights(n: int) -> np.ndarray:
    """Quadrature weights w, shape (n+1,): Σ w_i f(s_i) = ∫_{-1}^{1} f ds exactly for degree ≤ n."""
    theta = np.pi * np.arange(n + 1) / n
    w = np.zeros(n + 1)
    interior = slice(1, n)
    v = np.ones(n - 1)
    if n % 2 == 0:
        w[0] = w[n] = 1.0 / (n**2 - 1)
        for k in range(1, n // 2):
            v -= 2.0 * np.cos(2 * k * theta[interior]) / (4 * k**2 - 1)
        v -= np.cos(n * theta[interior]) / (n**2 - 1)
    else:
        w[0] = w[n] = 1.0 / n**2
        for k in range(1, (n - 1) // 2 + 1):
            v -= 2.0 * np.cos(2 * k * theta[interior]) / (4 * k**2 - 1)
    w[interior] = 2.0 * v / n
    return w


def interpolation_matrix(n: int, s: np.ndarray) -> np.ndarray:
    """L, shape (len(s), n+1): L @ f_knots is the degree-n interpolant at points s (barycentric form)."""
    nodes = lobatto_points(n)
    w = barycentric_weights(n)
    s = np.atleast_1d(np.asarray(s, dtype=float))
    diff = s[:, None] - nodes[None, :]
    exact = np.isclose(diff, 0.0, atol=1e-14, rtol=0.0)
    diff[exact] = 1.0
    terms = w / diff
    matrix = terms / terms.sum(axis=1, keepdims=True)
    hit_rows = exact.any(axis=1)
    matrix[hit_rows] = exact[hit_rows].astype(float)
    return matrix


def derivative_matrix(n: int, s: np.ndarray) -> np.ndarray:
    """L', shape (len(s), n+1): L' @ f_knots is d/ds of the degree-n interpolant at points s."""
    return interpolation_matrix(n, s) @ differentiation_matrix(n)
