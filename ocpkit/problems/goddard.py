"""Goddard rocket, maximum ascent, in the normalized form of COPS (Dolan, Moré, Munson, "Benchmarking Optimization
Software with COPS 3.0", ANL/MCS-TM-273, 2004, §10 "Goddard Rocket").

States height h, velocity v, mass m; control thrust 0 ≤ T ≤ T_max; free t_f; ḣ = v, v̇ = (T − D)/m − g, ṁ = −T/c,
D = D_c v² exp(−h_c (h − h0)/h0), g = g0 (h0/h)², with the COPS constants h0 = m0 = g0 = 1, v0 = 0,
T_c = 3.5, h_c = 500, v_c = 620, m_c = 0.6, T_max = T_c g0 m0, D_c = ½ v_c m0/g0, m_f = m_c m0, c = ½ √(g0 h0).
Bounds h ≥ h0, v ≥ 0, m_f ≤ m ≤ m0; m(t_f) = m_f. Maximize h(t_f), written as minimize −h(t_f): the published
optimum h(t_f) = 1.01283 (COPS 3.0), objective −1.01283. Dimensionless.
"""

from __future__ import annotations

import casadi as ca

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic

H0, V0, M0, G0 = 1.0, 0.0, 1.0, 1.0
TC, HC, VC, MC = 3.5, 500.0, 620.0, 0.6
T_MAX, D_C, M_F, C = TC * G0 * M0, 0.5 * VC * M0 / G0, MC * M0, 0.5 * (G0 * H0) ** 0.5


def build() -> Ocp:
    ocp = Ocp(T_bounds=(0.05, 1.0), T_guess=0.2, name="goddard")
    h = ocp.state("h", lower=H0, start=H0, guess=1.005)
    v = ocp.state("v", lower=0.0, start=V0, guess=0.05, scale=0.1)
    m = ocp.state("m", lower=M_F, upper=M0, start=M0, end=M_F)
    thrust = ocp.control("thrust", lower=0.0, upper=T_MAX)
    drag = D_C * v**2 * ca.exp(-HC * (h - H0) / H0)
    ocp.set_der(h, v)
    ocp.set_der(v, (thrust - drag) / m - G0 * (H0 / h) ** 2)
    ocp.set_der(m, -thrust / C)
    ocp.minimize_end(-h)
    return ocp


CLASSIC = Classic("goddard", build, optimum=-1.01283, smooth=False,
                  source="COPS 3.0 (Dolan, Moré, Munson 2004), goddard: h(t_f) = 1.01283",
                  note="bang-singular-bang thrust; t_f bounds and guesses are ours, not COPS'")
