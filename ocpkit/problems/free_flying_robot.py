"""Free-flying robot of Sakawa (1999) as in Betts, "Practical Methods for Optimal Control and Estimation Using
Nonlinear Programming", 2nd ed., 2010, example 6.13 (also PSOPT's and GPOPS' "free flying robot").

States position (x, y) (m), heading θ (rad), velocity (vx, vy), angular rate ω; four thruster controls
u = (u1, u2, u3, u4) ≥ 0 with u1 + u2 ≤ 1, u3 + u4 ≤ 1 (so each u_i ≤ 1); T1 = u1 − u2, T2 = u3 − u4:
ẋ = vx, ẏ = vy, θ̇ = ω, v̇x = (T1 + T2) cos θ, v̇y = (T1 + T2) sin θ, ω̇ = α T1 − β T2, α = β = 0.2.
From (−10, −10, π/2, 0, 0, 0) to rest at the origin in t_f = 12, minimize ∫ (u1 + u2 + u3 + u4) dt (fuel):
published J* = 7.9101471 (Betts 2010, example 6.13).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic

ALPHA, BETA = 0.2, 0.2


def build() -> Ocp:
    ocp = Ocp(T=12.0, name="free-flying-robot")
    x = ocp.state("x", start=-10.0, end=0.0)
    y = ocp.state("y", start=-10.0, end=0.0)
    theta = ocp.state("theta", start=np.pi / 2, end=0.0)
    vx = ocp.state("vx", start=0.0, end=0.0)
    vy = ocp.state("vy", start=0.0, end=0.0)
    omega = ocp.state("omega", start=0.0, end=0.0)
    u = ocp.control("u", size=4, lower=0.0, upper=1.0, guess=0.25)
    t1, t2 = u[0] - u[1], u[2] - u[3]
    ocp.set_der(x, vx)
    ocp.set_der(y, vy)
    ocp.set_der(theta, omega)
    ocp.set_der(vx, (t1 + t2) * ca.cos(theta))
    ocp.set_der(vy, (t1 + t2) * ca.sin(theta))
    ocp.set_der(omega, ALPHA * t1 - BETA * t2)
    ocp.subject_to(ca.vertcat(u[0] + u[1], u[2] + u[3]), upper=1.0)
    ocp.minimize_integral(ca.sum1(u))
    return ocp


CLASSIC = Classic("free-flying-robot", build, optimum=7.9101471, smooth=False,
                  source="Betts 2010, example 6.13: J* = 7.9101471",
                  note="bang-bang thrusts")
