"""Hand-written C kernels and the robot data they read: loading them, C arrays, and the joint chain (chain.c).

`kernel(sources, instead)` compiles C kept in the package (chain.c first where it is included) through
ocpkit.solvers.compiled's disk cache and loads it; `CArrays` hands NumPy values to C and keeps them alive; `chain`
fills chain.c's Chain from a robot's model (`joint_chain`: the joints `sphere_centers_batch` composes). The path
search's collision test (ocpkit.planner.sphere_check) and the collision rows' derivatives
(ocpkit.solvers.collision_derivatives) build on them.
"""

from __future__ import annotations

import ctypes
import warnings
from importlib import resources
from typing import Any

import numpy as np

from ocpkit.geometry.clearances import joint_chain
from ocpkit.robots import Robot
from ocpkit.solvers.compiled import shared_library

INT, REAL = ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_double)
"""ctypes' int* and double*."""
KERNEL_FLAGS = ("-O2", "-fPIC", "-shared")
"""Small hand-written kernels, compiled once per machine: optimized further than generated code (-O1)."""


class Chain(ctypes.Structure):
    """chain.c's Chain, field for field."""

    _fields_ = [("dof", ctypes.c_int), ("joints", ctypes.c_int), ("parent", INT), ("index", INT),
                ("revolute", INT), ("rotation", REAL), ("cross", REAL), ("cross_squared", REAL),
                ("translation", REAL), ("slide", REAL)]


def kernel(sources: tuple[tuple[str, str], ...], instead: str) -> ctypes.CDLL | None:
    """The library of the C files `sources` ((package, file name), in order, concatenated) compiled with
    KERNEL_FLAGS; None (with a warning naming what runs `instead`) when it cannot be compiled or loaded."""
    source = "\n".join(resources.files(package).joinpath(name).read_text() for package, name in sources)
    library = shared_library(source, KERNEL_FLAGS)
    if library is None:
        return None
    try:
        return ctypes.CDLL(str(library))
    except OSError as exc:  # e.g. a library damaged on disk
        warnings.warn(f"cannot load {library} (delete it to compile afresh): {exc}; {instead}", stacklevel=3)
        return None


class CArrays:
    """C arrays of NumPy values, kept alive as long as this object."""

    def __init__(self) -> None:
        self._kept: list[np.ndarray] = []

    def ints(self, values: object) -> Any:
        """A C int array of `values` (flattened)."""
        return self._keep(np.ascontiguousarray(values, dtype=np.intc).reshape(-1)).ctypes.data_as(INT)

    def reals(self, values: object) -> Any:
        """A C double array of `values` (flattened row-major)."""
        return self._keep(np.ascontiguousarray(values, dtype=float).reshape(-1)).ctypes.data_as(REAL)

    def _keep(self, array: np.ndarray) -> np.ndarray:
        self._kept.append(array)
        return array


def chain(robot: Robot, arrays: CArrays) -> Chain:
    """chain.c's Chain of `robot`'s model, its arrays kept by `arrays`."""
    joints = joint_chain(robot)
    return Chain(robot.model.nq, len(joints), arrays.ints([j.parent for j in joints]),
                 arrays.ints([j.index for j in joints]), arrays.ints([j.revolute for j in joints]),
                 arrays.reals([j.rotation for j in joints]), arrays.reals([j.cross for j in joints]),
                 arrays.reals([j.cross_squared for j in joints]), arrays.reals([j.translation for j in joints]),
                 arrays.reals([j.slide for j in joints]))


def chain_work(robot: Robot) -> int:
    """Doubles chain.c's `kinematics` writes for `robot`: rotations, origins and axes of its joints and the world."""
    return 15 * robot.model.njoints
