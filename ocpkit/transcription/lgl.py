"""Legendre–Gauss–Lobatto (LGL) pseudospectral transcription: chebyshev.py with other points and weights.

For N intervals the N + 1 LGL points are the roots of (1 − s²) P'_N(s) (P_N the Legendre polynomial), ordered
s_0 = 1 > … > s_N = −1 like the Chebyshev knots. On them:

    quadrature        w_i = 2 / (N (N+1) P_N(s_i)²)         exact for polynomials of degree ≤ 2N − 1
    barycentric       λ_i = 1 / P_N(s_i)                     (the node polynomial's ℓ'(s_i) ∝ P_N(s_i), by
                                                              Legendre's equation at the roots of P'_N)
    differentiation   D_ij = P_N(s_i) / (P_N(s_j) (s_i − s_j)),  D_00 = N(N+1)/4 = −D_NN, else D_ii = 0

The NLP (dynamics D X = (t_f/2) F, jerk, cost with these weights, checks, segments) is pseudospectral.py's.
Compared with Chebyshev's Clenshaw–Curtis weights (exact to degree N) the LGL quadrature of the jerk cost is
exact to degree 2N − 1, which covers the squared jerk of the degree-N interpolant. References: Canuto et al.,
*Spectral Methods* (2006), §2.2; Fahroo & Ross, *Costate estimation by a Legendre pseudospectral method*,
JGCD 24 (2001).
"""

from __future__ import annotations

import numpy as np

from ocpkit.transcription.polynomials import NodeFamily
from ocpkit.transcription.pseudospectral import Pseudospectral


def legendre(n: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(P_n(s), P_{n−1}(s)) by the three-term recurrence k P_k = (2k − 1) s P_{k−1} − (k − 1) P_{k−2}."""
    previous, current = np.ones_like(s), s.copy()
    for k in range(2, n + 1):
        previous, current = current, ((2 * k - 1) * s * current - (k - 1) * previous) / k
    return current, previous


def lgl_points(n: int) -> np.ndarray:
    """The n + 1 LGL points, shape (n+1,), decreasing from 1 to −1: Newton's iteration on
    s P_n(s) − P_{n−1}(s) = 0 (whose roots are ±1 and those of P'_n) from the Chebyshev–Lobatto points."""
    if n < 1:
        raise ValueError(f"need at least 1 interval, got n={n}")
    s = np.cos(np.pi * np.arange(n + 1) / n)
    for _ in range(100):
        p, p_previous = legendre(n, s)
        step = (s * p - p_previous) / ((n + 1) * p)
        s = s - step
        if np.abs(step).max() < 1e-16:
            break
    return s


def lgl_barycentric_weights(n: int) -> np.ndarray:
    """Barycentric weights of the LGL points, shape (n+1,): 1 / P_n(s_i) (alternating in sign)."""
    return 1.0 / legendre(n, lgl_points(n))[0]


def lgl_weights(n: int) -> np.ndarray:
    """Quadrature weights, shape (n+1,): 2 / (n (n+1) P_n(s_i)²), Σ w_i f(s_i) = ∫_{-1}^{1} f ds for degree ≤ 2n − 1."""
    return 2.0 / (n * (n + 1) * legendre(n, lgl_points(n))[0] ** 2)


LGL = NodeFamily("Legendre–Gauss–Lobatto", lgl_points, lgl_barycentric_weights, lgl_weights)


class LegendreGaussLobatto(Pseudospectral):
    """LGL pseudospectral transcription with N = `knots` intervals (N + 1 LGL points) on each of `segments`
    equal segments."""

    name = "lgl"
    family = LGL

