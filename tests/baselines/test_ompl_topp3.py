"""ompl-topp3: the path spline in NumPy and CasADi agree and have the derivatives they claim; the path-timing
OCP's robot quantities (q̇, q̈, q⃛, τ, τ̇ from s, ṡ, s̈, s⃛) match finite differences and pinocchio; its jerk cost
matches an independent quadrature; a planned motion stays on the path to 1e-9 and verifies."""

from __future__ import annotations

import json
import subprocess
import sys

import casadi as ca
import numpy as np
import pytest
from helpers import REPO, evaluate
from numpy.polynomial import Polynomial

import ocpkit
from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.formats.record import trajectory_header
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.path_spline import DEGREE, PathSpline, symbolic
from ocpkit.robots import rigid_torque
from ocpkit.transcription import TRANSCRIPTIONS
from ocpkit.transcription.ocp import Node, PathTimingOCP

CASE1 = ocpkit.load_scenario(REPO / "scenarios/paper/case1.yaml")
ROBOT = CASE1.robot
DATA = REPO / "ocpkit/robots/data/industrial6"
SMOOTHSTEP = Polynomial([0, 0, 0, 10, -15, 6])  # s(τ) from rest at 0 to rest at 1, τ = t / T


@pytest.fixture(scope="module")
def spline():
    """A quintic through 5 seeded waypoints between case 1's start and goal."""
    rng = np.random.default_rng(3)
    line = np.linspace(0, 1, 5)[:, None]
    waypoints = CASE1.start + line * (CASE1.goal - CASE1.start) + 0.2 * rng.standard_normal((5, ROBOT.n)) * \
        (line * (1 - line) > 0)
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))])
    return PathSpline.fit(chord, waypoints), waypoints, chord


def symbolic_path(spline):
    s = ca.SX.sym("s")
    breaks, coefficients = (ca.DM(v) for v in spline.parameters())
    return ca.Function("p", [s], list(symbolic(s, breaks, coefficients)))


def test_spline_interpolates_the_waypoints_is_natural_and_agrees_with_its_casadi_form(spline):
    path, waypoints, chord = spline
    np.testing.assert_allclose(path(chord), waypoints, atol=1e-12)
    ends = path.taylor(np.array([0.0, 1.0 - 1e-15]))  # the last piece's Taylor coefficients near s = 1
    assert np.abs(ends[0, 3:5]).max() < 1e-9  # p‴ = p⁗ = 0 at s = 0
    last = path.values(np.array([1.0]))[3]
    assert np.abs(last).max() < 1e-6 * np.abs(path.values(np.linspace(0, 1, 50))[3]).max()  # p‴ = 0 at s = 1
    function, s = symbolic_path(path), np.random.default_rng(0).uniform(0, 1, 40)
    numeric = path.values(s)
    for k, x in enumerate(s):
        for derivative, value in zip(numeric, function(x)):
            np.testing.assert_allclose(np.asarray(value).ravel(), derivative[k], rtol=1e-12, atol=1e-12)


def test_spline_derivatives_match_finite_differences_and_p3_is_continuous(spline):
    path, h = spline[0], 1e-5
    s = np.linspace(0.05, 0.95, 31)
    lower, upper = path.values(s - h), path.values(s + h)
    middle = path.values(s)
    for d in range(3):
        np.testing.assert_allclose((upper[d] - lower[d]) / (2 * h), middle[d + 1],
                                   atol=1e-4 * np.abs(middle[d + 1]).max())
    inner = path.breaks[1:-1]
    jumps = path.values(inner + 1e-12)[3] - path.values(inner - 1e-12)[3]
    assert np.abs(jumps).max() < 1e-6 * np.abs(path.values(s)[3]).max()  # C⁴ quintic: p‴ has no jump


def test_split_keeps_the_path(spline):
    path = spline[0]
    finer = path.split(path.intervals + 5)
    assert finer.intervals == path.intervals + 5
    s = np.linspace(0, 1, 301)
    for a, b in zip(path.values(s), finer.values(s)):
        np.testing.assert_allclose(a, b, atol=1e-10 * max(np.abs(a).max(), 1))
    assert finer.taylor(s).shape == (301, DEGREE + 1, ROBOT.n)




