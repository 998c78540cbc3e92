"""The collision rows' compiled derivatives against CasADi's automatic ones, through the mapped Functions IPOPT's
derivatives call (every term kind, soft-minimum groups, workspace faces, binding margin caps, prismatic and
unaligned joints)."""

from __future__ import annotations

import copy
import dataclasses
import gc

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest
from helpers import REPO, unaligned_chain

import ocpkit
from ocpkit.constraints import Context, PointValues
from ocpkit.constraints.collision import SphereCollision
from ocpkit.nlp import Refinement
from ocpkit.planner import screening
from ocpkit.planner.build_cache import shape
from ocpkit.solvers import collision_derivatives
from ocpkit.solvers.collision_derivatives import CollisionDerivatives, derivatives_by_hand
from ocpkit.solvers.pointwise import pointwise_derivatives
from ocpkit.dynamics import make_dynamics
from ocpkit.geometry.quaternion import quaternion_matrix
from ocpkit.geometry.scene import Boxes, Cylinders, Scene

PAPER = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
TILTED = quaternion_matrix([0.2, -0.3, 0.4, 0.8])
PRIMITIVES = dataclasses.replace(PAPER, scene=dataclasses.replace(
    PAPER.scene, boxes=Boxes(np.array([[1.0, 0.2, 0.9], [0.0, -0.9, 0.5]]),
                             np.array([[0.3, 0.6, 0.2], [1.0, 0.2, 1.0]]), np.stack([TILTED, np.eye(3)])),
    cylinders=Cylinders(np.array([[0.9, -0.4, 1.2]]), np.array([0.15]), np.array([0.8]), TILTED[None])))
MBM = ocpkit.load_scenario(REPO / "scenarios/mbm/panda/box/0001.yaml")


def grouped(constraint: SphereCollision) -> SphereCollision:
    """`constraint` with its terms grouped into soft minima, as a robot with many terms has them."""
    made = copy.copy(constraint)
    made.grouped = True
    return made


def prismatic_problem() -> ocpkit.Problem:
    """Spheres on a chain of prismatic, unaligned and revolute joints among a sphere, a box and a cylinder."""
    rng = np.random.default_rng(6)
    model, (a, b, c, d) = unaligned_chain()
    joints = np.array([0, a, a, b, c, c, d, d])
    robot = dataclasses.replace(PAPER.robot, model=model, sphere_joint=joints,
                                sphere_offset=rng.normal(0, 0.3, (8, 3)), sphere_radius=rng.uniform(0.05, 0.2, 8),
                                self_collision=np.array([[1, 4], [5, 2], [6, 1], [7, 3]]))
    scene = Scene(np.array([[-0.5, 0.2, 0.9]]), np.array([0.3]),
                  boxes=Boxes(np.array([[0.4, 0.5, 0.6]]), np.array([[0.3, 0.8, 0.2]]),
                              pin.rpy.rpyToMatrix(0.4, 0.1, -0.7)[None]),
                  cylinders=Cylinders(np.array([[0.2, -0.4, 0.3]]), np.array([0.2]), np.array([0.5]), TILTED[None]))
    return dataclasses.replace(PAPER, robot=robot, scene=scene, start=np.zeros(4), goal=np.full(4, 0.3))


CASES = {
    "paper (sphere obstacle, workspace)": (PAPER, lambda c: c),
    "paper grouped": (PAPER, grouped),
    "boxes and a tilted cylinder": (PRIMITIVES, lambda c: c),
    "boxes and a tilted cylinder, grouped": (PRIMITIVES, grouped),
    "mbm panda box (grouped)": (MBM, lambda c: c),
    "prismatic and unaligned joints, grouped": (prismatic_problem(), grouped),
}


