"""The public Ocp description: declarations and the errors that name what is wrong."""

from __future__ import annotations

import casadi as ca
import pytest

from ocpkit.errors import OptionError
from ocpkit.ocp import Ocp, solve


def test_declarations_are_recorded_with_bounds_guesses_and_scales():
    ocp = Ocp(T_bounds=(0.5, 4.0))
    x = ocp.state("x", 2, lower=[-1, -2], upper=3, start=[0, 1], end=[1, 1], scale=2.0)
    u = ocp.control("u", lower=-1, upper=1)
    ocp.set_der(x, ca.vertcat(x[1], u))
    state = ocp.states[0]
    assert state.size == 2 and list(state.lower) == [-1, -2] and list(state.upper) == [3, 3]
    assert list(state.guess) == [0.5, 1.0]  # between the fixed start and end
    assert ocp.controls[0].guess[0] == 0.0 and ocp.T_guess == pytest.approx(2.25)


@pytest.mark.parametrize("declare, message", [
    (lambda o: o.state("x", lower=1, upper=0), "lower > upper"),
    (lambda o: o.state("x", 2, start=[0, 1, 2]), "x.start: expected 1 or 2 values, got 3"),
    (lambda o: o.state("tf"), "cannot name a variable"),
    (lambda o: (o.state("x"), o.control("x")), "already declared"),
    (lambda o: o.control("u", scale=0), "scale must be > 0"),
    (lambda o: o.set_der(ca.SX.sym("y"), 1), "set_der() takes a declared state"),
    (lambda o: o.rate(o.state("x")), "rate() takes a declared control"),
    (lambda o: o.minimize_end(ca.SX.sym("a", 2)), "minimize_end takes a scalar"),
])
def test_bad_declarations_name_the_field(declare, message):
    with pytest.raises(OptionError, match=message.replace("(", r"\(").replace(")", r"\)")):
        declare(Ocp(T=1.0))


def test_a_missing_derivative_and_a_stray_symbol_are_named_before_any_build():
    ocp = Ocp(T=1.0, name="demo")
    x, y = ocp.state("x"), ocp.state("y")
    ocp.set_der(x, y)
    with pytest.raises(OptionError, match="demo: no set_der\\(\\) for the state\\(s\\) y"):
        solve(ocp)
    ocp.set_der(y, ca.SX.sym("stray"))
    with pytest.raises(OptionError, match="set_der reads a symbol that is not a declared"):
        solve(ocp)


def test_a_rate_in_the_dynamics_is_refused():
    ocp = Ocp(T=1.0)
    x, u = ocp.state("x"), ocp.control("u")
    ocp.set_der(x, ocp.rate(u))
    with pytest.raises(OptionError, match="set_der reads a symbol it cannot"):
        solve(ocp)


@pytest.mark.parametrize("T, bounds", [(0.0, (0, 1)), (None, (2.0, 1.0))])
def test_bad_final_times_are_refused(T, bounds):
    with pytest.raises(OptionError, match="T"):
        Ocp(T=T, T_bounds=bounds)


@pytest.mark.parametrize("t0", [(2.0, 1.0), (0.0, float("inf")), (1.0, 2.0, 3.0)])
def test_bad_initial_times_are_refused(t0):
    with pytest.raises(OptionError, match="t0 must be a number or"):
        Ocp(T=5.0, t0=t0)
