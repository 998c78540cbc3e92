"""Per-plan metrics against closed forms, and the per-group summary against numpy on known rows."""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest

from ocpkit.bench.metrics import end_effector_positions, plan_metrics, success_grid, summarize, time_split
from ocpkit.formats.trajectory import Samples
from ocpkit.robots import load_robot


def samples_of(q: np.ndarray, tau: np.ndarray, dt: float = 1e-3) -> Samples:
    t = dt * np.arange(len(q))
    zeros = np.zeros_like(q)
    return Samples(t, q, zeros, zeros, tau, np.gradient(tau, t, axis=0))


def test_a_base_rotation_gives_arc_lengths_and_the_limit_fractions():
    robot = load_robot("industrial6")
    start = np.array([0.0, 0.3, -0.2, 0.0, 0.4, 0.0])
    angle = 1.2  # rad about the vertical base axis: the flange moves on a circle
    q = start + np.outer(np.linspace(0, 1, 2001), [angle, 0, 0, 0, 0, 0])
    tau = np.outer(np.sin(np.linspace(0, np.pi, 2001)), 0.5 * robot.tau_max)  # half the limit at the top
    metrics = plan_metrics(robot, samples_of(q, tau))
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, start)
    flange = data.oMi[robot.model.njoints - 1].translation
    radius = np.hypot(flange[0], flange[1])  # joint 1 turns about the world z axis through the origin
    assert metrics["path_length_rad"] == pytest.approx(angle, rel=1e-9)
    assert metrics["ee_path_length_m"] == pytest.approx(radius * angle, rel=1e-5)
    assert metrics["peak_torque_use"] == pytest.approx(0.5, rel=1e-6)
    rate = 0.5 * robot.tau_max * np.pi / 2.0  # d/dt of 0.5 τmax sin(π t / 2 s) at t = 0
    assert metrics["peak_torque_rate_use"] == pytest.approx(np.max(rate / robot.taud_max), rel=1e-3)


def test_end_effector_positions_are_pinocchios_last_joint_origin_for_a_flange_robot():
    robot = load_robot("industrial6")  # its flange frame sits at the last joint's origin
    q = np.random.default_rng(0).uniform(-1, 1, (3, robot.n))
    data = robot.model.createData()
    for k, position in enumerate(end_effector_positions(robot, q)):
        pin.forwardKinematics(robot.model, data, q[k])
        assert np.allclose(position, data.oMi[robot.model.njoints - 1].translation)


def test_the_panda_and_ur5_end_effectors_are_their_tool_points_at_the_zero_pose():
    # Panda (Franka's DH table): flange at x = a7 = 0.088, z = d1 + d3 + d5 - d_F = 0.333 + 0.316 + 0.384 - 0.107,
    # pointing down; the hand's TCP 0.1034 m below it.
    panda = load_robot("panda")
    assert end_effector_positions(panda, np.zeros((1, 7)))[0] == pytest.approx([0.088, 0.0, 0.926 - 0.1034], abs=1e-6)
    # UR5 (UR's DH: d1 0.089159, a2 -0.425, a3 -0.39225, d4 0.10915, d5 0.09465, d6 0.0823): tool0 at the zero pose
    # is (-(a2 + a3), d4 + d6, d1 - d5) in the URDF's base_link, which the spec yaws by 1.57 rad and lifts 0.9144 m.
    ur5 = load_robot("ur5")
    local = np.array([0.425 + 0.39225, 0.10915 + 0.0823, 0.089159 - 0.09465])
    c, s = np.cos(1.57), np.sin(1.57)
    world = np.array([c * local[0] - s * local[1], s * local[0] + c * local[1], local[2] + 0.9144])
    assert end_effector_positions(ur5, np.zeros((1, 6)))[0] == pytest.approx(world, abs=1e-4)


def row(method: str, scene: str, status: str, time: float, tf: float = 1.0, setup: float = 0.5) -> dict:
    metrics = {"path_length_rad": "1", "ee_path_length_m": "2", "peak_torque_use": "0.5", "peak_torque_rate_use": "0.9"}
    return {"method": method, "scene": scene, "status": status, "solve_time_s": str(time), "tf": str(tf),
            "setup_time_s": str(setup), **metrics}


