"""Minimum-time double integrator, rest to rest: ẍ = u, |u| ≤ 1, from (x, v) = (0, 0) to (1, 0), minimize t_f.

Analytic optimum (Pontryagin; the minimum-time problems of Kirk, "Optimal Control Theory", 1970, ch. 5): bang-bang,
u = +1 on [0, 1) and −1 on [1, 2], one switch at t = 1 s, so x(t_f) = t_f²/4 = 1 gives t_f* = 2 s. Units: m, m/s,
m/s², s.
"""

from __future__ import annotations

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic


def build() -> Ocp:
    ocp = Ocp(T_bounds=(0.1, 10.0), T_guess=1.0, name="double-integrator")
    x = ocp.state("x", start=0.0, end=1.0)
    v = ocp.state("v", start=0.0, end=0.0)
    u = ocp.control("u", lower=-1.0, upper=1.0)
    ocp.set_der(x, v)
    ocp.set_der(v, u)
    ocp.minimize_end(ocp.T)
    return ocp


CLASSIC = Classic("double-integrator", build, optimum=2.0, smooth=False,
                  source="analytic: bang-bang with one switch at t = 1 s (Pontryagin; Kirk 1970, ch. 5)")
