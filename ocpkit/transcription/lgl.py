"""Legendre–Gauss–Lobatto (LGL) pseudospectral transcription (`lgl`): a node family for pseudospectral.py.

    D X = h F at the N + 1 roots of (1 − s²) P'_N(s)

This module computes the points (Newton's iteration from the Chebyshev–Lobatto points), the barycentric
weights 1/P_N(s_i) and the quadrature weights, exact to degree 2N − 1; everything else is pseudospectral.py's.

Equations: docs/transcription.md, section "Pseudospectral" (family "Legendre–Gauss–Lobatto").
"""

from __future__ import annotations

import numpy as np

from ocpkit.transcription.polynomials import NodeFamily, legendre
from ocpkit.transcription.pseudospectral import Pseudospectral


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
    """Legendre–Gauss–Lobatto (LGL) pseudospectral transcription, in one or more equal segments.

    N = `knots` intervals (N + 1 LGL points) on each of `segments` equal segments."""

    name = "lgl"
    family = LGL