def test_two_waypoints_give_the_straight_line():
    """OMPL's simplified path is two waypoints when the straight line is free (MBM panda table_pick 1): the
    natural quintic through them alone is not unique; the fit is the line."""
    a, b = np.array([0.0, -0.5, 1.0]), np.array([1.2, 0.3, -0.4])
    length = np.linalg.norm(b - a)
    c = np.linspace(0.0, length, 9)
    path = PathSpline.fit(np.array([0.0, length]), np.stack([a, b]))
    assert path(c) == pytest.approx(a + np.outer(c / length, b - a), abs=1e-12)


def test_path_timing_quantities_match_finite_differences_and_pinocchio(spline):
    """Along s(t) = smoothstep(t / T): q̇, q̈, q⃛ of the OCP against finite differences of q(t) = p(s(t)), and τ,
    dτ/dt against pinocchio's rnea + friction and its finite difference."""
    path, T, h = spline[0], 2.0, 1e-4
    ocp = PathTimingOCP(ROBOT, path)
    symbols = {name: ca.SX.sym(name, *shape) for name, shape in ocp.parameter_shapes().items()}
    ocp.use_parameters(symbols)
    dynamics = make_dynamics("casadi-rnea", ROBOT)
    x, dt_ds, slope = ca.SX.sym("x", 3), ca.SX.sym("dt_ds"), ca.SX.sym("slope")
    node = Node(x[:2], x[2:])
    q, qd, qdd = ocp.robot_state(node)
    tau, dtau_ds = ocp.torque_function(dynamics)(node, slope, dt_ds)
    jerk = ocp.jerk_s(node, slope, dt_ds) / dt_ds
    with_symbols = ca.Function("f", [x, slope, dt_ds, *symbols.values()], [q, qd, qdd, jerk, tau, dtau_ds / dt_ds])
    function = lambda *args: with_symbols(*args, *path.parameters())  # noqa: E731
    s = [SMOOTHSTEP.deriv(k) for k in range(4)]
    q_of = lambda t: path.values(np.atleast_1d(s[0](t / T)))[0][0]  # noqa: E731
    tau_of = lambda t: np.asarray(function([s[k](t / T) / T ** k for k in range(3)], 0.0, 1.0)[4]).ravel()  # noqa: E731
    for t in (0.3, 0.77, 1.1, 1.6):
        values = [np.asarray(v).ravel() for v in function([s[k](t / T) / T ** k for k in range(3)],
                                                          s[3](t / T) / T ** 3 * 0.01, 0.01)]
        fd = [(q_of(t + h) - q_of(t - h)) / (2 * h), (q_of(t + h) - 2 * q_of(t) + q_of(t - h)) / h ** 2,
              (q_of(t + 2 * h) - 2 * q_of(t + h) + 2 * q_of(t - h) - q_of(t - 2 * h)) / (2 * h ** 3)]
        np.testing.assert_allclose(values[0], q_of(t), atol=1e-12)
        for value, expected, tolerance in zip(values[1:4], fd, (1e-6, 1e-4, 1e-2)):
            np.testing.assert_allclose(value, expected, atol=tolerance * max(np.abs(expected).max(), 1.0))
        qd, qdd = values[1][None], values[2][None]
        needed = rigid_torque(ROBOT, values[0][None], qd, qdd)[0] + ROBOT.friction(qd)[0]
        np.testing.assert_allclose(values[4], needed, rtol=1e-9, atol=1e-9)
        rate = (tau_of(t + h) - tau_of(t - h)) / (2 * h)
        np.testing.assert_allclose(values[5], rate, atol=1e-4 * max(np.abs(rate).max(), 1.0))


def chain_motion(T):
    """s(t) = smoothstep(t / T) as a chain trajectory (s, ṡ, s̈ in q, qd, qdd)."""
    s = [SMOOTHSTEP.deriv(k) for k in range(3)]

    def at(t):
        t = np.asarray(t, dtype=float)
        zeros = np.zeros((len(t), 1))
        return Samples(t, *(s[k](t / T)[:, None] / T ** k for k in range(3)), zeros, zeros)

    return Trajectory(at(np.array([0.0, T])), at)


