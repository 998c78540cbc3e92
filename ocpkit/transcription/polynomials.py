"""Chebyshev–Lobatto polynomial tools on the normalized interval s ∈ [-1, 1], and the barycentric formulas
every node family (`NodeFamily`: Chebyshev here, Legendre–Gauss–Lobatto in lgl.py, Legendre–Gauss–Radau in
lgr.py) shares, and the Legendre recurrence of the last two.

Knot i sits at s_i = cos(iπ/N), i = 0..N, so knot 0 is s = 1 (t = t_f) and knot N is s = -1 (t = 0),
with t = t_f (s + 1) / 2. References: Trefethen, *Spectral Methods in MATLAB* (cheb, clencurt) and
Berrut & Trefethen, *Barycentric Lagrange Interpolation*, SIAM Review 46 (2004). Equations:
docs/transcription.md, section "Pseudospectral".
"""

from __future__ import annotations

import functools

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


def barycentric_differentiation(nodes: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """D, shape (n+1, n+1), for distinct `nodes` with barycentric `weights`: D_ij = (w_j / w_i) / (s_i − s_j)
    off the diagonal, so (D f)_i = f'(s_i) exactly for every polynomial f of degree ≤ n."""
    ds = nodes[:, None] - nodes[None, :] + np.eye(len(nodes))
    d = (weights[None, :] / weights[:, None]) / ds
    d -= np.diag(d.sum(axis=1))  # negative-sum trick: rows of D annihilate constants
    return d


def barycentric_interpolation(nodes: np.ndarray, weights: np.ndarray, s: np.ndarray) -> np.ndarray:
    """L, shape (len(s), n+1): L @ f_nodes is the degree-n interpolant at points s (second barycentric form)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    diff = s[:, None] - nodes[None, :]
    exact = np.isclose(diff, 0.0, atol=1e-14, rtol=0.0)
    diff[exact] = 1.0
    terms = weights / diff
    matrix = terms / terms.sum(axis=1, keepdims=True)
    hit_rows = exact.any(axis=1)
    matrix[hit_rows] = exact[hit_rows].astype(float)
    return matrix


def legendre(n: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(P_n(s), P_{n−1}(s)) by the three-term recurrence k P_k = (2k − 1) s P_{k−1} − (k − 1) P_{k−2}."""
    previous, current = np.ones_like(s), s.copy()
    for k in range(2, n + 1):
        previous, current = current, ((2 * k - 1) * s * current - (k - 1) * previous) / k
    return current, previous


@dataclass(frozen=True)
class NodeFamily:
    """A pseudospectral node family: for n intervals, the n + 1 points s_i (decreasing from 1 to -1, both ends
    included), their barycentric weights, their quadrature weights (Σ w_i f(s_i) ≈ ∫_{-1}^{1} f ds) and the
    points where the differential equations are collocated (`collocated`, a bool mask (n+1,); every point
    when None, as for the Lobatto families)."""

    name: str
    points: Callable[[int], np.ndarray]
    barycentric_weights: Callable[[int], np.ndarray]
    quadrature_weights: Callable[[int], np.ndarray]
    collocated: Callable[[int], np.ndarray] | None = None

    def __post_init__(self) -> None:
        """Each family's numbers computed once per n (a decoded trajectory evaluates them at every call)."""
        for name in ("points", "barycentric_weights", "quadrature_weights"):
            object.__setattr__(self, name, _computed_once(getattr(self, name)))
        object.__setattr__(self, "_differentiation", _computed_once(
            lambda n: barycentric_differentiation(self.points(n), self.barycentric_weights(n))))

    def collocation_mask(self, n: int) -> np.ndarray:
        """Bool (n+1,): where D X = h F is imposed."""
        return np.ones(n + 1, dtype=bool) if self.collocated is None else self.collocated(n)

    def differentiation(self, n: int) -> np.ndarray:
        """D, shape (n+1, n+1): exact derivative at the points of the degree-n interpolant."""
        return self._differentiation(n)

    def interpolation(self, n: int, s: np.ndarray) -> np.ndarray:
        """L, shape (len(s), n+1): the degree-n interpolant of the point values at s."""
        return barycentric_interpolation(self.points(n), self.barycentric_weights(n), s)

    def derivative(self, n: int, s: np.ndarray) -> np.ndarray:
        """L', shape (len(s), n+1): d/ds of the degree-n interpolant at s."""
        return self.interpolation(n, s) @ self.differentiation(n)


def _computed_once(function: Callable[[int], np.ndarray]) -> Callable[[int], np.ndarray]:
    """`function` of n with its results kept (read-only arrays)."""

    @functools.cache
    def once(n: int) -> np.ndarray:
        value = np.array(function(n))
        value.flags.writeable = False
        return value

    return once


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
    return barycentric_differentiation(lobatto_points(n), barycentric_weights(n))


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
    return barycentric_interpolation(lobatto_points(n), barycentric_weights(n), s)


def derivative_matrix(n: int, s: np.ndarray) -> np.ndarray:
    """L', shape (len(s), n+1): L' @ f_knots is d/ds of the degree-n interpolant at points s."""
    return interpolation_matrix(n, s) @ differentiation_matrix(n)


CHEBYSHEV = NodeFamily("Chebyshev–Lobatto", lobatto_points, barycentric_weights, clenshaw_curtis_weights)
