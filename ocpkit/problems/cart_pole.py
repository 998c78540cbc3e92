"""Cart-pole swing-up of Kelly, "An Introduction to Trajectory Optimization: How to Do Your Own Direct Collocation",
SIAM Review 59(4), 2017, §6 (cart-pole swing-up) and its appendix on the cart-pole: cart position q1 (m), pole
angle q2 (rad, 0 hanging down, π upright), force u (N) on the cart; cart m1 = 1 kg, pole m2 = 0.3 kg, pole length
ℓ = 0.5 m, g = 9.81 m/s²; from rest at (q1, q2) = (0, 0) to rest at (d, π), d = 1 m, in T = 2 s; |q1| ≤ 2d,
|u| ≤ 20 N; minimize ∫u² dt (N²·s).

Dynamics (Kelly's, ℓ the pole length):
    q̈1 = (ℓ m2 sin q2 q̇2² + u + m2 g cos q2 sin q2) / (m1 + m2 (1 − cos² q2))
    q̈2 = −(ℓ m2 cos q2 sin q2 q̇2² + u cos q2 + (m1 + m2) g sin q2) / (ℓ m1 + ℓ m2 (1 − cos² q2))

Kelly reports no optimal value: the reference optimum is ours (`CLASSIC.source`), the best of two local
minima found (`CLASSIC.note`).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic

M1, M2, ELL, G = 1.0, 0.3, 0.5, 9.81  # kg, kg, m, m/s²
D, D_MAX, U_MAX, DURATION = 1.0, 2.0, 20.0, 2.0  # m, m, N, s


def build() -> Ocp:
    ocp = Ocp(T=DURATION, name="cart-pole")
    q1 = ocp.state("q1", lower=-D_MAX, upper=D_MAX, start=0.0, end=D)
    q2 = ocp.state("q2", start=0.0, end=np.pi, guess=lambda tau: np.pi * tau - np.sin(np.pi * tau))  # lags first
    dq1 = ocp.state("dq1", start=0.0, end=0.0)
    dq2 = ocp.state("dq2", start=0.0, end=0.0)
    u = ocp.control("u", lower=-U_MAX, upper=U_MAX)
    s, c = ca.sin(q2), ca.cos(q2)
    ocp.set_der(q1, dq1)
    ocp.set_der(q2, dq2)
    ocp.set_der(dq1, (ELL * M2 * s * dq2**2 + u + M2 * G * c * s) / (M1 + M2 * (1 - c**2)))
    ocp.set_der(dq2, -(ELL * M2 * c * s * dq2**2 + u * c + (M1 + M2) * G * s) / (ELL * M1 + ELL * M2 * (1 - c**2)))
    ocp.minimize_integral(u**2)
    return ocp


CLASSIC = Classic("cart-pole", build, optimum=57.94478, smooth=True,
                  source="reference computed for ocpkit (Kelly 2017 reports none): Radau collocation, degree 3-4, "
                         "100-400 intervals, control at the collocation points, IPOPT tol 1e-10: 57.944780 N²·s",
                  note="a second local minimum at 58.80767 (the cart overshooting to 1.18 m instead of first backing "
                       "up) is 1.5 % higher: from the straight-line guess every transcription lands there; the guess "
                       "here has the pole lag the line at first (q2 = πτ − sin πτ) and reaches the lower one")
