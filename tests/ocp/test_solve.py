"""Solving an Ocp with every transcription against closed forms: the minimum-energy and minimum-time double
integrators, a free parameter, scaling, costates (smooth: exact; Bryson–Denham's: on each arc)."""

from __future__ import annotations

import numpy as np
import pytest

from ocpkit.ocp import Ocp, solve
from ocpkit.ocp.certify import certify

PSEUDOSPECTRAL = ("chebyshev", "lgl", "lgr")
MESH = ("trapezoidal", "hermite-simpson")


def energy(scale: float = 1.0) -> Ocp:
    """min ½∫u² dt, ẍ = u, (x, v) from (0, 0) to (1, 0) in T = 1: u = 6 − 12t, J* = 6, λx = −12, λv = 12t − 6."""
    ocp = Ocp(T=1.0, name="energy")
    x, v = ocp.state("x", start=0, end=1, scale=scale), ocp.state("v", start=0, end=0)
    u = ocp.control("u")
    ocp.set_der(x, v)
    ocp.set_der(v, u)
    ocp.minimize_integral(0.5 * u ** 2)
    return ocp


def minimum_time() -> Ocp:
    """min T, ẍ = u, |u| ≤ 1, (0, 0) to (1, 0): bang-bang, T* = 2."""
    ocp = Ocp(T_bounds=(0.1, 10.0), T_guess=1.0, name="minimum-time")
    x, v = ocp.state("x", start=0, end=1), ocp.state("v", start=0, end=0)
    u = ocp.control("u", lower=-1, upper=1)
    ocp.set_der(x, v)
    ocp.set_der(v, u)
    ocp.minimize_end(ocp.T)
    return ocp


@pytest.mark.parametrize("transcription", PSEUDOSPECTRAL)
def test_a_smooth_optimum_and_its_costates_are_exact_with_a_pseudospectral_transcription(transcription):
    solution = solve(energy(), transcription, 8)
    assert solution.converged and solution.objective == pytest.approx(6.0, rel=1e-8)
    t = np.linspace(0, 1, 7)
    np.testing.assert_allclose(solution.u("u", t), 6 - 12 * t, atol=1e-6)
    times, lam = solution.costates()
    np.testing.assert_allclose(lam[:, 0], -12.0, rtol=1e-6)
    np.testing.assert_allclose(lam[:, 1], 12 * times - 6, atol=1e-6)
    assert certify(solution).state_error < 1e-8  # linear dynamics, polynomial control: re-integration exact


@pytest.mark.parametrize("transcription", MESH)
def test_a_mesh_method_converges_to_the_smooth_optimum_and_gives_no_costates(transcription):
    solution = solve(energy(), transcription, 40)
    assert solution.objective == pytest.approx(6.0, rel=5e-3)  # second order: 2.5e-3 at 40 intervals
    with pytest.raises(ValueError, match="no costate estimates"):
        solution.costates()


@pytest.mark.parametrize("transcription", PSEUDOSPECTRAL + MESH)
def test_minimum_time_double_integrator(transcription):
    solution = solve(minimum_time(), transcription, 30)
    assert solution.converged and solution.T == pytest.approx(2.0, rel=3e-3)
    assert abs(solution.objective - solution.T) < 1e-12


def test_scaling_a_state_leaves_the_solution_unchanged():
    plain, scaled = solve(energy(), "lgr", 8), solve(energy(scale=100.0), "lgr", 8)
    assert scaled.objective == pytest.approx(plain.objective, rel=1e-9)
    t = np.linspace(0, 1, 5)
    np.testing.assert_allclose(scaled.x("x", t), plain.x("x", t), atol=1e-9)
    np.testing.assert_allclose(scaled.costates()[1], plain.costates()[1], rtol=1e-6, atol=1e-6)


def test_a_free_parameter_is_optimized_and_end_rows_hold():
    """ẋ = u, x(0) = 0, x(1) = p, min ½∫u² − p: p* = 1, J* = −½."""
    ocp = Ocp(T=1.0)
    x, u, p = ocp.state("x", start=0), ocp.control("u"), ocp.parameter("p", lower=0, upper=2)
    ocp.set_der(x, u)
    ocp.at_end(x - p, 0, 0)
    ocp.minimize_integral(0.5 * u ** 2)
    ocp.minimize_end(-p)
    solution = solve(ocp, "chebyshev", 6)
    assert solution.p("p") == pytest.approx(1.0, abs=1e-8) and solution.objective == pytest.approx(-0.5, abs=1e-8)
    assert certify(solution).passed