def test_summary_times_are_over_the_verified_runs_and_success_is_a_rate():
    times = [0.1, 0.2, 0.4, 0.8, 3.0]
    rows = [row("a", "s1", "verified", t) for t in times] + [row("a", "s2", "violated", 9.0),
                                                            row("b", "s1", "no_path", 1.0)]
    a, b = summarize(rows, ("method",))
    assert a["runs"] == 6 and a["success_%"] == pytest.approx(500 / 6)
    assert a["time_mean_s"] == pytest.approx(np.mean(times)) and a["time_median_s"] == 0.4
    assert a["time_p75_s"] == pytest.approx(np.percentile(times, 75))
    assert a["time_p98_s"] == pytest.approx(np.percentile(times, 98))
    assert b["success_%"] == 0 and np.isnan(b["time_median_s"])
    assert a["setup_median_s"] == 0.5 and b["all_median_s"] == 1.5  # a failure's wait counts in all_*
    waited = [t + 0.5 for t in times + [9.0]]
    assert a["all_median_s"] == pytest.approx(np.median(waited)) and a["all_p90_s"] == pytest.approx(
        np.percentile(waited, 90))
    assert [(r["method"], r["scene"], r["runs"]) for r in summarize(rows, ("method", "scene"))] == [
        ("a", "s1", 5), ("a", "s2", 1), ("b", "s1", 1)]
    methods, scenes, rates = success_grid(rows)
    assert methods == ["a", "b"] and scenes == ["s1", "s2"]
    assert rates[0].tolist() == [100.0, 0.0] and rates[1, 0] == 0.0 and np.isnan(rates[1, 1])


def test_the_tables_do_not_depend_on_the_order_the_plans_finished_in():
    rows = [row("b", "s2", "verified", 1.0), row("a", "s1", "violated", 2.0), row("b", "s1", "verified", 3.0),
            row("a", "s2", "verified", 4.0)]
    for by in (("method",), ("method", "scene")):
        assert str(summarize(rows, by)) == str(summarize(rows[::-1], by))  # NaN cells too
        assert [tuple(r[c] for c in by) for r in summarize(rows, by)] == sorted({tuple(r[c] for c in by) for r in rows})
    forward, backward = success_grid(rows), success_grid(rows[::-1])
    assert forward[:2] == backward[:2] == (["a", "b"], ["s1", "s2"])
    np.testing.assert_array_equal(forward[2], backward[2])


def timed(time: float, guess: float, rounds: list[tuple[float, float, int]], rebuilds: int = 0) -> dict:
    """A results row whose `extra` records a guess of `guess` s and (solve s, verify s, iterations) per round."""
    timing = {"guess": guess, "rounds": [{"solve": s, "verify": v, "iterations": k} for s, v, k in rounds]}
    extra = {"timing": timing, "screening": {"rows_per_point": 50, "rebuilds": rebuilds}}
    return {**row("a", "s1", "verified", time, setup=0.8), "iterations": str(sum(k for _, _, k in rounds) + 7),
            "extra": json.dumps(extra)}


def test_the_time_split_adds_up_to_the_computation_and_takes_medians_over_every_plan():
    rows = [timed(4.0, 1.0, [(1.5, 0.2, 30), (0.5, 0.1, 10)], rebuilds=1), timed(2.0, 0.5, [(1.0, 0.1, 20)]),
            {**row("a", "s1", "no_path", 30.0, setup=1.2), "iterations": "0", "extra": json.dumps({"rungs": []})}]
    (split,) = time_split(rows, ("method", "scene"))
    assert (split["method"], split["scene"], split["runs"]) == ("a", "s1", 3)
    assert split["setup_s"] == 0.8 and split["guess_s"] == 0.75 and split["solves_s"] == 1.5
    assert split["verify_s"] == pytest.approx(0.2) and split["rounds"] == 1.5  # NaN for the plan without a solve
    assert split["rest_s"] == pytest.approx(0.7)  # 4 - 1 - 2 - 0.3 = 0.7, 2 - 0.5 - 1 - 0.1 = 0.4, 30 (no timing)
    assert split["ms_per_iteration"] == pytest.approx(50.0) and split["iterations"] == 27.0
    assert split["rebuilds"] == 0.5
