"""Bryson–Denham: x' = v, v' = u, x ≤ ℓ = 1/9, (x, v)(0) = (0, 1), (x, v)(1) = (0, −1), t_f = 1, minimize ½∫u² dt.

Source: Bryson & Ho, "Applied Optimal Control", 1975, §3.11 (pp. 120–123). For ℓ ≤ 1/6 the solution has three
arcs, unconstrained on [0, 3ℓ], on the constraint x = ℓ on [3ℓ, 1 − 3ℓ] (a second-order state constraint: u = 0,
v = 0), unconstrained and mirrored on [1 − 3ℓ, 1]: u = −(2/(3ℓ))(1 − t/(3ℓ)) on the first arc, and
J* = 4/(9ℓ) = 4. Dimensionless.
"""

from __future__ import annotations

import numpy as np

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic

ELL = 1.0 / 9.0
JUNCTIONS = (3.0 * ELL, 1.0 - 3.0 * ELL)  # entry and exit of the arc on x = ℓ


def build() -> Ocp:
    ocp = Ocp(T=1.0, name="bryson-denham")
    x = ocp.state("x", upper=ELL, start=0.0, end=0.0)
    v = ocp.state("v", start=1.0, end=-1.0)
    u = ocp.control("u")
    ocp.set_der(x, v)
    ocp.set_der(v, u)
    ocp.minimize_integral(0.5 * u**2)
    return ocp


def costates(t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The analytic costates (λx, λv) at t (same shape as t) for ℓ = 1/9.

    Convention: H = ½u² + λx v + λv u, λ̇ = −∂H/∂(x, v), so u = −λv and λ̇v = −λx; the state constraint
    x − ℓ ≤ 0 adjoined directly (H + μ(x − ℓ), μ ≥ 0), the form a direct transcription's multipliers estimate.
    Off the constraint λx is constant; on it u = 0 forces λv = 0 and hence λx = 0 (μ = 0 inside the arc); λx
    jumps by −ν ∂(x − ℓ)/∂x = −2/(9ℓ²) at each junction, λv is continuous:

        [0, 3ℓ):        λx = 2/(9ℓ²),   λv = (2/(3ℓ))(1 − t/(3ℓ))
        [3ℓ, 1 − 3ℓ]:   λx = 0,         λv = 0
        (1 − 3ℓ, 1]:    λx = −2/(9ℓ²),  λv = (2/(3ℓ))(1 − (1 − t)/(3ℓ))

    At the junctions themselves the value of the middle arc is returned."""
    t = np.asarray(t, dtype=float)
    first, last = t < JUNCTIONS[0], t > JUNCTIONS[1]
    lam_x = np.where(first, 2.0 / (9.0 * ELL**2), np.where(last, -2.0 / (9.0 * ELL**2), 0.0))
    lam_v = np.where(first, 2.0 / (3.0 * ELL) * (1.0 - t / (3.0 * ELL)),
                     np.where(last, 2.0 / (3.0 * ELL) * (1.0 - (1.0 - t) / (3.0 * ELL)), 0.0))
    return lam_x, lam_v


CLASSIC = Classic("bryson-denham", build, optimum=4.0 / (9.0 * ELL), smooth=False,
                  source="analytic: J* = 4/(9ℓ), Bryson & Ho 1975, §3.11",
                  note="a state-constrained arc on [1/3, 2/3]: u has kinks at the junctions")
