"""The pinocchio callback backends: `pinocchio` (ABA, computeABADerivatives) and `pinocchio-rnea` (RNEA,
computeRNEADerivatives). Their callbacks (values, analytic Jacobian) against pinocchio, finite differences and
our symbolic SX algorithms; the SX → MX lift of an NLP against the symbolic twin backend."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from ocpkit import load_robot
from ocpkit.dynamics import make_dynamics

ROBOT = load_robot("industrial6")
N = ROBOT.n
RNG = np.random.default_rng(5)
STATES = [(RNG.uniform(ROBOT.q_lower, ROBOT.q_upper), RNG.uniform(-2, 2, N), RNG.uniform(-5, 5, N))
          for _ in range(10)]
COLUMNS = np.stack([np.concatenate(state) for state in STATES], axis=1)  # (3n, K): [q; v; a] per point
TWIN = {"pinocchio": "casadi", "pinocchio-rnea": "casadi-rnea"}
"""Each callback backend and the symbolic backend with the same defect form."""
PINOCCHIO = {"pinocchio": pin.aba, "pinocchio-rnea": pin.rnea}


def _symbolic(name: str, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The twin's SX algorithm (ABA or RNEA) and its AD Jacobian at the columns, in the callback's layout."""
    symbolic = make_dynamics(TWIN[name], ROBOT).symbolic
    algorithm = symbolic.forward_dynamics if name == "pinocchio" else symbolic.inverse_dynamics
    X = ca.SX.sym("X", 3 * N, columns.shape[1])
    y = ca.horzcat(*[algorithm(X[:N, k], X[N:2 * N, k], X[2 * N:, k]) for k in range(X.size2())])
    value, jac = ca.Function("y", [X], [y, ca.jacobian(y, X)])(columns)
    return np.asarray(value), np.asarray(ca.densify(jac))


def _callback(name: str, columns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The callback's value and the CasADi Jacobian of its call on MX symbols."""
    callback = make_dynamics(name, ROBOT).callback(columns.shape[1])
    X = ca.MX.sym("X", 3 * N, columns.shape[1])
    value, jac = ca.Function("y", [X], [callback(X), ca.jacobian(callback(X), X)])(columns)
    return np.asarray(value), np.asarray(ca.densify(jac))


@pytest.mark.parametrize("name", TWIN)
def test_callback_values_match_pinocchio_and_the_symbolic_algorithm(name):
    value, _ = _callback(name, COLUMNS)
    data = ROBOT.model.createData()
    expected = np.stack([PINOCCHIO[name](ROBOT.model, data, *state) for state in STATES], axis=1)
    np.testing.assert_allclose(value, expected, atol=1e-8, rtol=0)
    np.testing.assert_allclose(value, _symbolic(name, COLUMNS)[0], atol=1e-8, rtol=0)


@pytest.mark.parametrize("name", TWIN)
def test_callback_jacobian_matches_symbolic_ad_and_finite_differences(name):
    _, jac = _callback(name, COLUMNS)
    scale = max(1.0, np.abs(jac).max())
    np.testing.assert_allclose(jac, _symbolic(name, COLUMNS)[1], atol=1e-8 * scale, rtol=0)
    callback = make_dynamics(name, ROBOT).callback(COLUMNS.shape[1])
    flat, step = COLUMNS.ravel(order="F"), 1e-6
    fd = np.empty_like(jac)
    for c in range(flat.size):
        e = np.zeros(flat.size)
        e[c] = step
        plus, minus = (np.asarray(callback((flat + s * e).reshape(COLUMNS.shape, order="F"))) for s in (1, -1))
        fd[:, c] = ((plus - minus) / (2 * step)).ravel(order="F")
    np.testing.assert_allclose(jac, fd, atol=1e-6 * scale, rtol=0)
    # block diagonal: a point's value depends on its own state only
    assert callback.jacobian_sparsity.nnz() == COLUMNS.shape[1] * N * 3 * N


@pytest.mark.parametrize("name", TWIN)
@pytest.mark.parametrize("kind", ["numbers", "MX"])
def test_residual_vanishes_exactly_on_consistent_states(name, kind):
    dynamics = make_dynamics(name, ROBOT)
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


def _nlp(dynamics, points: int) -> dict:
    """A small SX NLP with `points` dynamics residuals, lifted by `dynamics`."""
    x, p = ca.SX.sym("x", 4 * N * points), ca.SX.sym("p", 1)
    cols = [x[4 * N * k:4 * N * (k + 1)] for k in range(points)]
    g = ca.vertcat(*[dynamics.residual(c[:N], c[N:2 * N], c[2 * N:3 * N], p * c[3 * N:]) for c in cols])
    f = ca.sumsqr(g) + p * ca.sumsqr(x)
    return dynamics.lift(dict(x=x, p=p, f=f, g=g, lbg=None, ubg=None, shape_key=()))


def _evaluate(fields: dict, x0: np.ndarray) -> list[np.ndarray]:
    """f, g and dg/dx at x0, p = 30."""
    fn = ca.Function("nlp", [fields["x"], fields["p"]],
                     [fields["f"], fields["g"], ca.jacobian(fields["g"], fields["x"])])
    return [np.asarray(ca.densify(v)) for v in fn(x0, 30.0)]


def _x0(points: int) -> np.ndarray:
    return np.concatenate([np.concatenate([COLUMNS[:, k], RNG.uniform(-1, 1, N)]) for k in range(points)])


def _assert_same_nlp(lifted: dict, twin: dict, x0: np.ndarray) -> None:
    for a, b in zip(_evaluate(twin, x0), _evaluate(lifted, x0)):
        np.testing.assert_allclose(b, a, atol=1e-8 * max(1.0, np.abs(a).max()), rtol=0)


@pytest.mark.parametrize("name", TWIN)
def test_lift_turns_an_sx_nlp_with_placeholders_into_the_same_mx_nlp(name):
    """The SX residual records placeholders; `lift` gives an MX NLP whose f, g and Jacobian equal those of the
    same NLP built with the twin's symbolic residual."""
    lifted = _nlp(make_dynamics(name, ROBOT), 2)
    assert isinstance(lifted["x"], ca.MX) and lifted["exact_hessian"] is False
    _assert_same_nlp(lifted, _nlp(make_dynamics(TWIN[name], ROBOT), 2), _x0(2))


@pytest.mark.parametrize("name", TWIN)
def test_one_instance_serves_builds_one_after_the_other(name):
    """`lift` forgets the placeholders it lifted: a second build on the same instance lifts its own only."""
    dynamics, twin = make_dynamics(name, ROBOT), make_dynamics(TWIN[name], ROBOT)
    for points in (2, 3):
        _assert_same_nlp(_nlp(dynamics, points), _nlp(twin, points), _x0(points))