@pytest.mark.parametrize("case", CASES, ids=CASES.keys())
def test_compiled_derivatives_equal_casadis_automatic_ones(case):
    problem, adapt = CASES[case]
    constraint = adapt(SphereCollision(problem))
    robot, n = problem.robot, problem.robot.model.nq
    point = PointValues(*(ca.SX.sym(k, n) for k in ("q", "qd", "qdd", "tau", "dtau_ds")), ca.SX.sym("dt_ds"))
    shapes = constraint.parameter_shapes()
    symbols = {name: ca.SX.sym(name, *shape) for name, shape in shapes.items()}
    margin, scale = ca.SX.sym("margin"), ca.SX.sym("limit_scale")
    rows = constraint.evaluate(point, Context(make_dynamics("casadi", robot), margin, scale, symbols)).g
    inputs = [*dataclasses.astuple(point), margin, scale, *symbols.values()]
    function = ca.Function("point_rows", inputs, [rows])
    lam = ca.SX.sym("lam", rows.numel())
    reference = ca.Function("reference", [*inputs, lam], [ca.jacobian(rows, point.q),
                                                          ca.hessian(ca.dot(lam, rows), point.q)[0]])
    assert constraint.grouped == (rows.numel() < constraint.term_count)  # groups shrink the rows

    rng = np.random.default_rng(7)
    calls = 4
    q = rng.uniform(-2.0, 2.0, (calls, n))
    multipliers = rng.uniform(-1.0, 1.0, (calls, rows.numel()))
    values = constraint.parameter_values(problem)
    values["margin_cap"] = rng.uniform(0.0, 0.04, constraint.term_count)  # some below the margin: they bind
    parameters = [np.reshape(values[name], shapes[name]) for name in symbols]
    others = [np.zeros((n, calls))] * 4 + [np.ones((1, calls))]
    mapped = [q.T, *others, np.full((1, calls), 0.02), np.ones((1, calls)), *(np.tile(v, calls) for v in parameters)]
    derivatives = CollisionDerivatives(constraint)
    jacobian, hessian = derivatives.mapped(function, 6, calls)
    jacobian_sparsity, hessian_sparsity = derivatives.sparsities(5 * n + 1)
    got_jacobian, got_hessian = np.asarray(jacobian(*mapped)), np.asarray(hessian(*mapped, multipliers.T))
    for k in range(calls):
        expected_jacobian, expected_hessian = (np.asarray(v) for v in reference(
            q[k], *(np.zeros(n),) * 4, 1.0, 0.02, 1.0, *parameters, multipliers[k]))
        dense_jacobian = np.asarray(ca.DM(jacobian_sparsity, got_jacobian[:, k]))[:, :n]
        dense_hessian = np.asarray(ca.DM(hessian_sparsity, got_hessian[:, k]))[:n, :n]
        np.testing.assert_allclose(dense_jacobian, expected_jacobian, rtol=1e-9, atol=1e-10)
        np.testing.assert_allclose(dense_hessian, expected_hessian, rtol=1e-7, atol=1e-8 * np.abs(
            expected_hessian).max())


def test_the_sparsity_leaves_out_only_joints_that_do_not_move_a_rows_spheres():
    constraint = SphereCollision(PAPER)
    derivatives = CollisionDerivatives(constraint)
    jacobian, _ = derivatives.sparsities(PAPER.robot.n)
    pattern = np.asarray(ca.DM(jacobian, 1.0)) > 0
    terms = constraint.terms()
    first_obstacle_row = int(np.flatnonzero(terms.kind > 0)[0])  # ungrouped: a term a row
    sphere = terms.first[first_obstacle_row]
    joint = PAPER.robot.sphere_joint[sphere]
    assert pattern[first_obstacle_row].sum() == joint  # industrial6: a serial chain, joint j moved by q_1..q_j
    assert pattern.any(axis=0).all()


def test_without_a_compiler_casadi_differentiates_the_rows(monkeypatch):
    assert isinstance(derivatives_by_hand(SphereCollision(PAPER)), CollisionDerivatives)
    monkeypatch.setattr(collision_derivatives, "_kernel", lambda: None)
    assert derivatives_by_hand(SphereCollision(PAPER)) is None


def test_the_solvers_derivatives_outlive_the_objects_that_made_them():
    """CasADi calls back into Python objects that nothing but the NLP's constraint keeps: they must survive a
    garbage collection for as long as the NLP does, and go with it."""
    problem = MBM
    discretization = shape(problem, near=screening.line_samples(problem)).discretization
    nlp = discretization.nlp
    derivatives = pointwise_derivatives(nlp)
    gc.collect()
    x = np.random.default_rng(8).uniform(-0.2, 0.2, nlp.x.numel())
    x[nlp.variables.index("tf")] = 1.5
    parameters = discretization.parameters(problem, Refinement())
    hessian = derivatives["hess_lag"](x, parameters, 1.0, np.ones(nlp.g.numel()))
    assert np.isfinite(np.asarray(ca.DM(hessian).nonzeros())).all()
    made = len(collision_derivatives._MADE)
    del discretization, nlp, derivatives
    gc.collect()
    assert len(collision_derivatives._MADE) < made
