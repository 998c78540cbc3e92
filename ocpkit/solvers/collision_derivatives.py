"""The collision rows' derivatives in closed form, compiled once per machine.

CasADi's automatic derivatives of the collision rows (`SphereCollision.evaluate`: sphere centres through the
kinematics, squared distances, soft minima), run by its virtual machine at every point, are the costliest of
IPOPT's evaluations on a spherized arm among obstacles, and their graph differs from problem to problem (the
screened terms), so compiling it would cost seconds per plan (figures: docs/design-notes.md). `CollisionDerivatives`
computes the same numbers in C (collision_derivatives.c, the same for every robot and scene, compiled once per
machine through ocpkit.solvers.compiled): the robot's kinematics from its model (`joint_chain`), each term's
gradient and Hessian in its sphere centre in closed form, the chain rule and the soft minimum's (the C file's
comment). The terms, rows and their order are the constraint's (`SphereCollision.terms`); the obstacles, margins and
workspace are read from the NLP parameters at each evaluation, so a build serves every query of its shape.
ocpkit.solvers.pointwise maps them over the constraint's calls in place of CasADi's (`derivatives_by_hand`); where
nothing compiles, CasADi's stay (tests/solvers/test_collision_derivatives.py holds both to the same values).
"""

from __future__ import annotations

import ctypes
import functools
import weakref
from typing import Any

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint
from ocpkit.constraints.collision import RADIAL_EPS, SOFTMIN_SHARPNESS, SphereCollision
from ocpkit.geometry.clearances import joint_chain
from ocpkit.robots import Robot
from ocpkit.solvers.chain import INT, REAL, Chain, CArrays, chain, chain_work, kernel


class _Model(ctypes.Structure):
    """collision_derivatives.c's Model, field for field."""

    _fields_ = [("chain", Chain), ("spheres", ctypes.c_int), ("sphere_joint", INT), ("offset", REAL),
                ("radius", REAL), ("used", ctypes.c_int), ("used_spheres", INT), ("terms", ctypes.c_int),
                ("kind", INT), ("first", INT), ("second", INT), ("groups", ctypes.c_int), ("group_start", INT),
                ("group_terms", INT), ("faces", ctypes.c_int), ("face_sphere", INT), ("face_axis", INT),
                ("face_sides", INT), ("sharpness", ctypes.c_double), ("radial_eps", ctypes.c_double)]


class _Scene(ctypes.Structure):
    """collision_derivatives.c's Scene, field for field."""

    _fields_ = [("margin", ctypes.c_double), ("cap", REAL), *((name, REAL) for name in (
        "sphere_center", "sphere_radius", "box_center", "box_half", "box_rotation", "cylinder_center",
        "cylinder_half", "cylinder_rotation", "workspace"))]


_MADE: weakref.WeakKeyDictionary[SphereCollision, CollisionDerivatives] = weakref.WeakKeyDictionary()
"""Each constraint's derivatives while the constraint lives: CasADi calls back into their Python objects (`_Mapped`),
which must outlive the solver's Functions that call them, and the constraint does (the NLP's point calls hold it,
and the prepared solver holds the NLP)."""


@functools.cache
def _kernel() -> ctypes.CDLL | None:
    """collision_derivatives.c's library (after chain.c), loaded once per process; None (with a warning) when it
    cannot be compiled or loaded."""
    library = kernel((("ocpkit.solvers", "chain.c"), ("ocpkit.solvers", "collision_derivatives.c")),
                     "CasADi differentiates the collision rows")
    if library is not None:
        library.collision_derivatives.restype = None
        library.collision_derivatives.argtypes = [ctypes.POINTER(_Model), ctypes.POINTER(_Scene), ctypes.c_void_p,
                                                  ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                                                  ctypes.c_void_p]
    return library


