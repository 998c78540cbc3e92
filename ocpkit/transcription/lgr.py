"""Legendre–Gauss–Radau (LGR) pseudospectral transcription (`lgr`): two node families for pseudospectral.py,
N Radau points and one point that is not collocated.

    LGR         the end of each segment collocated, its start not (Radau IIA; option collocate="end", default)
    LGR_START   the start collocated, the end not (GPOPS-II's and dymos' orientation; collocate="start")
    D X = h F at every collocated point;  dynamics residual and path constraints at every point

Why the end by default: collocation at Radau points that include a segment's end is L-stable (its stability
function is the (N−1, N) Padé approximant of e^z, which vanishes as hλ → −∞); with the start included it is the
(N, N−1) one, which grows without bound, so on a segment much longer than a damped mode's time constant the
discrete problem admits growing modes that an optimizer exploits (the hang glider: design notes, 2026-12-03).

This module computes the N LGR points (roots of P_{N−1} + P_N, by Newton's iteration from the
Chebyshev–Gauss–Radau points) plus the non-collocated s = 1 as point 0, the barycentric weights, the Radau
quadrature weights (0 at s = 1; exact to degree 2N − 2) and the collocation mask (`lgr_collocated`): LGR_START;
LGR is its mirror image s → −s. pseudospectral.py uses the mask, so on K segments each joint column is
collocated once, by the segment that ends there (LGR) or starts there (LGR_START). The weights are computed
through (P_{N−1} − P_N)/2, which equals P_{N−1} at the roots but is less sensitive to their rounding
(`_half_difference`).

Equations and their derivation: docs/transcription.md, section "Pseudospectral" (family "Legendre–Gauss–Radau").
"""

from __future__ import annotations

import numpy as np

from ocpkit.errors import OptionError
from ocpkit.transcription.polynomials import NodeFamily, legendre
from ocpkit.transcription.pseudospectral import Pseudospectral


def _half_difference(n: int, s: np.ndarray) -> np.ndarray:
    """(P_{n−1}(s) − P_n(s)) / 2, shape like s: P_{n−1}(s_i) at the LGR points, but less sensitive to their
    rounding (its slope at s = 1 is −n/2 against P'_{n−1}(1) = n(n − 1)/2)."""
    p, p_previous = legendre(n, s)
    return (p_previous - p) / 2


def lgr_points(n: int) -> np.ndarray:
    """The n LGR points plus the non-collocated s = 1, shape (n+1,), decreasing from 1 to −1 (both exact)."""
    if n < 1:
        raise ValueError(f"need at least 1 interval, got n={n}")
    s = -np.cos(2 * np.pi * np.arange(1, n) / (2 * n - 1))  # Chebyshev–Gauss–Radau guesses for the interior roots
    for _ in range(100):
        p, p_previous = legendre(n, s)
        step = (1 - s) * (p_previous + p) / (n * (p_previous - p))
        s = s - step
        if np.all(np.abs(step) < 1e-15):
            break
    return np.concatenate([[1.0], s[::-1], [-1.0]])


def lgr_barycentric_weights(n: int) -> np.ndarray:
    """Barycentric weights of the n + 1 points, shape (n+1,): n at s = 1, −1 / P_{n−1}(s_i) elsewhere."""
    s = lgr_points(n)
    return np.concatenate([[float(n)], -1.0 / _half_difference(n, s[1:])])


def lgr_quadrature_weights(n: int) -> np.ndarray:
    """Quadrature weights, shape (n+1,): 0 at s = 1, (1 − s_i) / (n² P_{n−1}(s_i)²) at the n LGR points, so
    Σ w_i f(s_i) = ∫_{-1}^{1} f ds for degree ≤ 2n − 2."""
    s = lgr_points(n)
    return np.concatenate([[0.0], (1 - s[1:]) / (n**2 * _half_difference(n, s[1:]) ** 2)])


def lgr_collocated(n: int) -> np.ndarray:
    """Which points are collocated, shape (n+1,) bool: False at point 0 (s = 1), True elsewhere."""
    return np.arange(n + 1) > 0


LGR_START = NodeFamily("Legendre–Gauss–Radau (start collocated)", lgr_points, lgr_barycentric_weights,
                       lgr_quadrature_weights, lgr_collocated)
LGR = NodeFamily("Legendre–Gauss–Radau", lambda n: -lgr_points(n)[::-1], lambda n: lgr_barycentric_weights(n)[::-1],
                 lambda n: lgr_quadrature_weights(n)[::-1], lambda n: lgr_collocated(n)[::-1])
"""The mirror image of LGR_START (barycentric weights are defined up to one factor, here (−1)^n)."""
FAMILIES = {"end": LGR, "start": LGR_START}


class LegendreGaussRadau(Pseudospectral):
    """Legendre–Gauss–Radau (LGR) pseudospectral transcription: N = `knots` intervals (N LGR points and one that
    is not collocated) on each of `segments` segments; `collocate` = "end" (default; L-stable) or "start" (as in
    GPOPS-II and dymos) says which end of each segment is collocated. Other options: `Pseudospectral`."""

    name = "lgr"
    family = LGR

    def __init__(self, *args, collocate: str = "end", **kwargs) -> None:
        if collocate not in FAMILIES:
            raise OptionError(f"lgr: collocate must be one of {sorted(FAMILIES)}, got {collocate!r}")
        self.collocate, self.family = collocate, FAMILIES[collocate]
        super().__init__(*args, **kwargs)

    def options_key(self) -> tuple:
        return *super().options_key(), self.collocate