@pytest.mark.parametrize("transcription, knots", [("chebyshev", 60), ("hermite-simpson", 40), ("trapezoidal", 80)])
def test_path_timing_cost_is_tf_plus_the_jerk_integral(spline, transcription, knots):
    """The NLP's objective at s(t) = smoothstep(t / T) against t_f + μ ∫ q⃛ᵀ Q q⃛ dt by dense Simpson quadrature
    of q⃛ = p′s⃛ + 3p″ṡs̈ + p‴ṡ³."""
    path, T = spline[0], 2.0
    ocp = PathTimingOCP(ROBOT, path)
    disc = TRANSCRIPTIONS.get(transcription)(knots=knots).build(
        CASE1, make_dynamics("casadi-rnea", ROBOT), make_constraints(CASE1, ("state-limits", "torque", "torque-rate")),
        ocp)
    value, _ = evaluate(disc, disc.encode(chain_motion(T)), CASE1)
    t = np.linspace(0, T, 4001)
    s = [SMOOTHSTEP.deriv(k)(t / T) / T ** k for k in range(4)]
    _, dp, ddp, dddp = path.values(s[0])
    jerk = dp * s[3][:, None] + 3 * ddp * (s[1] * s[2])[:, None] + dddp * s[1][:, None] ** 3
    integrand = (jerk ** 2) @ CASE1.jerk_weights
    simpson = (t[1] - t[0]) / 3 * (integrand[0] + 4 * integrand[1:-1:2].sum() + 2 * integrand[2:-1:2].sum()
                                   + integrand[-1])
    assert value == pytest.approx(T + CASE1.mu * simpson, rel=1e-3)  # the path is C⁴ only: slow convergence


def test_samples_torque_rate_is_the_derivative_of_the_torque(spline):
    """The decoded samples' τ̇ (exact, from pinocchio's RNEA derivatives) against finite differences of τ."""
    path, T = spline[0], 2.0
    ocp = PathTimingOCP(ROBOT, path)
    disc = TRANSCRIPTIONS.get("chebyshev")(knots=16).build(
        CASE1, make_dynamics("casadi-rnea", ROBOT), make_constraints(CASE1, ("state-limits", "torque", "torque-rate")),
        ocp)
    motion = disc.decode(disc.encode(chain_motion(T)))
    t, h = np.linspace(0.1, 1.9, 7), 1e-6
    rate = (motion.interpolant(t + h).tau - motion.interpolant(t - h).tau) / (2 * h)
    np.testing.assert_allclose(motion.interpolant(t).taud, rate, atol=1e-4 * np.abs(rate).max())


@pytest.fixture(scope="module")
def case4_plan():
    return ocpkit.plan(ocpkit.load_scenario(REPO / "scenarios/paper/case4.yaml"), planner="ompl-topp3")


def test_the_motion_stays_on_the_path(case4_plan):
    """q(t) of the samples equals p(s(t)) to 1e-9, s(t) the barycentric interpolant of the solution's s knots."""
    trajectory = case4_plan.trajectory
    interpolant = trajectory.interpolant
    path = interpolant.ocp.path
    t = np.concatenate([trajectory.knots.t, np.linspace(0, trajectory.tf, 997)])
    L, _ = interpolant.grid.matrices(2.0 * t / trajectory.tf - 1.0)
    s = L @ interpolant.columns[0]
    np.testing.assert_allclose(interpolant(t).q, path.values(s)[0], atol=1e-9)
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case4.yaml")
    np.testing.assert_allclose(path.values(np.array([0.0, 1.0]))[0], [problem.start, problem.goal], atol=1e-9)


def test_a_paper_case_verifies_and_its_json_passes_the_outside_check(case4_plan, tmp_path):
    assert case4_plan.status == "verified", case4_plan.verification.summary()
    assert case4_plan.method["planner"] == "ompl-topp3"
    outside_check(case4_plan, REPO / "scenarios/paper/case4.yaml", tmp_path)


def outside_check(plan, scenario, tmp_path):
    """tests/outside_check.py (torque rate included) passes on the plan's trajectory JSON."""
    path = tmp_path / "t.json"
    ocpkit.write_json(path, plan.trajectory, trajectory_header(ocpkit.load_scenario(scenario), plan))
    assert json.loads(path.read_text())["status"] == "verified"
    check = subprocess.run([sys.executable, str(REPO / "tests/outside_check.py"), str(path), str(DATA / "spec.yaml"),
                            str(DATA / "robot.urdf"), str(scenario)], capture_output=True, text=True)
    assert check.returncode == 0, check.stdout + check.stderr
    assert "torque_rate" in check.stdout


