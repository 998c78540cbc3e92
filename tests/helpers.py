"""Shared test helpers."""

from __future__ import annotations

import copy
import importlib.metadata
from pathlib import Path

import casadi as ca
import numpy as np
import pinocchio as pin
import pytest
from numpy.polynomial import Polynomial

from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.formats.scenario import problem_from_dict
from ocpkit.formats.trajectory import Samples, Trajectory
from ocpkit.nlp import Refinement
from ocpkit.problem import Problem
from ocpkit.robots import rigid_torque
from ocpkit.transcription import TRANSCRIPTIONS, Discretization

REPO = Path(__file__).resolve().parents[1]
EXAMPLE_ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",  # 9 DoF incl. the prismatic fingers
}


def example_robot_urdf(name: str) -> Path:
    """URDF of an example-robot-data robot (a test dependency); fails the test if missing."""
    suffix = "robots/" + EXAMPLE_ROBOTS[name]
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.fail("example-robot-data is not installed; it is a test dependency (.[test])")
    for file in dist.files or []:
        if file.as_posix().endswith(suffix):
            return Path(dist.locate_file(file))
    pytest.fail(f"{suffix} is not part of the installed example-robot-data")


def discretize(problem: Problem, transcription: str, dynamics: str = "casadi", **options) -> Discretization:
    """The Discretization of `problem` by the named transcription (with `options`), dynamics backend and the
    default constraints, without a solver."""
    method = TRANSCRIPTIONS.get(transcription)(**options)
    return method.build(problem, make_dynamics(dynamics, problem.robot), make_constraints(problem))


def evaluate(discretization: Discretization, w: np.ndarray, problem: Problem, refinement: Refinement | None = None
             ) -> tuple[float, np.ndarray]:
    """(f, g (n_g,)) of the discretization's NLP at w with `problem`'s parameters after `refinement`."""
    nlp = discretization.nlp
    f = ca.Function("nlp", [nlp.x, nlp.p], [nlp.f, nlp.g])
    value, g = f(w, discretization.parameters(problem, refinement or Refinement()))
    return float(value), np.asarray(g).ravel()


def polynomial_motion(problem: Problem, tf: float, shape: Polynomial) -> Trajectory:
    """q(t) = start + shape(t / tf) (goal − start), with its exact inverse-dynamics torque."""
    robot, delta = problem.robot, problem.goal - problem.start
    derivatives = [shape.deriv(k) for k in range(4)]

    def at(t: np.ndarray) -> Samples:
        x = np.asarray(t, dtype=float) / tf
        q, qd, qdd, jerk = (np.outer(p(x) / tf**k, delta) for k, p in enumerate(derivatives))
        q += problem.start
        tau = rigid_torque(robot, q, qd, qdd) + robot.friction(qd)
        return Samples(np.asarray(t, dtype=float), q, qd, qdd, tau, np.zeros_like(tau))

    return Trajectory(at(np.array([0.0, tf])), at)


def monomial(degree: int) -> Polynomial:
    """s ↦ s^degree."""
    return Polynomial([0.0] * degree + [1.0])


def quintic(problem, tf: float, tau_offset: float = 0.0) -> Trajectory:
    """Rest-to-rest minimum-jerk motion start → goal in tf seconds, with its exact inverse-dynamics torque."""
    robot, delta = problem.robot, problem.goal - problem.start
    data = robot.model.createData()

    def at(t: np.ndarray) -> Samples:
        x = np.clip(np.asarray(t) / tf, 0, 1)[:, None]
        s = 10 * x**3 - 15 * x**4 + 6 * x**5
        ds = (30 * x**2 - 60 * x**3 + 30 * x**4) / tf
        dds = (60 * x - 180 * x**2 + 120 * x**3) / tf**2
        q, qd, qdd = problem.start + s * delta, ds * delta, dds * delta
        tau = np.array([pin.rnea(robot.model, data, *row).copy() for row in zip(q, qd, qdd)]) + robot.friction(qd)
        return Samples(np.asarray(t), q, qd, qdd, tau + tau_offset, np.gradient(tau, np.asarray(t), axis=0))

    return Trajectory(at(np.array([0.0, tf])), at)


def load(data: dict) -> Problem:
    """The Problem of scenario `data` (a copy: the caller's dict is untouched), paths relative to the repository."""
    return problem_from_dict(copy.deepcopy(data), base_dir=REPO)


def unaligned_chain() -> tuple[pin.Model, tuple[int, ...]]:
    """A pinocchio model (with bodies) of a prismatic joint, an unaligned prismatic one, an unaligned revolute one
    and a revolute one in a chain, each placed tilted and offset in its parent, and the four joints' ids."""
    model = pin.Model()
    tilted = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.1, 0.2, 0.3]))
    a = model.addJoint(0, pin.JointModelPY(), tilted, "slide")
    b = model.addJoint(a, pin.JointModelPrismaticUnaligned(np.array([0.6, 0.0, 0.8])), tilted, "slide2")
    c = model.addJoint(b, pin.JointModelRevoluteUnaligned(np.array([0.0, 0.6, 0.8])), tilted, "turn")
    d = model.addJoint(c, pin.JointModelRZ(), tilted, "wrist")
    for joint in (a, b, c, d):
        model.appendBodyToJoint(joint, pin.Inertia.Random(), pin.SE3.Identity())
    return model, (a, b, c, d)
