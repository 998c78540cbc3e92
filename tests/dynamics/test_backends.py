"""Dynamics backends (friction included) and symbolic sphere kinematics against pinocchio."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest

from ocpkit import load_robot
from ocpkit.dynamics import DYNAMICS, make_dynamics
from ocpkit.errors import OptionError, RegistryError
from ocpkit.geometry.clearances import sphere_centers

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


@pytest.mark.parametrize("name", DYNAMICS.names())
def test_symbolic_friction_matches_the_numeric_law_and_its_slope(name):
    dynamics = make_dynamics(name, ROBOT)
    v = ca.SX.sym("qd", 6)
    jacobian = ca.Function("j", [v], [ca.jacobian(dynamics.friction(v), v)])
    for qd in [state[1] for state in STATES] + [np.array([0.0, 1e-3, -1e-3, 0.02, -30.0, 30.0])]:
        np.testing.assert_allclose(np.asarray(ca.densify(jacobian(qd))), np.diag(ROBOT.friction_slope(qd)),
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(numeric(dynamics.friction, qd), ROBOT.friction(qd), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", ["casadi", "casadi-rnea"])
def test_cse_option_reaches_the_backend_and_keeps_values(name):
    plain, cse = make_dynamics(name, ROBOT), make_dynamics(name, ROBOT, cse=True)
    assert (plain.cse, cse.cse) == (False, True) and plain.key != cse.key
    assert cse.key == (name, ROBOT.key, (("cse", True),)) and hash(cse.key)
    for q, qd, qdd in STATES:
        tau = RNG.normal(size=6)
        np.testing.assert_allclose(numeric(cse.residual, q, qd, qdd, tau), numeric(plain.residual, q, qd, qdd, tau),
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(numeric(cse.sphere_centers, q), numeric(plain.sphere_centers, q), atol=1e-12)


@pytest.mark.parametrize("name, option", [("casadi", "fast"), ("pinocchio", "cse"), ("pinocchio-rnea", "cse")])
def test_unknown_option_is_named(name, option):
    with pytest.raises(OptionError, match=f"dynamics backend '{name}' has no option '{option}'"):
        make_dynamics(name, ROBOT, **{option: True})


def test_bad_option_value_is_named():
    with pytest.raises(OptionError, match="option 'cse' must be true or false"):
        make_dynamics("casadi", ROBOT, cse="yes")


def test_an_instance_is_reused_for_its_own_robot_only(tmp_path):
    dynamics = make_dynamics("casadi-rnea", ROBOT, cse=True)
    assert make_dynamics(dynamics, load_robot("industrial6")) is dynamics
    with pytest.raises(OptionError, match="cannot be applied to the existing"):
        make_dynamics(dynamics, ROBOT, cse=False)
    other = _edited_robot(tmp_path)
    with pytest.raises(OptionError, match="made for another robot"):
        make_dynamics(dynamics, other)


@pytest.mark.parametrize("name", DYNAMICS.names())
def test_key_follows_backend_options_and_robot_content(name, tmp_path):
    key = make_dynamics(name, ROBOT).key
    assert key == make_dynamics(name, ROBOT).key and key[:2] == (name, ROBOT.key)
    assert make_dynamics(name, _edited_robot(tmp_path)).key != key


def _edited_robot(tmp_path):
    """industrial6 with one torque limit changed: another robot key."""
    import yaml

    from ocpkit.robots.robot import DATA_DIR
    spec = yaml.safe_load((DATA_DIR / "industrial6/spec.yaml").read_text())
    spec["limits"]["torque"][0] *= 2
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    return load_robot({"urdf": str(DATA_DIR / "industrial6/robot.urdf"), "spec": str(tmp_path / "spec.yaml")})
