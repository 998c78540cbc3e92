"""Dynamics backends (friction included) and symbolic sphere kinematics against pinocchio."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from ocpkit import load_robot
from ocpkit.dynamics import DYNAMICS, make_dynamics
from ocpkit.errors import RegistryError
from ocpkit.geometry import sphere_centers

ROBOT = load_robot("industrial6")
RNG = np.random.default_rng(3)
STATES = [(RNG.uniform(ROBOT.q_lower, ROBOT.q_upper), RNG.uniform(-2, 2, 6), RNG.uniform(-5, 5, 6)) for _ in range(10)]


def numeric(expr_fn, *args) -> np.ndarray:
    symbols = [ca.SX.sym(f"a{k}", 6) for k in range(len(args))]
    return np.asarray(ca.Function("f", symbols, [expr_fn(*symbols)])(*args)).squeeze()


@pytest.mark.parametrize("name", DYNAMICS.names())
def test_inverse_and_forward_include_friction(name):
    dynamics = make_dynamics(name, ROBOT)
    data = ROBOT.model.createData()
    for q, qd, qdd in STATES:
        tau = pin.rnea(ROBOT.model, data, q, qd, qdd) + ROBOT.friction(qd)
        np.testing.assert_allclose(numeric(dynamics.inverse, q, qd, qdd), tau, atol=1e-8)
        np.testing.assert_allclose(numeric(dynamics.forward, q, qd, tau), qdd, atol=1e-8)


@pytest.mark.parametrize("name", ["casadi", "casadi-rnea"])  # the callback backends: test_dynamics_pinocchio
def test_residual_vanishes_exactly_on_consistent_states(name):
    dynamics = make_dynamics(name, ROBOT)
    data = ROBOT.model.createData()
    for q, qd, qdd in STATES:
        rigid = pin.rnea(ROBOT.model, data, q, qd, qdd).copy()
        assert np.abs(numeric(dynamics.residual, q, qd, qdd, rigid)).max() < 1e-8
        assert np.abs(numeric(dynamics.residual, q, qd, qdd, rigid + 1.0)).max() > 1e-4


def test_sphere_centers_match_pinocchio_frame_placements():
    dynamics = make_dynamics("casadi", ROBOT)
    model, data = ROBOT.model, ROBOT.model.createData()
    spec_centres = _spec_centres()
    for q, _, _ in STATES:
        pin.framesForwardKinematics(model, data, q)
        expected = np.array([data.oMf[model.getFrameId(link)].act(c) for link, c in spec_centres])
        q_sym = ca.SX.sym("q", 6)
        symbolic = np.asarray(ca.Function("c", [q_sym], [dynamics.sphere_centers(q_sym)])(q))
        np.testing.assert_allclose(symbolic, expected, atol=1e-10)
        np.testing.assert_allclose(sphere_centers(ROBOT, q), expected, atol=1e-10)


def _spec_centres():
    import yaml

    from ocpkit.robots.robot import DATA_DIR
    spec = yaml.safe_load((DATA_DIR / "industrial6/spec.yaml").read_text())
    return [(s["link"], np.array(s["center"], dtype=float)) for s in spec["spheres"]]


def test_unknown_backend_lists_known_ones():
    with pytest.raises(RegistryError, match="unknown dynamics backend 'fast'; known: casadi, casadi-rnea"):
        DYNAMICS.get("fast")
