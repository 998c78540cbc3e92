"""Cross-check of ompl-topp3's timing against copp-py's TOPP3 (sequential convex programming, Clarabel SOCP) on
one path: paper case 4's OMPL path, the robot without friction (copp's torque is the rigid-body torque) and
μ = 0 (time-optimal), under the same velocity, torque and torque-rate limits.

copp-py imposes its limits at stations along s and linearises the third-order rows around the previous
profile; ocpkit's path-timing OCP imposes them on its transcription's points and checks, and `verify` densely.
Both answer the same problem, so their motion times must agree closely."""

from __future__ import annotations

import dataclasses

import copp_py as copp  # a test dependency (.[test])
import numpy as np
import pinocchio as pin
import pytest
from helpers import REPO

import ocpkit

STATIONS = 151
SCP_ROUNDS = 12


def frictionless_time_optimal(case: str) -> ocpkit.Problem:
    problem = ocpkit.load_scenario(REPO / f"scenarios/paper/{case}.yaml")
    r = problem.robot
    robot = dataclasses.replace(r, viscous=0 * r.viscous, coulomb=0 * r.coulomb, key=f"{r.key}:frictionless")
    return dataclasses.replace(problem, robot=robot, mu=0.0)


def torque_terms(robot, path, s):
    """τ(s, a, b) = m(s) b + c(s) a + g(s) along the path (a = ṡ², b = s̈): (m, c, g), each (n,)."""
    data = robot.model.createData()
    q, dq, ddq, _ = (v[0] for v in path.values(np.atleast_1d(s)))
    g = pin.rnea(robot.model, data, q, 0 * q, 0 * q).copy()
    m = pin.rnea(robot.model, data, q, 0 * q, dq) - g
    c = pin.rnea(robot.model, data, q, dq, ddq) - g
    return np.stack([m, c, g])


def copp_topp3(problem, path) -> float:
    """copp-py's time-optimal t_f (s) along `path` with the problem's velocity, torque and torque-rate limits.

    τ̇ = ṡ (m c_s + (m′ + 2c) b + c′ a + g′) with c_s = db/ds, which is copp's third-order row
    √a (jerk_a a + jerk_b b + jerk_c c_s + jerk_d) ≤ jerk_max; the derivatives in s by central differences."""
    robot, s = problem.robot, np.linspace(0.0, 1.0, STATIONS)
    data = robot.model.createData()
    h = 1e-6
    terms = np.array([torque_terms(robot, path, x) for x in s])
    slopes = np.array([(torque_terms(robot, path, x + h) - torque_terms(robot, path, x - h)) / (2 * h) for x in s])
    (m, c), (dm, dc, dg) = terms[:, :2].transpose(1, 0, 2), slopes.transpose(1, 0, 2)
    model = copp.Robot(robot.n, inverse_dynamics=lambda q, v, a: pin.rnea(robot.model, data, q, v, a).copy())
    model.append_s(s)
    model.set_q(*path.values(s)[:3], 0, dddq=path.values(s)[3])
    model.add_velocity_limits(robot.qd_max, -robot.qd_max, start_idx_s=0)
    model.add_torque_limits(robot.tau_max, -robot.tau_max, start_idx_s=0)
    limit = np.tile(robot.taud_max, (STATIONS, 1))
    for sign in (1.0, -1.0):
        model.constraints.add_constraint_3rd(sign * dc, sign * (dm + 2 * c), sign * m, sign * dg, limit, 0)
    a = copp.solver.topp2_ra.solve(copp.solver.topp2_ra.Problem(model.constraints, (0, STATIONS - 1)))
    b, times = None, []
    for _ in range(SCP_ROUNDS):
        profile = copp.solver.topp3_socp.solve(copp.solver.topp3_socp.Problem(model.constraints, a,
                                                                               b_linearization=b))
        times.append(copp.interpolation.s_to_t_topp3(s, profile)[0])
        if len(times) > 2 and abs(times[-1] - times[-2]) < 2e-3 * times[-1]:
            break
        a, b = profile.a, profile.b
    return times[-1]


@pytest.mark.slow
def test_ompl_topp3_timing_agrees_with_copp_topp3_on_a_paper_path():
    problem = frictionless_time_optimal("case4")
    plan = ocpkit.plan(problem, planner="ompl-topp3", transcription="trapezoidal", knots=40)
    assert plan.status == "verified", plan.verification.summary()
    reference = copp_topp3(problem, plan.trajectory.interpolant.ocp.path)
    assert plan.trajectory.tf == pytest.approx(reference, rel=0.01)
