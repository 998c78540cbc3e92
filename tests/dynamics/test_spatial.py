"""ocpkit.dynamics.spatial.SymbolicModel against pinocchio's aba, rnea and forwardKinematics."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest
from helpers import REPO, example_robot_urdf

from ocpkit.dynamics.spatial import SymbolicModel

TOL = 1e-8
N_STATES = 20
MODELS = ["ur5", "panda", "industrial6", "tree"]
INDUSTRIAL6 = REPO / "ocpkit/robots/data/industrial6/robot.urdf"


def random_tree_model(rng: np.random.Generator) -> pin.Model:
    """Branching model with every supported joint type, oblique and negative axes."""

    def unit() -> np.ndarray:
        axis = rng.normal(size=3)
        return axis / np.linalg.norm(axis)

    joints = [
        pin.JointModelRX(),
        pin.JointModelRY(),
        pin.JointModelRZ(),
        pin.JointModelRevoluteUnaligned(unit()),
        pin.JointModelRevoluteUnaligned(np.array([0.0, 0.0, -1.0])),
        pin.JointModelPX(),
        pin.JointModelPY(),
        pin.JointModelPZ(),
        pin.JointModelPrismaticUnaligned(unit()),
    ]
    parents = [0, 1, 2, 2, 4, 1, 6, 3, 0]
    model = pin.Model()
    for k, (joint, parent) in enumerate(zip(joints, parents)):
        rotation = pin.rpy.rpyToMatrix(*rng.uniform(-np.pi, np.pi, 3))
        placement = pin.SE3(rotation, rng.uniform(-0.5, 0.5, 3))
        index = model.addJoint(parent, joint, placement, f"joint{k}")
        A = rng.normal(size=(3, 3))
        rotational = A @ A.T + 0.1 * np.eye(3)
        inertia = pin.Inertia(rng.uniform(0.5, 3.0), rng.uniform(-0.2, 0.2, 3), rotational)
        model.appendBodyToJoint(index, inertia, pin.SE3.Identity())
    return model


def load_model(name: str) -> pin.Model:
    """Model by name: a random tree, industrial6 from this repo or an example-robot-data URDF."""
    if name == "tree":
        return random_tree_model(np.random.default_rng(1))
    if name == "industrial6":
        return pin.buildModelFromUrdf(str(INDUSTRIAL6))
    return pin.buildModelFromUrdf(str(example_robot_urdf(name)))


@pytest.fixture(
    scope="module",
    params=[(name, armature) for name in MODELS for armature in (False, True)],
    ids=lambda p: p[0] + ("-armature" if p[1] else ""),
)
def case(request) -> tuple[pin.Model, SymbolicModel]:
    """A pinocchio model (random positive armature if requested) and its SymbolicModel."""
    name, armature = request.param
    model = load_model(name)
    if armature:
        model.armature = np.random.default_rng(2).uniform(0.05, 2.0, model.nv)
    return model, SymbolicModel(model)


def random_states(model: pin.Model, seed: int = 0):
    """N_STATES tuples (q, qd, x): q within limits and [-pi, pi], qd and x ~ N(0, 2^2)."""
    rng = np.random.default_rng(seed)
    lower = np.maximum(model.lowerPositionLimit, -np.pi)
    upper = np.minimum(model.upperPositionLimit, np.pi)
    for _ in range(N_STATES):
        yield rng.uniform(lower, upper), *rng.normal(0.0, 2.0, (2, model.nv))


def assert_close(got: ca.DM, expected: np.ndarray) -> None:
    """got equals expected within TOL; a 1-D expected must come back as a (n,1) column."""
    expected = expected[:, None] if expected.ndim == 1 else expected
    assert got.shape == expected.shape
    np.testing.assert_allclose(got.full(), expected, rtol=0, atol=TOL)


def test_forward_dynamics_matches_aba(case):
    model, symbolic = case
    data = model.createData()
    for q, qd, tau in random_states(model):
        assert_close(symbolic.forward_dynamics(q, qd, tau), pin.aba(model, data, q, qd, tau))


def test_inverse_dynamics_matches_rnea(case):
    model, symbolic = case
    data = model.createData()
    for q, qd, qdd in random_states(model):
        assert_close(symbolic.inverse_dynamics(q, qd, qdd), pin.rnea(model, data, q, qd, qdd))


def test_joint_placements_match_forward_kinematics(case):
    model, symbolic = case
    data = model.createData()
    for q, _, _ in random_states(model):
        pin.forwardKinematics(model, data, q)
        placements = symbolic.joint_placements(q)
        assert len(placements) == model.njoints
        for (rotation, position), expected in zip(placements, data.oMi):
            assert_close(rotation, expected.rotation)
            assert_close(position, expected.translation)


@pytest.mark.parametrize("symbol", [ca.SX.sym, ca.MX.sym], ids=["SX", "MX"])
def test_symbolic_arguments(symbol):
    model = load_model("panda")
    symbolic = SymbolicModel(model)
    q, qd, x = (symbol(name, model.nv) for name in ("q", "qd", "x"))
    qdd, tau = symbolic.forward_dynamics(q, qd, x), symbolic.inverse_dynamics(q, qd, x)
    rotation, position = symbolic.joint_placements(q)[-1]
    assert qdd.shape == tau.shape == (model.nv, 1)
    assert rotation.shape == (3, 3) and position.shape == (3, 1)
    evaluate = ca.Function("evaluate", [q, qd, x], [qdd, tau, rotation, position])
    values = next(random_states(model))
    expected = [
        symbolic.forward_dynamics(*values),
        symbolic.inverse_dynamics(*values),
        *symbolic.joint_placements(values[0])[-1],
    ]
    for got, want in zip(evaluate(*values), expected):
        assert_close(got, want.full())


@pytest.mark.parametrize(
    "joint",
    [pin.JointModelFreeFlyer(), pin.JointModelSpherical(), pin.JointModelRUBZ()],
    ids=lambda joint: joint.shortname(),
)
def test_unsupported_joint_raises_with_its_name(joint):
    model = pin.Model()
    hinge = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "hinge")
    model.addJoint(hinge, joint, pin.SE3.Identity(), "odd_joint")
    with pytest.raises(ValueError, match="odd_joint"):
        SymbolicModel(model)
