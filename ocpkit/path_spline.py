"""A fixed joint-space path q = p(s), s ∈ [0, 1], smooth to its third derivative, in NumPy and in CasADi.

`PathSpline.fit` interpolates waypoints by a quintic spline (C⁴: p‴ is continuous) in the chord length c (rad),
with p′ = p″ = 0 at both ends. Its normalised parameter is s = c / L (L the chord length of the whole path).
Both evaluations use one piecewise polynomial in s (the spline's own Taylor coefficients at every breakpoint):
`values` in NumPy, `symbolic` on a CasADi scalar (the interval selected by comparisons, so the expression is
exact wherever s is), so the timing NLP and the samples it returns see the same p, p′, p″, p‴.
"""

from __future__ import annotations

import hashlib
from math import factorial

import casadi as ca
import numpy as np
from scipy.interpolate import make_interp_spline

DEGREE = 5


class PathSpline:
    """p(s) for s ∈ [0, 1] from `breaks` (K+1,) and `coefficients` (K, DEGREE+1, n): on [b_i, b_{i+1}],
    p(s) = Σ_j coefficients[i, j] (s − b_i)^j. Calling it with chord lengths c (m,) gives p(c / L) (m, n)."""

    def __init__(self, breaks: np.ndarray, coefficients: np.ndarray, length: float) -> None:
        self.breaks, self.coefficients, self.length = breaks, coefficients, length
        self.n = coefficients.shape[2]

    @classmethod
    def fit(cls, chord: np.ndarray, waypoints: np.ndarray) -> PathSpline:
        """The quintic through `waypoints` (k, n) at increasing chord lengths `chord` (k,), rad, at rest at both
        ends (p′ = p″ = 0)."""
        length = float(chord[-1])
        s = chord / length
        zero = np.zeros(waypoints.shape[1])
        ends = [(1, zero), (2, zero)]
        curve = make_interp_spline(s, waypoints, k=DEGREE, bc_type=(ends, ends))
        breaks = np.unique(np.clip(curve.t, 0.0, 1.0))
        coefficients = np.stack([curve(breaks[:-1], nu=j) / factorial(j) for j in range(DEGREE + 1)], axis=1)
        return cls(breaks, coefficients, length)

    @property
    def key(self) -> str:
        """A digest of the breakpoints and coefficients: equal exactly for equal splines."""
        return hashlib.sha256(self.breaks.tobytes() + self.coefficients.tobytes()).hexdigest()

    def __call__(self, chord: np.ndarray) -> np.ndarray:
        """p at chord lengths (m,), rad: (m, n)."""
        return self.values(np.asarray(chord, dtype=float) / self.length)[0]

    def values(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """p, p′, p″, p‴ at s (m,), each (m, n) (derivatives in s; outside [0, 1] the end polynomials)."""
        s = np.asarray(s, dtype=float)
        interval = np.clip(np.searchsorted(self.breaks, s, side="right") - 1, 0, len(self.breaks) - 2)
        local = (s - self.breaks[interval])[:, None]
        coefficients = self.coefficients[interval]  # (m, DEGREE+1, n)
        return tuple(_horner(coefficients, local, d) for d in range(4))

    def symbolic(self, s: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX, ca.SX]:
        """p, p′, p″, p‴ at the CasADi scalar s, each (n, 1)."""
        K = len(self.breaks) - 1
        select = [(1 if i == 0 else s >= self.breaks[i]) * (1 if i == K - 1 else s < self.breaks[i + 1])
                  for i in range(K)]
        onehot = ca.vertcat(*select)
        local = s - ca.dot(onehot, ca.DM(self.breaks[:-1]))
        rows = [ca.mtimes(ca.DM(self.coefficients[:, j, :].T), onehot) for j in range(DEGREE + 1)]  # (n, 1) each
        return tuple(_horner(rows, local, d) for d in range(4))


def _horner(coefficients: object, local: object, derivative: int) -> object:
    """The d-th derivative of Σ_j c_j x^j at x = `local`; coefficients indexed [.., j, ..] (NumPy (m, J, n)) or
    a list of CasADi columns c_j."""
    terms = [coefficients[:, j, :] for j in range(DEGREE + 1)] if isinstance(coefficients, np.ndarray) \
        else coefficients
    value = 0
    for j in range(DEGREE, derivative - 1, -1):
        value = value * local + terms[j] * (factorial(j) // factorial(j - derivative))
    return value
