"""The classic problems: every one builds a complete `Ocp` with a finite published optimum and a source, the
Bryson–Denham costates follow the stated convention, and an unknown name lists the known ones."""

from __future__ import annotations

import numpy as np
import pytest

from ocpkit.errors import OptionError
from ocpkit.problems import CLASSICS, bryson_denham, classic

NAMES = ["double-integrator", "bryson-denham", "brachistochrone", "goddard", "cart-pole", "hang-glider",
         "free-flying-robot"]


def test_the_registry_holds_the_seven_classics_in_order():
    assert list(CLASSICS) == NAMES


@pytest.mark.parametrize("name", NAMES)
def test_every_classic_builds_a_complete_ocp_with_an_optimum_and_a_source(name):
    record = classic(name)
    ocp = record.build()
    ocp.check()
    assert ocp.name == name and record.name == name
    assert np.isfinite(record.optimum) and record.source
    assert record.build() is not ocp  # a fresh problem every call


def test_an_unknown_name_lists_the_known_ones():
    with pytest.raises(OptionError, match="unknown classic problem 'nope'; known: double-integrator, bryson-denham"):
        classic("nope")


def test_bryson_denham_costates_satisfy_the_stated_conditions():
    t = np.linspace(0.0, 1.0, 901)
    lam_x, lam_v = bryson_denham.costates(t)
    ell = bryson_denham.ELL
    u = np.where(t < 3 * ell, -2 / (3 * ell) * (1 - t / (3 * ell)),
                 np.where(t > 1 - 3 * ell, -2 / (3 * ell) * (1 - (1 - t) / (3 * ell)), 0.0))
    np.testing.assert_allclose(-lam_v, u, atol=1e-12)  # ∂H/∂u = u + λv = 0
    off = (np.abs(t - bryson_denham.JUNCTIONS[0]) > 1e-3) & (np.abs(t - bryson_denham.JUNCTIONS[1]) > 1e-3)
    np.testing.assert_allclose(np.gradient(lam_v, t)[off], -lam_x[off], atol=1e-6)  # λ̇v = −∂H/∂v = −λx
    assert lam_x[0] == pytest.approx(2 / (9 * ell**2)) and lam_x[-1] == pytest.approx(-2 / (9 * ell**2))
    assert bryson_denham.CLASSIC.optimum == pytest.approx(4.0)
