"""The `pinocchio` dynamics backend: its RNEA callback (values, analytic Jacobian) against pinocchio, finite
differences and `casadi-rnea`; the SX → MX lift of an NLP; and a plan against casadi-rnea."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from ocpkit import load_robot
from ocpkit.dynamics import make_dynamics
from ocpkit.transcription.base import NLP

ROBOT = load_robot("industrial6")
N = ROBOT.n
RNG = np.random.default_rng(5)
STATES = [(RNG.uniform(ROBOT.q_lower, ROBOT.q_upper), RNG.uniform(-2, 2, N), RNG.uniform(-5, 5, N))
          for _ in range(10)]
COLUMNS = np.stack([np.concatenate(state) for state in STATES], axis=1)  # (3n, K)


def _symbolic_rnea(columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """casadi-rnea's RNEA and its AD Jacobian at the columns, in the callback's layout."""
    symbolic = make_dynamics("casadi-rnea", ROBOT).symbolic
    X = ca.SX.sym("X", 3 * N, columns.shape[1])
    tau = ca.horzcat(*[symbolic.inverse_dynamics(X[:N, k], X[N:2 * N, k], X[2 * N:, k]) for k in range(X.size2())])
    value, jac = ca.Function("rnea", [X], [tau, ca.jacobian(tau, X)])(columns)
    return np.asarray(value), np.asarray(ca.densify(jac))


def _callback_rnea(columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The callback's value and the CasADi Jacobian of its call on MX symbols."""
    callback = make_dynamics("pinocchio", ROBOT).callback(columns.shape[1])
    X = ca.MX.sym("X", 3 * N, columns.shape[1])
    value, jac = ca.Function("rnea", [X], [callback(X), ca.jacobian(callback(X), X)])(columns)
    return np.asarray(value), np.asarray(ca.densify(jac))


def test_callback_values_match_pinocchio_and_casadi_rnea():
    value, _ = _callback_rnea(COLUMNS)
    data = ROBOT.model.createData()
    expected = np.stack([pin.rnea(ROBOT.model, data, q, qd, qdd) for q, qd, qdd in STATES], axis=1)
    np.testing.assert_allclose(value, expected, atol=1e-8, rtol=0)
    np.testing.assert_allclose(value, _symbolic_rnea(COLUMNS)[0], atol=1e-8, rtol=0)


def test_callback_jacobian_matches_casadi_rnea_and_finite_differences():
    _, jac = _callback_rnea(COLUMNS)
    symbolic = _symbolic_rnea(COLUMNS)[1]
    np.testing.assert_allclose(jac, symbolic, atol=1e-6, rtol=0)
    callback = make_dynamics("pinocchio", ROBOT).callback(COLUMNS.shape[1])
    flat, step = COLUMNS.ravel(order="F"), 1e-6
    fd = np.empty_like(jac)
    for c in range(flat.size):
        e = np.zeros(flat.size)
        e[c] = step
        plus, minus = (np.asarray(callback((flat + s * e).reshape(COLUMNS.shape, order="F"))) for s in (1, -1))
        fd[:, c] = ((plus - minus) / (2 * step)).ravel(order="F")
    np.testing.assert_allclose(jac, fd, atol=1e-6 * max(1.0, np.abs(jac).max()), rtol=0)
    # block diagonal: a point's torque depends on its own state only
    assert callback.jacobian_sparsity.nnz() == COLUMNS.shape[1] * N * 3 * N


@pytest.mark.parametrize("kind", ["numbers", "MX"])
def test_residual_vanishes_exactly_on_consistent_states(kind):
    dynamics = make_dynamics("pinocchio", ROBOT)
    data = ROBOT.model.createData()
    for q, qd, qdd in STATES[:3]:
        rigid = pin.rnea(ROBOT.model, data, q, qd, qdd).copy()
        for tau, vanishes in ((rigid, True), (rigid + 1.0, False)):
            if kind == "numbers":
                r = np.asarray(dynamics.residual(q, qd, qdd, tau)).ravel()
            else:
                s = [ca.MX.sym(f"a{k}", N) for k in range(4)]
                r = np.asarray(ca.Function("r", s, [dynamics.residual(*s)])(q, qd, qdd, tau)).ravel()
            assert (np.abs(r).max() < 1e-8) == vanishes


def test_lift_turns_an_sx_nlp_with_placeholders_into_the_same_mx_nlp():
    """The SX residual records placeholders; `lift` gives an MX NLP whose f, g and Jacobian equal those of the
    same NLP built with casadi-rnea's symbolic residual."""
    x, p = ca.SX.sym("x", 4 * N * 2), ca.SX.sym("p", 1)
    fields = {}
    for name in ("casadi-rnea", "pinocchio"):
        dynamics = make_dynamics(name, ROBOT)
        cols = [x[4 * N * k:4 * N * (k + 1)] for k in range(2)]
        g = ca.vertcat(*[dynamics.residual(c[:N], c[N:2 * N], c[2 * N:3 * N], p * c[3 * N:]) for c in cols])
        f = ca.sumsqr(g) + p * ca.sumsqr(x)
        fields[name] = dict(x=x, p=p, f=f, g=g, lbg=None, ubg=None, shape_key=())
        if name == "pinocchio":
            fields[name] = dynamics.lift(fields[name])
            assert isinstance(fields[name]["x"], ca.MX) and fields[name]["exact_hessian"] is False
    x0 = np.concatenate([COLUMNS[:, 0], RNG.uniform(-1, 1, N), COLUMNS[:, 1], RNG.uniform(-1, 1, N)])
    out = {}
    for name, fl in fields.items():
        fn = ca.Function("nlp", [fl["x"], fl["p"]], [fl["f"], fl["g"], ca.jacobian(fl["g"], fl["x"])])
        out[name] = [np.asarray(ca.densify(v)) for v in fn(x0, 30.0)]
    for a, b in zip(out["casadi-rnea"], out["pinocchio"]):
        np.testing.assert_allclose(b, a, atol=1e-8 * max(1.0, np.abs(a).max()), rtol=0)


_HOOKED = "exact_hessian" in getattr(NLP, "__dataclass_fields__", {})


@pytest.mark.slow
@pytest.mark.skipif(not _HOOKED, reason="needs the NLP.exact_hessian / Assembly.nlp_fields lift hook")
def test_plan_case2_matches_casadi_rnea():
    import ocpkit

    problem = ocpkit.load_scenario("scenarios/paper/case2.yaml")
    reference = ocpkit.plan(problem, knots=8, dynamics="casadi-rnea")
    plan = ocpkit.plan(problem, knots=8, dynamics="pinocchio")
    assert reference.ok and plan.ok, (reference.status, plan.status)
    assert abs(plan.trajectory.tf - reference.trajectory.tf) <= 0.01 * reference.trajectory.tf