def derivatives_by_hand(constraint: Constraint | None) -> CollisionDerivatives | None:
    """The compiled derivatives of `constraint`'s rows: for a SphereCollision where the C compiles, else None
    (CasADi's then). They live as long as the constraint (`_MADE`)."""
    if not isinstance(constraint, SphereCollision) or _kernel() is None:
        return None
    if constraint not in _MADE:
        _MADE[constraint] = CollisionDerivatives(constraint)
    return _MADE[constraint]


class CollisionDerivatives:
    """The Jacobian and the Lagrangian Hessian in q of one SphereCollision's rows at a point (module docstring)."""

    def __init__(self, constraint: SphereCollision) -> None:
        self._kernel = _kernel()
        self._arrays = CArrays()  # what the Model points to, kept alive with it
        robot, terms, arrays = constraint.robot, constraint.terms(), self._arrays
        self.dof, self.rows = robot.model.nq, len(terms.groups) + len(terms.face_sphere)
        starts = np.cumsum([0, *map(len, terms.groups)])
        members = np.concatenate([np.zeros(0, int), *terms.groups])
        used = np.unique(np.concatenate([terms.first, terms.second[terms.kind == 0], terms.face_sphere]))
        self.model = _Model(
            chain(robot, arrays), len(robot.sphere_radius), arrays.ints(robot.sphere_joint),
            arrays.reals(robot.sphere_offset), arrays.reals(robot.sphere_radius), len(used), arrays.ints(used),
            len(terms.kind),
            arrays.ints(terms.kind), arrays.ints(terms.first), arrays.ints(terms.second), len(terms.groups),
            arrays.ints(starts), arrays.ints(members), len(terms.face_sphere), arrays.ints(terms.face_sphere),
            arrays.ints(terms.face_axis), arrays.ints(terms.face_sides), SOFTMIN_SHARPNESS, RADIAL_EPS)
        self._work = np.empty(chain_work(robot) + len(robot.sphere_radius) * (6 + 3 * self.dof) + len(terms.kind)
                              + 8 * self.dof)
        moved = _moved_by(robot, self.dof)  # (M, dof): which joints move each sphere
        depends = np.zeros((self.rows, self.dof), dtype=bool)
        for row, group in enumerate(terms.groups):
            pairs = terms.kind[group] == 0
            depends[row] = moved[terms.first[group]].any(axis=0) | moved[terms.second[group][pairs]].any(axis=0)
        depends[len(terms.groups):] = moved[terms.face_sphere]
        self.jacobian_columns, self.jacobian_rows = np.nonzero(depends.T)  # column-major: the CCS order
        hessian = (depends[:, :, None] & depends[:, None, :]).any(axis=0)
        self.hessian_columns, self.hessian_rows = np.nonzero(hessian.T)
        self.parameters = tuple(constraint.parameter_shapes())  # their names, in the point function's order
        self._mapped: dict[tuple, tuple[ca.Function, ca.Function]] = {}

    def sparsities(self, size: int) -> tuple[ca.Sparsity, ca.Sparsity]:
        """The Jacobian's (rows, size) and the Hessian's (size, size) sparsity at one point, for a point function
        whose differentiated inputs z (size,) start with q."""
        return (ca.Sparsity.triplet(self.rows, size, self.jacobian_rows.tolist(), self.jacobian_columns.tolist()),
                ca.Sparsity.triplet(size, size, self.hessian_rows.tolist(), self.hessian_columns.tolist()))

    def mapped(self, function: ca.Function, differentiated: int, calls: int) -> tuple[ca.Function, ca.Function]:
        """Functions of `function`'s inputs side by side for `calls` calls (as its map takes them; the Hessian's
        also the rows' multipliers (rows, calls)) → each call's Jacobian, or Hessian, nonzeros (nnz, calls), in
        `sparsities`' order. `function` is the constraint's point function: its first `differentiated` inputs are
        the point's values, q first, then the margin, the limit scale and the constraint's parameters
        (ocpkit.transcription.assembly)."""
        shapes = [(function.size1_in(i), function.size2_in(i) * calls) for i in range(function.n_in())]
        key = (tuple(shapes), differentiated, calls)
        if key not in self._mapped:
            self._mapped[key] = tuple(_Mapped(self, shapes, differentiated, calls, hessian) for hessian in
                                      (False, True))
        return self._mapped[key]

    def evaluate(self, q: np.ndarray, scene: _Scene, lam: np.ndarray | None) -> np.ndarray:
        """Per point of q (K, dof): the Jacobian's nonzeros (K, nnz), or with lam (K, rows) the Hessian's."""
        q = np.ascontiguousarray(q, dtype=float)
        count = len(q)
        if lam is None:
            out = np.empty((count, self.dof, self.rows))  # each point's rows x dof, column-major
            self._kernel.collision_derivatives(ctypes.byref(self.model), ctypes.byref(scene), q.ctypes.data, count,
                                               None, out.ctypes.data, None, self._work.ctypes.data)
            return out[:, self.jacobian_columns, self.jacobian_rows]
        lam = np.ascontiguousarray(lam, dtype=float)
        out = np.empty((count, self.dof, self.dof))
        self._kernel.collision_derivatives(ctypes.byref(self.model), ctypes.byref(scene), q.ctypes.data, count,
                                           lam.ctypes.data, None, out.ctypes.data, self._work.ctypes.data)
        return out[:, self.hessian_columns, self.hessian_rows]