@pytest.mark.slow
@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_every_paper_case_verifies_and_passes_the_outside_check(case, tmp_path):
    scenario = REPO / f"scenarios/paper/{case}.yaml"
    plan = ocpkit.plan(ocpkit.load_scenario(scenario), planner="ompl-topp3")
    assert plan.status == "verified", plan.verification.summary()
    outside_check(plan, scenario, tmp_path)


def test_a_path_that_leaves_the_joint_limits_is_repaired():
    """Random problem 19 (seed 5): the natural quintic through its OMPL waypoints leaves a joint's position limit,
    which no timing can fix; the smoothing repairs it (a waypoint inserted) and the plan verifies."""
    from ocpkit.bench.random import random_problems

    problem = next(p for p in random_problems(5, 30) if p.name == "random19")
    plan = ocpkit.plan(problem, planner="ompl-topp3")
    assert plan.stats.path.repair_rounds >= 1 and plan.stats.figures()["repair_rounds"] >= 1
    assert plan.status == "verified", plan.verification.summary()


def test_without_a_toppra_profile_the_timing_starts_from_constant_speed(monkeypatch):
    import ocpkit.baselines.ompl_topp3 as topp3

    monkeypatch.setattr(topp3, "time_optimal", lambda *args: None)
    plan = ocpkit.plan(ocpkit.load_scenario(REPO / "scenarios/paper/case4.yaml"), planner="ompl-topp3")
    assert "from s at constant speed" in plan.stats.solver_message
    assert plan.status == "verified", plan.verification.summary()


def test_an_unknown_ompl_planner_is_named_before_planning():
    with pytest.raises(ocpkit.errors.RegistryError, match="unknown OMPL planner 'rrt-fast'"):
        ocpkit.plan(CASE1, planner="ompl-topp3", planner_name="rrt-fast")


def test_the_goal_at_the_start_holds_still():
    import dataclasses

    plan = ocpkit.plan(dataclasses.replace(CASE1, goal=CASE1.start), planner="ompl-topp3")
    assert plan.status == "verified" and plan.trajectory.tf == CASE1.time.min


@pytest.mark.slow
@pytest.mark.parametrize("case", ["case1", "case2"])
def test_retiming_the_simultaneous_plans_own_path_reproduces_its_motion_time(case):
    """Two OCP families, one answer: the simultaneous plan's path (a natural quintic through 25 of its samples),
    timed by the path-timing OCP with the same limits and cost, takes the simultaneous plan's t_f within 1 %."""
    from ocpkit.baselines.ompl_topp3 import time_path
    from ocpkit.planner.ladder import SINGLE_SHOT

    problem = ocpkit.load_scenario(REPO / f"scenarios/paper/{case}.yaml")
    simultaneous = ocpkit.plan(problem, fallbacks=SINGLE_SHOT)
    q = simultaneous.trajectory.interpolant(np.linspace(0, simultaneous.trajectory.tf, 25)).q
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))])
    timed = time_path(problem, PathSpline.fit(chord, q)).refined
    assert timed.verification.ok, timed.verification.summary()
    assert timed.trajectory.tf == pytest.approx(simultaneous.trajectory.tf, rel=0.01)


def test_the_timings_rounds_verify_the_limits_first_as_no_round_can_move_the_path(spline, monkeypatch):
    """The timing OCP has no contact rows: its refinement rounds check contact only on a motion within the limits
    (ocpkit.planner.refinement), and the motion it returns is verified in full."""
    import ocpkit.baselines.ompl_topp3 as topp3

    asked = []
    original = topp3.solve_refined
    monkeypatch.setattr(topp3, "solve_refined",
                        lambda *args, **kwargs: asked.append(kwargs) or original(*args, **kwargs))
    timed = topp3.time_path(CASE1, spline[0]).refined
    assert [kwargs.get("limits_first") for kwargs in asked] == [True]
    assert timed.verification.contact_checked and "obstacle" in {c.name for c in timed.verification.checks}
