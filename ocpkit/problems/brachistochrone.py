"""Brachistochrone as in dymos' example (OpenMDAO/dymos, dymos/examples/brachistochrone): a bead slides without
friction from (x, y) = (0, 10) m at rest to x = 10 m, y = 5 m in minimum time; ẋ = v sin θ, ẏ = −v cos θ,
v̇ = g cos θ, g = 9.80665 m/s², wire angle θ (rad, from the downward vertical) in [0.01°, 179.9°], t_f in
[0.5, 10] s.

Optimum: the cycloid through both points (Bernoulli, 1697), x = r(φ − sin φ), y_0 − y = r(1 − cos φ), reaches
them at φ_f with (φ_f − sin φ_f)/(1 − cos φ_f) = Δx/Δy in t_f* = φ_f √(r/g) = 1.8016031 s (`cycloid_time`);
dymos' tests assert 1.8016 s. Units: m, m/s, rad, s.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from scipy.optimize import brentq

from ocpkit.ocp.model import Ocp
from ocpkit.problems.classic import Classic

G = 9.80665  # m/s²
DX, DY = 10.0, 5.0  # m, across and down


def cycloid_time() -> float:
    """t_f* (s) of the cycloid from rest through (DX, −DY) (module docstring)."""
    phi = brentq(lambda p: (p - np.sin(p)) / (1 - np.cos(p)) - DX / DY, 1e-3, 2 * np.pi - 1e-3)
    return float(phi * np.sqrt(DY / (1 - np.cos(phi)) / G))


def build() -> Ocp:
    ocp = Ocp(T_bounds=(0.5, 10.0), T_guess=2.0, name="brachistochrone")
    x = ocp.state("x", start=0.0, end=DX)
    y = ocp.state("y", start=10.0, end=10.0 - DY)
    v = ocp.state("v", start=0.0, guess=5.0)
    theta = ocp.control("theta", lower=np.radians(0.01), upper=np.radians(179.9))
    ocp.set_der(x, v * ca.sin(theta))
    ocp.set_der(y, -v * ca.cos(theta))
    ocp.set_der(v, G * ca.cos(theta))
    ocp.minimize_end(ocp.T)
    return ocp


CLASSIC = Classic("brachistochrone", build, optimum=cycloid_time(), smooth=True,
                  source="the cycloid's closed form (Bernoulli 1697): t_f = 1.8016031 s; dymos' example asserts "
                         "1.8016 s")