def _moved_by(robot: Robot, dof: int) -> np.ndarray:
    """(M, dof): whether q[k] moves sphere m (k is the index of a joint on the chain from m's joint to the world)."""
    joints = joint_chain(robot)
    moved = np.zeros((len(robot.sphere_joint), dof), dtype=bool)
    for m, joint in enumerate(robot.sphere_joint.tolist()):
        while joint > 0:
            moved[m, joints[joint - 1].index] = True
            joint = joints[joint - 1].parent
    return moved


class _Mapped(ca.Callback):
    """A CasADi Function evaluating `CollisionDerivatives` over the calls of a mapped point function
    (CollisionDerivatives.mapped)."""

    def __init__(self, derivatives: CollisionDerivatives, shapes: list[tuple[int, int]], differentiated: int,
                 calls: int, hessian: bool) -> None:
        ca.Callback.__init__(self)
        self.derivatives, self.shapes, self.differentiated, self.calls = derivatives, shapes, differentiated, calls
        self.hessian = hessian
        nonzeros = derivatives.hessian_rows if hessian else derivatives.jacobian_rows
        self.out_shape = (len(nonzeros), calls)
        self.construct("collision_hessian" if hessian else "collision_jacobian", {})

    def get_n_in(self) -> int:
        return len(self.shapes) + self.hessian

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(*(self.shapes[i] if i < len(self.shapes) else (self.derivatives.rows, self.calls)))

    def get_sparsity_out(self, i: int) -> ca.Sparsity:
        return ca.Sparsity.dense(*self.out_shape)

    def eval(self, arguments: list[ca.DM]) -> list[ca.DM]:
        first = self.differentiated  # the margin; the limit scale, then the constraint's parameters follow
        parameters = {name: arguments[first + 2 + k] for k, name in enumerate(self.derivatives.parameters)}
        arrays = CArrays()  # what the Scene points to, alive through the call

        def reals(name: str, width: int) -> Any:
            return arrays.reals(parameters[name][:, :width].full())  # the first call's: every call's are the same

        scene = _Scene(float(arguments[first][0, 0]), reals("margin_cap", 1), reals("obstacle_center", 3),
                       reals("obstacle_radius", 1), reals("box_center", 3), reals("box_half_size", 3),
                       reals("box_rotation", 9), reals("cylinder_center", 3), reals("cylinder_half_size", 2),
                       reals("cylinder_rotation", 9), reals("workspace", 1))
        lam = arguments[-1].full().T if self.hessian else None
        return [ca.DM(self.derivatives.evaluate(arguments[0].full().T, scene, lam).T)]
