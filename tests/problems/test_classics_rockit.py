"""The classic problems solved by rockit (`ocpkit.ocp.rockit_peer`) reach their published optimum within 1 %
(discretization error: rockit's controls are piecewise constant), on the cheap problems and grids."""

from __future__ import annotations

import numpy as np
import pytest

from ocpkit.errors import OptionError
from ocpkit.ocp.model import Ocp
from ocpkit.ocp.rockit_peer import solve_with_rockit
from ocpkit.problems import classic

pytest.importorskip("rockit")

CASES = [("double-integrator", "multiple-shooting", 50), ("bryson-denham", "multiple-shooting", 50),
         ("brachistochrone", "direct-collocation", 30), ("goddard", "multiple-shooting", 50),
         ("hang-glider", "direct-collocation", 50), ("free-flying-robot", "multiple-shooting", 50)]


@pytest.mark.parametrize(("name", "method", "intervals"), CASES)
def test_rockit_reaches_the_published_optimum(name, method, intervals):
    record = classic(name)
    result = solve_with_rockit(record.build(), method, intervals)
    assert result.success, result.status
    assert result.objective == pytest.approx(record.optimum, rel=1e-2)
    assert result.t.shape == (intervals + 1,) and result.t[-1] == pytest.approx(result.T)
    assert result.x.shape[0] == result.u.shape[0] == intervals + 1


def test_the_solution_keeps_the_fixed_ends_and_the_bounds():
    result = solve_with_rockit(classic("double-integrator").build(), "multiple-shooting", 20)
    np.testing.assert_allclose(result.x[0], [0.0, 0.0], atol=1e-8)
    np.testing.assert_allclose(result.x[-1], [1.0, 0.0], atol=1e-6)
    assert np.all(np.abs(result.u) <= 1.0 + 1e-6) and result.parameters.shape == (0,)


def test_parameters_and_control_rates_translate():
    ocp = Ocp(T=1.0, name="rates")
    x = ocp.state("x", start=0.0, end=1.0)
    u = ocp.control("u", lower=-5.0, upper=5.0)
    p = ocp.parameter("p", lower=0.0, upper=10.0, guess=1.0)
    ocp.set_der(x, u)
    ocp.minimize_integral(ocp.rate(u) ** 2)  # u̇ = 0 and x(1) = 1: u = 1
    ocp.minimize_end((p - 2.0) ** 2)
    result = solve_with_rockit(ocp, "direct-collocation", 10)
    assert result.success and result.objective == pytest.approx(0.0, abs=1e-8)
    np.testing.assert_allclose(result.u[:, 0], 1.0, atol=1e-6)
    np.testing.assert_allclose(result.parameters, [2.0], atol=1e-6)


def test_an_unknown_method_is_an_option_error():
    with pytest.raises(OptionError, match="unknown rockit method 'shooting'"):
        solve_with_rockit(classic("double-integrator").build(), "shooting")
