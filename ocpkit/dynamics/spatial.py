"""Featherstone rigid-body algorithms (RNEA, ABA, forward kinematics) in CasADi.

The algorithms are built once as SX graphs from the numeric parameters of a
pinocchio ``Model`` with 1-DoF joints and wrapped in ``casadi.Function`` objects.
Spatial vectors are pairs of 3-vectors (linear part first) in the local joint
frames; spatial inertias are 3x3 blocks built from (mass, com, rotational
inertia), so the graphs contain no dense 6x6 products. A joint's pose is its
numeric placement followed by its joint motion, applied one after the other, so
a rotation about a coordinate axis costs a planar rotation only. Placement and
axis entries within 1e-10 of -1, 0 or 1 (e.g. ``cos(1.57079632679) = 4.9e-12``
from a URDF ``rpy``) are snapped to exact values so CasADi drops the
corresponding operations; results then differ from pinocchio's by ~1e-10.
Units are SI: m, rad, kg, s, N, N*m.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Union

import casadi as ca
import numpy as np
import pinocchio

Matrix = Union[ca.SX, ca.MX, ca.DM]
ArrayLike = Union[ca.SX, ca.MX, ca.DM, np.ndarray]

_SNAP_TOL = 1e-10
_AXES = "XYZ"
_REVOLUTE = {f"JointModelR{k}" for k in _AXES} | {"JointModelRevoluteUnaligned"}
_PRISMATIC = {f"JointModelP{k}" for k in _AXES} | {"JointModelPrismaticUnaligned"}


def _const(values: np.ndarray) -> ca.DM:
    """Numeric constant with entries within _SNAP_TOL of -1, 0 or 1 made exact, zeros sparse."""
    values = np.asarray(values, dtype=float)
    rounded = np.clip(np.round(values), -1.0, 1.0)
    return ca.sparsify(ca.DM(np.where(np.abs(values - rounded) < _SNAP_TOL, rounded, values)))


def _symmetric(A: Matrix) -> Matrix:
    """Symmetric matrix from the upper triangle of A (the lower one is left unused)."""
    return ca.triu(A) + ca.triu(A, False).T


@dataclass(frozen=True)
class _Spatial:
    """Spatial motion (velocity, angular velocity) or force (force, moment), (3,1) each."""

    lin: Matrix
    ang: Matrix

    def __add__(self, other: _Spatial) -> _Spatial:
        return _Spatial(self.lin + other.lin, self.ang + other.ang)

    def __mul__(self, scalar: Matrix) -> _Spatial:
        return _Spatial(self.lin * scalar, self.ang * scalar)

    def __neg__(self) -> _Spatial:
        return _Spatial(-self.lin, -self.ang)

    def dot(self, other: _Spatial) -> Matrix:
        """Scalar product, e.g. motion subspace^T force."""
        return ca.dot(self.lin, other.lin) + ca.dot(self.ang, other.ang)

    def cross(self, motion: _Spatial) -> _Spatial:
        """Motion cross product self x motion (self is a motion)."""
        return _Spatial(
            ca.cross(self.ang, motion.lin) + ca.cross(self.lin, motion.ang),
            ca.cross(self.ang, motion.ang),
        )


_ZERO = _Spatial(ca.DM(3, 1), ca.DM(3, 1))


@dataclass(frozen=True)
class _Inertia:
    """Spatial inertia [[M, H], [H^T, J]], (3,3) blocks, M and J symmetric: maps a motion
    (lin, ang) to a force (force, moment)."""

    M: Matrix
    H: Matrix
    J: Matrix

    def __add__(self, other: _Inertia) -> _Inertia:
        return _Inertia(self.M + other.M, self.H + other.H, self.J + other.J)

    def __matmul__(self, motion: _Spatial) -> _Spatial:
        return _Spatial(
            self.M @ motion.lin + self.H @ motion.ang, self.H.T @ motion.lin + self.J @ motion.ang
        )

    def minus_outer(self, U: _Spatial, V: _Spatial) -> _Inertia:
        """self - U V^T for U, V parallel (so the result stays symmetric)."""
        return _Inertia(
            _symmetric(self.M - U.lin @ V.lin.T),
            self.H - U.lin @ V.ang.T,
            _symmetric(self.J - U.ang @ V.ang.T),
        )


@dataclass(frozen=True)
class _Transform:
    """Pose of a child frame in its parent frame: x_parent = rot @ x_child + pos (m)."""

    rot: Matrix  # (3,3)
    pos: Matrix  # (3,1)

    def motion_to_child(self, v: _Spatial) -> _Spatial:
        """Motion in parent coordinates -> child coordinates."""
        return _Spatial(self.rot.T @ (v.lin - ca.cross(self.pos, v.ang)), self.rot.T @ v.ang)

    def force_to_parent(self, f: _Spatial) -> _Spatial:
        """Force in child coordinates -> parent coordinates."""
        force = self.rot @ f.lin
        return _Spatial(force, self.rot @ f.ang + ca.cross(self.pos, force))

    def inertia_to_parent(self, inertia: _Inertia) -> _Inertia:
        """Spatial inertia in child coordinates -> parent coordinates."""
        rotate = lambda A: self.rot @ A @ self.rot.T  # noqa: E731
        M, H, J = _symmetric(rotate(inertia.M)), rotate(inertia.H), _symmetric(rotate(inertia.J))
        P = ca.skew(self.pos)
        H_new = H - M @ P
        return _Inertia(M, H_new, _symmetric(J - H.T @ P + P @ H_new))


@dataclass(frozen=True)
class _JointTransform:
    """Pose of a joint frame in its parent joint frame: numeric placement, then joint motion."""

    placement: _Transform
    motion: _Transform

    def motion_to_child(self, v: _Spatial) -> _Spatial:
        return self.motion.motion_to_child(self.placement.motion_to_child(v))

    def force_to_parent(self, f: _Spatial) -> _Spatial:
        return self.placement.force_to_parent(self.motion.force_to_parent(f))

    def inertia_to_parent(self, inertia: _Inertia) -> _Inertia:
        return self.placement.inertia_to_parent(self.motion.inertia_to_parent(inertia))


@dataclass(frozen=True)
class _Joint:
    """Numeric parameters of one 1-DoF joint and of the body it carries."""

    parent: int  # index of the parent joint, 0 = universe
    placement: _Transform  # joint frame at q = 0 in the parent joint frame
    axis: ca.DM  # (3,1) unit axis in the joint frame
    revolute: bool
    mass: float  # kg
    com: ca.DM  # (3,1) centre of mass in the joint frame, m
    inertia: ca.DM  # (3,3) rotational inertia about the com, kg*m^2
    armature: float  # rotor inertia, kg*m^2 (revolute) or kg (prismatic)

    @classmethod
    def from_model(cls, model: pinocchio.Model, index: int) -> _Joint:
        """Joint ``index`` (>= 1) of ``model``; ValueError if it is not 1-DoF revolute/prismatic."""
        name, jmodel = model.names[index], model.joints[index]
        kind = jmodel.shortname()
        if kind not in _REVOLUTE | _PRISMATIC:
            raise ValueError(
                f"joint '{name}' has unsupported type {kind}; supported are the 1-DoF joints "
                f"{', '.join(sorted(_REVOLUTE | _PRISMATIC))}"
            )
        if kind.endswith("Unaligned"):
            axis = jmodel.extract().axis
        else:
            axis = np.eye(3)[_AXES.index(kind[-1])]
        placement, body = model.jointPlacements[index], model.inertias[index]
        return cls(
            parent=model.parents[index],
            placement=_Transform(_const(placement.rotation), _const(placement.translation)),
            axis=_const(axis),
            revolute=kind in _REVOLUTE,
            mass=float(body.mass),
            com=ca.DM(body.lever),
            inertia=ca.DM(body.inertia),
            armature=float(model.armature[jmodel.idx_v]),
        )

    @property
    def subspace(self) -> _Spatial:
        """Motion subspace S, in the joint frame: joint velocity = S * qd."""
        zero = ca.DM(3, 1)
        return _Spatial(zero, self.axis) if self.revolute else _Spatial(self.axis, zero)

    def transform(self, q: ca.SX) -> _JointTransform:
        """Pose of the joint frame in the parent joint frame at joint position q (rad or m)."""
        zero = ca.DM(3, 1)
        if not self.revolute:
            return _JointTransform(self.placement, _Transform(ca.DM.eye(3), self.axis * q))
        c, s = ca.cos(q), ca.sin(q)
        axis = np.asarray(self.axis).ravel()
        k = int(np.argmax(np.abs(axis)))
        if abs(axis[k]) == 1.0:  # about +-e_k: a planar rotation of the other two axes
            i, j, s = (k + 1) % 3, (k + 2) % 3, s * axis[k]
            rot = ca.SX(3, 3)
            rot[k, k], rot[i, i], rot[j, j], rot[i, j], rot[j, i] = 1, c, c, -s, s
        else:  # Rodrigues' formula
            a = self.axis
            rot = c * ca.DM.eye(3) + s * ca.skew(a) + (1 - c) * (a @ a.T)
        return _JointTransform(self.placement, _Transform(rot, zero))

    def spatial_inertia(self) -> _Inertia:
        """Rigid-body inertia of the body about the joint origin, in the joint frame."""
        C = ca.skew(self.com)
        return _Inertia(self.mass * ca.DM.eye(3), -self.mass * C, self.inertia - self.mass * C @ C)

    def body_force(self, v: _Spatial, a: _Spatial) -> _Spatial:
        """Force (N) and moment (N*m) about the joint origin that give the body spatial
        acceleration a at velocity v, all in the joint frame: I a + v x* (I v)."""
        w, dw = v.ang, a.ang
        v_com = v.lin + ca.cross(w, self.com)
        force = self.mass * (a.lin + ca.cross(dw, self.com) + ca.cross(w, v_com))
        moment = self.inertia @ dw + ca.cross(w, self.inertia @ w) + ca.cross(self.com, force)
        return _Spatial(force, moment)


class SymbolicModel:
    """CasADi rigid-body algorithms for a pinocchio Model with 1-DoF joints.

    Supported joints: JointModelRX/RY/RZ, RevoluteUnaligned, PX/PY/PZ and
    PrismaticUnaligned (so nq == nv). Arguments q (rad or m), qd (rad/s or m/s),
    qdd (rad/s^2 or m/s^2) and tau (N*m or N) are (nv,1) casadi SX/MX/DM or numpy
    arrays. Results are DM for numeric input, inlined SX expressions for SX input
    and a call of the underlying SX ``casadi.Function`` for MX input. Gravity and
    armature (rotor inertia) are taken from the model; friction is not modelled.
    """

    def __init__(self, model: pinocchio.Model) -> None:
        """Read the numeric parameters of ``model``; ValueError names an unsupported joint."""
        self._joints = [_Joint.from_model(model, i) for i in range(1, model.njoints)]
        self.nv: int = len(self._joints)
        self._base_acc = -_Spatial(_const(model.gravity.linear), _const(model.gravity.angular))

    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike) -> Matrix:
        """Joint accelerations qdd (nv,1) by the articulated-body algorithm (ABA)."""
        return self._aba(q, qd, tau)

    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> Matrix:
        """Joint efforts tau (nv,1) by the recursive Newton-Euler algorithm (RNEA)."""
        return self._rnea(q, qd, qdd)

    def joint_placements(self, q: ArrayLike) -> list[tuple[Matrix, Matrix]]:
        """World rotation (3,3) and position (3,1, m) of every joint frame, indexed like
        pinocchio's ``data.oMi`` (index 0 = universe, identity)."""
        out = self._kinematics(q)
        return list(zip(out[0::2], out[1::2]))

    def _symbols(self, *names: str) -> list[ca.SX]:
        return [ca.SX.sym(name, self.nv) for name in names]

    def _transforms(self, q: ca.SX) -> list[_JointTransform]:
        return [joint.transform(q[i]) for i, joint in enumerate(self._joints)]

    def _velocities(self, X: list[_JointTransform], qd: ca.SX) -> tuple[list, list]:
        """Velocity of every joint frame, and of its parent frame, in joint coordinates."""
        vel, parent_vel = [_ZERO], []
        for i, joint in enumerate(self._joints):
            parent_vel.append(X[i].motion_to_child(vel[joint.parent]))
            vel.append(parent_vel[i] + joint.subspace * qd[i])
        return vel[1:], parent_vel

    def _bias_accelerations(self, parent_vel: list[_Spatial], qd: ca.SX) -> list[_Spatial]:
        """Velocity-product accelerations v_parent x (S qd) of every joint frame."""
        return [
            v.cross(joint.subspace * qd[i])
            for i, (joint, v) in enumerate(zip(self._joints, parent_vel))
        ]

    @staticmethod
    def _function(name: str, inputs: list[ca.SX], outputs: list[ca.SX]) -> ca.Function:
        return ca.Function(name, inputs, ca.cse(outputs))

    @cached_property
    def _kinematics(self) -> ca.Function:
        (q,) = self._symbols("q")
        poses = [(ca.SX.eye(3), ca.SX(3, 1))]
        for joint, X in zip(self._joints, self._transforms(q)):
            rot, pos = poses[joint.parent]
            for T in (X.placement, X.motion):
                rot, pos = rot @ T.rot, pos + rot @ T.pos
            poses.append((rot, pos))
        return self._function("joint_placements", [q], [x for pose in poses for x in pose])

    @cached_property
    def _rnea(self) -> ca.Function:
        q, qd, qdd = self._symbols("q", "qd", "qdd")
        X = self._transforms(q)
        vel, parent_vel = self._velocities(X, qd)
        bias = self._bias_accelerations(parent_vel, qd)
        acc, forces = [self._base_acc], []
        for i, joint in enumerate(self._joints):
            acc.append(X[i].motion_to_child(acc[joint.parent]) + bias[i] + joint.subspace * qdd[i])
            forces.append(joint.body_force(vel[i], acc[-1]))
        tau = [None] * self.nv
        for i in reversed(range(self.nv)):
            joint = self._joints[i]
            tau[i] = joint.subspace.dot(forces[i]) + joint.armature * qdd[i]
            if joint.parent > 0:
                p = joint.parent - 1
                forces[p] = forces[p] + X[i].force_to_parent(forces[i])
        return self._function("rnea", [q, qd, qdd], [ca.vertcat(*tau)])

    @cached_property
    def _aba(self) -> ca.Function:
        q, qd, tau = self._symbols("q", "qd", "tau")
        X = self._transforms(q)
        vel, parent_vel = self._velocities(X, qd)
        bias = self._bias_accelerations(parent_vel, qd)
        inertia = [joint.spatial_inertia() for joint in self._joints]
        force = [joint.body_force(vel[i], _ZERO) for i, joint in enumerate(self._joints)]
        U, D, u = [None] * self.nv, [None] * self.nv, [None] * self.nv
        for i in reversed(range(self.nv)):
            joint = self._joints[i]
            U[i] = inertia[i] @ joint.subspace
            D[i] = joint.subspace.dot(U[i]) + joint.armature
            u[i] = tau[i] - joint.subspace.dot(force[i])
            if joint.parent > 0:
                p, U_D = joint.parent - 1, U[i] * (1 / D[i])
                articulated = inertia[i].minus_outer(U_D, U[i])
                inertia[p] = inertia[p] + X[i].inertia_to_parent(articulated)
                f = force[i] + articulated @ bias[i] + U_D * u[i]
                force[p] = force[p] + X[i].force_to_parent(f)
        acc, qdd = [self._base_acc], []
        for i, joint in enumerate(self._joints):
            a = X[i].motion_to_child(acc[joint.parent]) + bias[i]
            qdd.append((u[i] - U[i].dot(a)) / D[i])
            acc.append(a + joint.subspace * qdd[i])
        return self._function("aba", [q, qd, tau], [ca.vertcat(*qdd)])
