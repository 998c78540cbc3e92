"""Fit collision spheres to a link's mesh, and measure how well a set of spheres covers one.

Quality of spheres on a mesh (both measured on seeded samples, independent of the fit's own samples):
- coverage: share of SURFACE_SAMPLES points drawn uniformly on the mesh surface that lie inside some sphere;
- protrusion: how far the spheres reach beyond the mesh, m: the largest outside distance to the mesh surface
  of POINTS_PER_SPHERE points spread evenly on each sphere; sampled, so it approaches the true value from
  below. Inside or outside is the generalised winding number (deterministic, unlike trimesh's ray test, which
  retries unseeded random rays on edge hits), the distance trimesh's closest point.

The fit: for k = 1, 2, … up to the sphere budget, k-means (seeded) on points sampled inside the mesh gives k
centres; each surface sample goes to its nearest centre and each radius is the farthest surface sample of its
centre, so every fitting sample is covered; then, largest first, each radius shrinks to the farthest sample no
other sphere covers. The first k whose coverage reaches the target and whose protrusion
is at most the tolerance wins; at the budget, the least protruding k that reaches the coverage target.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.cluster.vq import kmeans2

SURFACE_SAMPLES = 4000
"""Surface points for the coverage measure (and, with another seed, for the fit)."""
POINTS_PER_SPHERE = 200
"""Points on each sphere for the protrusion measure."""
VOLUME_SAMPLES = 2000
"""Points sampled inside the mesh (for k-means centres)."""


@dataclass(frozen=True)
class Quality:
    """Coverage (share, 0–1) and protrusion (m) of a sphere set on a mesh."""

    coverage: float
    protrusion: float


@dataclass(frozen=True)
class Fit:
    """Fitted spheres: centres (k, 3) m in the mesh frame, radii (k,) m, and their quality."""

    centers: np.ndarray
    radii: np.ndarray
    quality: Quality


def sphere_points(centers: np.ndarray, radii: np.ndarray, count: int = POINTS_PER_SPHERE) -> np.ndarray:
    """`count` points spread evenly (Fibonacci lattice) on each sphere: shape (k · count, 3)."""
    i = np.arange(count) + 0.5
    polar, azimuth = np.arccos(1 - 2 * i / count), np.pi * (1 + 5 ** 0.5) * i
    unit = np.stack([np.cos(azimuth) * np.sin(polar), np.sin(azimuth) * np.sin(polar), np.cos(polar)], axis=1)
    return (centers[:, None, :] + radii[:, None, None] * unit[None]).reshape(-1, 3)


def quality(mesh: trimesh.Trimesh, centers: np.ndarray, radii: np.ndarray, seed: int = 0) -> Quality:
    """Coverage and protrusion (module docstring) of spheres (centres (k, 3), radii (k,)) on `mesh`."""
    surface, _ = trimesh.sample.sample_surface(mesh, SURFACE_SAMPLES, seed=seed)
    inside = np.linalg.norm(surface[:, None] - centers[None], axis=-1) <= radii[None]
    points = sphere_points(centers, radii)
    outside = ~inside_mesh(mesh, points)
    depth = trimesh.proximity.closest_point(mesh, points[outside])[1] if outside.any() else np.zeros(1)
    return Quality(float(inside.any(axis=1).mean()), float(depth.max()))


def inside_mesh(mesh: trimesh.Trimesh, points: np.ndarray, chunk: int = 256) -> np.ndarray:
    """Whether each point (N, 3) lies inside the closed mesh: winding number (sum of the triangles' solid angles
    over 4π, Van Oosterom–Strackee) above one half."""
    triangles = mesh.triangles  # (F, 3, 3)
    out = np.empty(len(points), dtype=bool)
    for start in range(0, len(points), chunk):
        r = triangles[None] - points[start:start + chunk, None, None]  # (n, F, 3, 3)
        length = np.linalg.norm(r, axis=-1)
        a, b, c = r[..., 0, :], r[..., 1, :], r[..., 2, :]
        la, lb, lc = length[..., 0], length[..., 1], length[..., 2]
        numerator = np.einsum("...i,...i", a, np.cross(b, c))
        denominator = (la * lb * lc + np.einsum("...i,...i", a, b) * lc + np.einsum("...i,...i", b, c) * la
                       + np.einsum("...i,...i", c, a) * lb)
        out[start:start + chunk] = np.abs(np.arctan2(numerator, denominator).sum(axis=1)) / (2 * np.pi) > 0.5
    return out


def _inside_points(mesh: trimesh.Trimesh, seed: int) -> np.ndarray:
    """Seeded uniform points of the mesh's bounding box that lie inside the (watertight) mesh."""
    low, high = mesh.bounds
    box = np.random.default_rng(seed).uniform(low, high, (VOLUME_SAMPLES, 3))
    return box[inside_mesh(mesh, box)]


def _spheres_for(surface: np.ndarray, volume: np.ndarray, k: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """k centres by k-means on the volume points; radii reaching each centre's farthest nearest surface point."""
    centers, _ = kmeans2(volume, k, minit="++", seed=np.random.default_rng(seed))
    nearest = np.argmin(np.linalg.norm(surface[:, None] - centers[None], axis=-1), axis=1)
    used = np.unique(nearest)
    centers = centers[used]
    radii = np.array([np.linalg.norm(surface[nearest == c] - centers[k], axis=1).max() for k, c in enumerate(used)])
    return _shrink(surface, centers, radii)


def _shrink(surface: np.ndarray, centers: np.ndarray, radii: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each radius in turn cut to the farthest surface point no other sphere covers (spheres left with none go)."""
    distance = np.linalg.norm(surface[:, None] - centers[None], axis=-1)  # (S, k)
    radii = radii.copy()
    for k in np.argsort(-radii):
        others = np.delete(distance <= radii[None], k, axis=1).any(axis=1)
        radii[k] = distance[~others, k].max(initial=0.0)
    keep = radii > 0
    return centers[keep], radii[keep]


def fit_spheres(mesh: trimesh.Trimesh, budget: int = 12, coverage: float = 0.99, protrusion: float = 0.01,
                seed: int = 0) -> Fit:
    """Spheres covering `mesh` (module docstring): at most `budget` spheres, coverage target (share), protrusion
    tolerance (m); seeded, so the same mesh gives the same spheres."""
    surface, _ = trimesh.sample.sample_surface(mesh, SURFACE_SAMPLES, seed=seed + 1)
    volume = _inside_points(mesh, seed) if mesh.is_watertight else np.zeros((0, 3))
    if len(volume) < budget:  # an open or very thin mesh: cluster the surface instead
        volume = surface
    fits = []
    for k in range(1, budget + 1):
        centers, radii = _spheres_for(surface, volume, k, seed)
        fit = Fit(centers, radii, quality(mesh, centers, radii, seed))
        if fit.quality.coverage >= coverage and fit.quality.protrusion <= protrusion:
            return fit
        fits.append(fit)
    covering = [f for f in fits if f.quality.coverage >= coverage] or fits
    return min(covering, key=lambda f: (f.quality.protrusion, -f.quality.coverage))
