"""The assembly's rows at a point: made through one CasADi Function per constraint, they must equal what each
constraint's own code gives at that point, on a scene with obstacle spheres, a box and a cylinder."""

from __future__ import annotations

import dataclasses

import casadi as ca
import numpy as np
from helpers import REPO

from ocpkit import load_scenario
from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.geometry.scene import Boxes, Cylinders
from ocpkit.transcription.assembly import Assembly

CASE = load_scenario(REPO / "scenarios/paper/case1.yaml")
PROBLEM = dataclasses.replace(CASE, scene=dataclasses.replace(
    CASE.scene, boxes=Boxes(np.array([[0.9, 0.3, 0.6]]), np.array([[0.2, 0.3, 0.4]]), np.eye(3)[None]),
    cylinders=Cylinders(np.array([[0.8, -0.4, 0.7]]), np.array([0.1]), np.array([0.5]), np.eye(3)[None])))


def test_rows_through_the_point_functions_equal_the_constraints_own():
    constraints = make_constraints(PROBLEM)
    assembly = Assembly(PROBLEM, make_dynamics("casadi-rnea", PROBLEM.robot), constraints)
    node, n = assembly.node("knot"), PROBLEM.robot.n
    slope, dt_ds = ca.SX.sym("du_ds", 2 * n), ca.SX.sym("dt_ds")  # du/dσ of the controls [q̈, u]
    assembly.path(node, [slope], dt_ds, None)  # the robot's values do not read t
    values = assembly.point(node, slope, dt_ds, None)
    own = [constraint.evaluate(values, context) for constraint, context in zip(constraints, assembly.contexts)]
    assert len(assembly.g) == len(own) and sum(rows.g.numel() for rows in own) > 100
    collision = next(c for c in constraints if c.name == "collision")
    assert collision.obstacle_mask[:, 1:].any(axis=0).all()  # the box and the cylinder have rows
    symbols = [assembly.w.symbol(), assembly.p.symbol(), slope, dt_ds]
    both = ca.Function("both", symbols, [ca.vertcat(*assembly.g), ca.vertcat(*(rows.g for rows in own))])
    rng = np.random.default_rng(0)
    for _ in range(5):
        g, expected = (np.asarray(v).ravel() for v in both(*(rng.normal(size=s.numel()) for s in symbols)))
        assert np.allclose(g, expected, rtol=1e-12, atol=1e-12)
    assert np.array_equal(np.concatenate(assembly.lbg), np.concatenate([rows.lower for rows in own]))
    assert np.array_equal(np.concatenate(assembly.ubg), np.concatenate([rows.upper for rows in own]))
