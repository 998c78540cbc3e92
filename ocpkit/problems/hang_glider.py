"""Hang glider, maximum range through a thermal (Bulirsch, Nerz, Pesch, von Stryk, "Combining Direct and Indirect
Methods in Optimal Control: Range Maximization of a Hang Glider", 1993), in the form of COPS (Dolan, Moré, Munson,
"Benchmarking Optimization Software with COPS 3.0", ANL/MCS-TM-273, 2004, §11) with the boundary values and g of
Bulirsch et al. and Betts ("Practical Methods for Optimal Control and Estimation Using Nonlinear Programming",
2nd ed., 2010, §6.5), to which the published optimum belongs: COPS rounds them (vx = 13.23, vy = −1.288,
g = 9.81), which moves the optimum (`CLASSIC.note`).

States x, y (m), vx, vy (m/s); control lift coefficient 0 ≤ c_L ≤ 1.4; free t_f (s). With the updraft
u_a = u_M (1 − r) e^(−r), r = (x/R − 2.5)², w = vy − u_a, v = √(vx² + w²), D = ½ (c0 + c1 c_L²) ρ S v²,
L = ½ c_L ρ S v²: ẋ = vx, ẏ = vy, v̇x = (−L w/v − D vx/v)/m, v̇y = (L vx/v − D w/v)/m − g; u_M = 2.5 m/s,
R = 100 m, c0 = 0.034, c1 = 0.069662, S = 14 m², ρ = 1.13 kg/m³, m = 100 kg, g = 9.80665 m/s²;
(x, y, vx, vy)(0) = (0, 1000, 13.2275675, −1.28750052), (y, vx, vy)(t_f) = (900, 13.2275675, −1.28750052);
x ≥ 0, vx ≥ 0 (COPS). Maximize x(t_f), written as minimize −x(t_f): published x(t_f) = 1248.031 m, objective
−1248.031.
"""

from __future__ import annotations

import casadi as ca

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic

U_M, R, C0, C1, S, RHO, MASS, G = 2.5, 100.0, 0.034, 0.069662, 14.0, 1.13, 100.0, 9.80665
VX0, VY0 = 13.2275675, -1.28750052  # m/s, at both ends


def build() -> Ocp:
    ocp = Ocp(T_bounds=(10.0, 200.0), T_guess=100.0, name="hang-glider")
    x = ocp.state("x", lower=0.0, start=0.0, guess=1250.0, scale=1000.0)
    y = ocp.state("y", start=1000.0, end=900.0, scale=1000.0)
    vx = ocp.state("vx", lower=0.0, start=VX0, end=VX0, scale=10.0)
    vy = ocp.state("vy", start=VY0, end=VY0)
    c_lift = ocp.control("cL", lower=0.0, upper=1.4)
    r = (x / R - 2.5) ** 2
    w = vy - U_M * (1 - r) * ca.exp(-r)
    v = ca.sqrt(vx**2 + w**2)
    drag, lift = 0.5 * (C0 + C1 * c_lift**2) * RHO * S * v**2, 0.5 * c_lift * RHO * S * v**2
    ocp.set_der(x, vx)
    ocp.set_der(y, vy)
    ocp.set_der(vx, (-lift * w / v - drag * vx / v) / MASS)
    ocp.set_der(vy, (lift * vx / v - drag * w / v) / MASS - G)
    ocp.minimize_end(-x)
    return ocp


CLASSIC = Classic("hang-glider", build, optimum=-1248.031, smooth=False,
                  source="Bulirsch et al. 1993 / Betts 2010, §6.5: x(t_f) = 1248.031 m",
                  note="c_L rides its upper bound 1.4 on an arc; with COPS' rounded constants (13.23, -1.288, "
                       "g = 9.81) the optimum is x(t_f) = 1247.988 m instead (recomputed here); t_f bounds and "
                       "guesses are ours")
