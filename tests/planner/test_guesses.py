"""The straight-line guesses: the paper's t_f = time.guess, the default's velocity and torque estimate."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from helpers import REPO

from ocpkit.formats.scenario import load_scenario
from ocpkit.planner.guesses import PEAK_SPEED, motion_time_estimate, quintic, torque_ratio

CASE2 = load_scenario(REPO / "scenarios/paper/case2.yaml")


def test_quintic_derivatives_match_finite_differences():
    tau, h = np.linspace(0.1, 0.9, 9), 1e-6
    s, ds, dds = quintic(tau)
    np.testing.assert_allclose(ds, (quintic(tau + h)[0] - quintic(tau - h)[0]) / (2 * h), atol=1e-6)
    np.testing.assert_allclose(dds, (quintic(tau + h)[1] - quintic(tau - h)[1]) / (2 * h), atol=1e-5)
    assert np.max(quintic(np.linspace(0, 1, 10001))[1]) == pytest.approx(PEAK_SPEED)


def test_estimate_keeps_the_quintic_within_velocity_and_torque_limits():
    tf = motion_time_estimate(CASE2)
    assert tf == pytest.approx(PEAK_SPEED * CASE2.velocity_lower_bound())  # torque allows it on case 2
    assert torque_ratio(CASE2, tf) <= 1.0


def test_weak_motors_lengthen_the_estimate_until_the_torque_fits():
    weak = dataclasses.replace(CASE2.robot, tau_max=CASE2.robot.tau_max * 0.05)
    problem = dataclasses.replace(CASE2, robot=weak)
    tf = motion_time_estimate(problem)
    assert tf > PEAK_SPEED * CASE2.velocity_lower_bound()
    assert torque_ratio(problem, tf) <= 1.0 or tf == problem.time.max
