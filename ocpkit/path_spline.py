"""A fixed joint-space path q = p(s), s ∈ [0, 1], smooth to its third derivative, in NumPy and in CasADi.

`PathSpline.fit` interpolates waypoints by the natural quintic spline (C⁴: p‴ is continuous) in the chord length
c (rad): p‴ = p⁗ = 0 at both ends, which makes it the interpolant of least ∫|p‴|² dc. Its normalised parameter
is s = c / L (L the chord length of the whole path). Rest at both ends is the timing's (ṡ = s̈ = 0 gives
q̇ = q̈ = 0), so the path keeps its tangent there: with p′ = 0 at the ends (a clamped spline, what TOPP-RA needs)
the path speed would vanish in s and the timing OCP would need ṡ → ∞ near the ends, which its polynomials
represent badly (docs/concepts/baselines.md, "ompl-topp3").
Both evaluations use one piecewise polynomial in s (the spline's own Taylor coefficients at every breakpoint):
`values` in NumPy, `symbolic` on CasADi symbols for s, the breakpoints and the coefficients (the interval
selected by comparisons, so the expression is exact wherever s is; the breakpoints and coefficients are NLP
parameters, `parameters`), so the timing NLP and the samples it returns see the same p, p′, p″, p‴. `split`
cuts intervals in two (the same polynomial) so paths of different lengths share one NLP shape.
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
        """The natural quintic through `waypoints` (k, n) at increasing chord lengths `chord` (k,), rad
        (p‴ = p⁗ = 0 at both ends). Through two waypoints it is the straight line (their midpoint is added: the
        end conditions alone leave a single quintic piece undetermined)."""
        if len(waypoints) == 2:
            chord = np.insert(chord, 1, chord.mean())
            waypoints = np.insert(waypoints, 1, waypoints.mean(axis=0), axis=0)
        length = float(chord[-1])
        s = chord / length
        zero = np.zeros(waypoints.shape[1])
        ends = [(3, zero), (4, zero)]
        curve = make_interp_spline(s, waypoints, k=DEGREE, bc_type=(ends, ends))
        breaks = np.unique(np.clip(curve.t, 0.0, 1.0))
        coefficients = np.stack([curve(breaks[:-1], nu=j) / factorial(j) for j in range(DEGREE + 1)], axis=1)
        return cls(breaks, coefficients, length)

    @property
    def key(self) -> str:
        """A digest of the breakpoints and coefficients: equal exactly for equal splines."""
        return hashlib.sha256(self.breaks.tobytes() + self.coefficients.tobytes()).hexdigest()

    @property
    def intervals(self) -> int:
        """K, the polynomial pieces."""
        return len(self.breaks) - 1

    def split(self, intervals: int) -> PathSpline:
        """The same path on `intervals` ≥ K pieces: the longest piece halved until there are that many."""
        breaks = self.breaks
        while len(breaks) - 1 < intervals:
            i = int(np.argmax(np.diff(breaks)))
            breaks = np.insert(breaks, i + 1, (breaks[i] + breaks[i + 1]) / 2)
        return PathSpline(breaks, self.taylor(breaks[:-1]), self.length)

    def taylor(self, s: np.ndarray) -> np.ndarray:
        """p^(j)(s)/j! for j = 0..DEGREE at s (m,): (m, DEGREE+1, n) (the piece starting at s where s is a break)."""
        interval, local = self._locate(s)
        return np.stack([_horner(self.coefficients[interval], local, d) / factorial(d) for d in range(DEGREE + 1)],
                        axis=1)

    def parameters(self) -> tuple[np.ndarray, np.ndarray]:
        """The NLP parameter values `symbolic` reads: breaks (K+1, 1) and coefficients ((DEGREE+1) n, K), rows
        j n .. (j+1) n − 1 holding the coefficients of (s − b_i)^j of piece i."""
        return self.breaks[:, None], np.concatenate([self.coefficients[:, j, :].T for j in range(DEGREE + 1)])

    def __call__(self, chord: np.ndarray) -> np.ndarray:
        """p at chord lengths (m,), rad: (m, n)."""
        return self.values(np.asarray(chord, dtype=float) / self.length)[0]

    def values(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """p, p′, p″, p‴ at s (m,), each (m, n) (derivatives in s; outside [0, 1] the end polynomials)."""
        interval, local = self._locate(s)
        return tuple(_horner(self.coefficients[interval], local, d) for d in range(4))

    def _locate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The piece of each s (m,) and s − its start, (m, 1)."""
        s = np.asarray(s, dtype=float)
        interval = np.clip(np.searchsorted(self.breaks, s, side="right") - 1, 0, len(self.breaks) - 2)
        return interval, (s - self.breaks[interval])[:, None]


def symbolic(s: ca.SX, breaks: ca.SX, coefficients: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX, ca.SX]:
    """p, p′, p″, p‴ (n, 1) at the CasADi scalar s of the path whose `PathSpline.parameters` are the symbols
    `breaks` (K+1, 1) and `coefficients` ((DEGREE+1) n, K)."""
    K, n = breaks.numel() - 1, coefficients.size1() // (DEGREE + 1)
    select = [(1 if i == 0 else s >= breaks[i]) * (1 if i == K - 1 else s < breaks[i + 1]) for i in range(K)]
    onehot = ca.vertcat(*select)
    local = s - ca.dot(onehot, breaks[:K])
    rows = [ca.mtimes(coefficients[j * n:(j + 1) * n, :], onehot) for j in range(DEGREE + 1)]  # (n, 1) each
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
