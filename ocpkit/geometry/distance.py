"""Exact signed distances (m) from points to oriented boxes and cylinders.

Negative inside (minus the depth to the nearest face). This is the numeric reference `geometry.clearances` (and so
`verify`, validation and the OMPL validity checker) uses; the NLP uses a smooth form (constraints/collision.py).
"""

from __future__ import annotations

import numpy as np

from ocpkit.geometry.scene import Boxes, Cylinders


def _local(points: np.ndarray, centers: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """Points (..., 3) in each primitive's frame: shape (..., P, 3). One matrix product against the P rotations
    side by side (Rᵀ(x − c) = Rᵀx − Rᵀc), which numpy runs as a single BLAS call."""
    count = len(centers)
    side_by_side = rotations.transpose(1, 0, 2).reshape(3, 3 * count)  # [j, 3p + i] = R_p[j, i]
    offsets = np.einsum("pji,pj->pi", rotations, centers).reshape(-1)
    return (points @ side_by_side - offsets).reshape(*points.shape[:-1], count, 3)


def _signed(excess: np.ndarray) -> np.ndarray:
    """Signed distance from per-axis excesses (..., k) beyond the faces: outside the norm of the positive parts,
    inside the largest (negative) excess."""
    outside = np.maximum(excess, 0.0)
    return np.sqrt(np.einsum("...i,...i->...", outside, outside)) + np.minimum(excess.max(axis=-1), 0.0)


def _own_local(points: np.ndarray, centers: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """Points (k, w, 3), row i in the frame of primitive i (centers (k, 3), rotations (k, 3, 3)): shape (k, w, 3)."""
    return np.einsum("kji,kwj->kwi", rotations, points - centers[:, None])


def box_distance(points: np.ndarray, boxes: Boxes) -> np.ndarray:
    """Signed distance of points (..., 3) to each box: shape (..., B)."""
    p = _local(points, boxes.centers, boxes.rotations)
    return _signed(np.abs(p) - 0.5 * boxes.sizes)


def box_distance_each(points: np.ndarray, boxes: Boxes, which: np.ndarray) -> np.ndarray:
    """Signed distance of points (k, w, 3), row i to box which[i] (k,) only: shape (k, w)."""
    p = _own_local(points, boxes.centers[which], boxes.rotations[which])
    return _signed(np.abs(p) - 0.5 * boxes.sizes[which][:, None])


def cylinder_distance(points: np.ndarray, cylinders: Cylinders) -> np.ndarray:
    """Signed distance of points (..., 3) to each cylinder: shape (..., C)."""
    p = _local(points, cylinders.centers, cylinders.rotations)
    return _cylinder(p, cylinders.radii, cylinders.lengths)


def cylinder_distance_each(points: np.ndarray, cylinders: Cylinders, which: np.ndarray) -> np.ndarray:
    """Signed distance of points (k, w, 3), row i to cylinder which[i] (k,) only: shape (k, w)."""
    p = _own_local(points, cylinders.centers[which], cylinders.rotations[which])
    return _cylinder(p, cylinders.radii[which][:, None], cylinders.lengths[which][:, None])


def _cylinder(p: np.ndarray, radii: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Signed distance of points p (..., 3) in cylinders' frames, radii and lengths broadcasting over p[..., 0]."""
    radial = np.linalg.norm(p[..., :2], axis=-1) - radii
    axial = np.abs(p[..., 2]) - 0.5 * lengths
    return _signed(np.stack([radial, axial], axis=-1))
