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
import warnings
from importlib import resources
from typing import Any

import casadi as ca
import numpy as np

from ocpkit.constraints import Constraint
from ocpkit.constraints.collision import RADIAL_EPS, SOFTMIN_SHARPNESS, SphereCollision
from ocpkit.geometry.clearances import joint_chain
from ocpkit.solvers.compiled import shared_library

FLAGS = ("-O2", "-fPIC", "-shared")
"""Small hand-written C compiled once per machine: optimized further than generated code (-O1)."""
_INT, _REAL = ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_double)


class _Model(ctypes.Structure):
    """collision_derivatives.c's Model, field for field."""

    _fields_ = [("dof", ctypes.c_int), ("joints", ctypes.c_int), ("parent", _INT), ("index", _INT),
                ("revolute", _INT), ("rotation", _REAL), ("cross", _REAL), ("cross_squared", _REAL),
                ("translation", _REAL), ("slide", _REAL), ("spheres", ctypes.c_int), ("sphere_joint", _INT),
                ("offset", _REAL), ("radius", _REAL), ("terms", ctypes.c_int), ("kind", _INT), ("first", _INT),
                ("second", _INT), ("groups", ctypes.c_int), ("group_start", _INT), ("group_terms", _INT),
                ("faces", ctypes.c_int), ("face_sphere", _INT), ("face_axis", _INT), ("face_sides", _INT),
                ("sharpness", ctypes.c_double), ("radial_eps", ctypes.c_double)]


class _Scene(ctypes.Structure):
    """collision_derivatives.c's Scene, field for field."""

    _fields_ = [("margin", ctypes.c_double), ("cap", _REAL), *((name, _REAL) for name in (
        "sphere_center", "sphere_radius", "box_center", "box_half", "box_rotation", "cylinder_center",
        "cylinder_half", "cylinder_rotation", "workspace"))]


@functools.cache
def _kernel() -> ctypes.CDLL | None:
    """collision_derivatives.c's library, loaded once per process; None (with a warning) when it cannot be
    compiled or loaded."""
    source = resources.files("ocpkit.solvers").joinpath("collision_derivatives.c").read_text()
    library = shared_library(source, FLAGS)
    if library is None:
        return None
    try:
        kernel = ctypes.CDLL(str(library))
    except OSError as exc:  # e.g. a library damaged on disk
        warnings.warn(f"cannot load {library} (delete it to compile afresh): {exc}; CasADi differentiates the "
                      "collision rows", stacklevel=2)
        return None
    kernel.collision_derivatives.restype = None
    kernel.collision_derivatives.argtypes = [ctypes.POINTER(_Model), ctypes.POINTER(_Scene), ctypes.c_void_p,
                                             ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                                             ctypes.c_void_p]
    return kernel


def derivatives_by_hand(constraint: Constraint | None) -> CollisionDerivatives | None:
    """The compiled derivatives of `constraint`'s rows: for a SphereCollision where the C compiles, else None
    (CasADi's then)."""
    if not isinstance(constraint, SphereCollision) or _kernel() is None:
        return None
    return CollisionDerivatives(constraint)


class CollisionDerivatives:
    """The Jacobian and the Lagrangian Hessian in q of one SphereCollision's rows at a point (module docstring)."""

    def __init__(self, constraint: SphereCollision) -> None:
        self._kernel = _kernel()
        self._arrays: list[np.ndarray] = []  # what the Model points to, kept alive with it
        robot, terms = constraint.robot, constraint.terms()
        joints = joint_chain(robot)
        self.dof, self.rows = robot.model.nq, len(terms.groups) + len(terms.face_sphere)
        starts = np.cumsum([0, *map(len, terms.groups)])
        members = np.concatenate([np.zeros(0, int), *terms.groups])
        self.model = _Model(
            self.dof, len(joints), self._ints([j.parent for j in joints]), self._ints([j.index for j in joints]),
            self._ints([j.revolute for j in joints]), self._reals([j.rotation for j in joints]),
            self._reals([j.cross for j in joints]), self._reals([j.cross_squared for j in joints]),
            self._reals([j.translation for j in joints]), self._reals([j.slide for j in joints]),
            len(robot.sphere_radius), self._ints(robot.sphere_joint), self._reals(robot.sphere_offset),
            self._reals(robot.sphere_radius), len(terms.kind), self._ints(terms.kind), self._ints(terms.first),
            self._ints(terms.second), len(terms.groups), self._ints(starts), self._ints(members),
            len(terms.face_sphere), self._ints(terms.face_sphere), self._ints(terms.face_axis),
            self._ints(terms.face_sides), SOFTMIN_SHARPNESS, RADIAL_EPS)
        self._work = np.empty(15 * (len(joints) + 1) + len(robot.sphere_radius) * (6 + 3 * self.dof)
                              + len(terms.kind) + 8 * self.dof)
        moved = _moved_by(robot.sphere_joint, joints, self.dof)  # (M, dof): which joints move each sphere
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
        key = (id(function), differentiated, calls)
        if key not in self._mapped:
            shapes = [(function.size1_in(i), function.size2_in(i) * calls) for i in range(function.n_in())]
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

    def _ints(self, values: object) -> Any:
        """A C int array of `values`, kept alive with this object."""
        array = np.ascontiguousarray(values, dtype=np.intc).reshape(-1)
        self._arrays.append(array)
        return array.ctypes.data_as(_INT)

    def _reals(self, values: object) -> Any:
        """A C double array of `values` (flattened row-major), kept alive with this object."""
        array = np.ascontiguousarray(values, dtype=float).reshape(-1)
        self._arrays.append(array)
        return array.ctypes.data_as(_REAL)


def _moved_by(sphere_joint: np.ndarray, joints: tuple, dof: int) -> np.ndarray:
    """(M, dof): whether q[k] moves sphere m (k is the index of a joint on the chain from m's joint to the world)."""
    moved = np.zeros((len(sphere_joint), dof), dtype=bool)
    for m, joint in enumerate(sphere_joint.tolist()):
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
        values = [np.asarray(a.full()) for a in arguments]
        first = self.differentiated  # the margin; the limit scale, then the constraint's parameters follow
        parameters = {name: values[first + 2 + k] for k, name in enumerate(self.derivatives.parameters)}
        kept = []  # the arrays the Scene points to, alive through the call

        def reals(name: str, width: int) -> Any:
            array = np.ascontiguousarray(parameters[name][:, :width], dtype=float)  # the first call's columns
            kept.append(array)
            return array.ctypes.data_as(_REAL)

        scene = _Scene(float(values[first][0, 0]), reals("margin_cap", 1), reals("obstacle_center", 3),
                       reals("obstacle_radius", 1), reals("box_center", 3), reals("box_half_size", 3),
                       reals("box_rotation", 9), reals("cylinder_center", 3), reals("cylinder_half_size", 2),
                       reals("cylinder_rotation", 9), reals("workspace", 1))
        lam = values[-1].T if self.hessian else None
        return [ca.DM(self.derivatives.evaluate(values[0].T, scene, lam).T)]