@pytest.mark.parametrize("transcription", PSEUDOSPECTRAL + MESH)
def test_time_dependent_dynamics(transcription):
    """ẋ = t u, x(0) = 0, x(1) = 1, min ½∫u² dt: u = 3t, J* = 3/2 (λ = −3 constant); a path row reading t,
    x ≤ t, holds along the optimum x = t³ and is imposed."""
    ocp = Ocp(T=1.0)
    x, u = ocp.state("x", start=0, end=1), ocp.control("u")
    ocp.set_der(x, ocp.t * u)
    ocp.subject_to(x - ocp.t, upper=0.0)
    ocp.minimize_integral(0.5 * u ** 2)
    solution = solve(ocp, transcription, 8 if transcription in PSEUDOSPECTRAL else 60)
    exact = transcription in PSEUDOSPECTRAL
    assert solution.converged and solution.objective == pytest.approx(1.5, rel=1e-8 if exact else 2e-3)
    t = np.linspace(0.0, 1.0, 5)
    np.testing.assert_allclose(solution.u("u", t), 3 * t, atol=1e-6 if exact else 0.05)
    assert certify(solution).passed


@pytest.mark.parametrize("transcription", ["lgr", "hermite-simpson"])
def test_a_control_rate_bound_holds_and_lengthens_the_minimum_time(transcription):
    ocp = minimum_time()
    u = ocp.controls[0].symbol
    ocp.subject_to(ocp.rate(u), -4.0, 4.0)
    solution = solve(ocp, transcription, 30)
    assert solution.converged and solution.T > 2.01  # the switch from +1 to −1 takes 0.5 s instead of none
    knots = solution.knot_times
    assert np.max(np.abs(solution.sample(knots)[2])) <= 4.0 * (1 + 1e-6)


def test_bryson_denham_costates_on_each_arc():
    """x ≤ ℓ = 1/9 with three segments meeting at the junctions 3ℓ and 1 − 3ℓ: λx = ±2/(9ℓ²) on the unconstrained
    arcs, 0 on the constrained one (Bryson & Ho 1975, §3.11)."""
    ell = 1 / 9
    ocp = Ocp(T=1.0)
    x, v = ocp.state("x", start=0, end=0, upper=ell), ocp.state("v", start=1, end=-1)
    u = ocp.control("u")
    ocp.set_der(x, v)
    ocp.set_der(v, u)
    ocp.minimize_integral(0.5 * u ** 2)
    solution = solve(ocp, "lgr", 10, transcription_options={"segments": 3})
    assert solution.objective == pytest.approx(4 / (9 * ell), rel=1e-6)
    t, lam = solution.costates()
    inside = (np.abs(t - 3 * ell) > 0.02) & (np.abs(t - (1 - 3 * ell)) > 0.02)
    expected = np.where(t < 3 * ell, 2 / (9 * ell ** 2), np.where(t > 1 - 3 * ell, -2 / (9 * ell ** 2), 0.0))
    np.testing.assert_allclose(lam[inside, 0], expected[inside], atol=0.01 * 2 / (9 * ell ** 2))


def test_the_certificate_sees_a_corrupted_control():
    solution = solve(energy(), "chebyshev", 8)
    assert certify(solution).passed
    w = solution.result.w.copy()
    w[solution.discretization.nlp.variables.index("u")] += 0.5
    broken = type(solution)(solution.model, solution.ocp, solution.discretization,
                            type(solution.result)(w, *list(vars(solution.result).values())[1:]),
                            solution.objective, solution.transcription, solution.knots)
    certificate = certify(broken)
    assert not certificate.passed and certificate.state_error > 0.1


def test_a_fixed_initial_time_other_than_zero():
    """ẋ = t u on [1, 3], x(1) = 0, x(3) = 1, min ½∫u² dt: u = 3t/26 (λ = −3/26), J* = ½ (3/26)² 26/3 = 39/676."""
    ocp = Ocp(T=3.0, t0=1.0)
    x, u = ocp.state("x", start=0, end=1), ocp.control("u")
    ocp.set_der(x, ocp.t * u)
    ocp.minimize_integral(0.5 * u ** 2)
    solution = solve(ocp, "lgr", 8)
    assert solution.t0 == 1.0 and solution.T == pytest.approx(3.0)
    assert solution.objective == pytest.approx(39 / 676, rel=1e-8)
    np.testing.assert_allclose(solution.u("u", np.array([1.0, 2.0, 3.0])), 3 * np.array([1.0, 2.0, 3.0]) / 26,
                               atol=1e-7)
    assert certify(solution).passed


@pytest.mark.parametrize("transcription", ["chebyshev", "hermite-simpson"])
def test_a_free_initial_time(transcription):
    """ẋ = u, |u| ≤ 1, x(t0) = 0, x(3) = 1, t0 ∈ [0, 2.5], start as late as possible: t0* = 2 (one second at full
    speed)."""
    ocp = Ocp(T=3.0, t0=(0.0, 2.5))
    x, u = ocp.state("x", start=0, end=1), ocp.control("u", lower=-1, upper=1)
    ocp.set_der(x, u)
    ocp.minimize_end(-ocp.t0)
    solution = solve(ocp, transcription, 20)
    assert solution.converged and solution.t0 == pytest.approx(2.0, abs=1e-6) and solution.T == pytest.approx(3.0)
    assert certify(solution).passed
