"""A robot's sphere model from a source ('urdf', a spherized URDF, or 'fit'), with its per-link quality report."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tqdm import tqdm

from ocpkit.errors import RobotError
from ocpkit.robots.link_geometry import link_meshes
from ocpkit.robots.sphere_fit import Quality, fit_spheres, quality
from ocpkit.robots.spheres import Sphere, move_onto, urdf_spheres
from ocpkit.robots.urdf import model_from_urdf


def _model(urdf: Path):
    return model_from_urdf(Path(urdf).read_bytes(), urdf)


def fitted(urdf: Path, budget: int = 12, coverage: float = 0.99, protrusion: float = 0.01) -> list[Sphere]:
    """Spheres fitted to each link's collision geometry (ocpkit.robots.sphere_fit), links in file order."""
    spheres = []
    for link, mesh in tqdm(link_meshes(urdf).items(), desc="fitting spheres", unit="link", leave=False):
        fit = fit_spheres(mesh, budget, coverage, protrusion)
        spheres += [Sphere(link, tuple(c), float(r)) for c, r in zip(fit.centers, fit.radii)]
    return spheres


def sphere_model(urdf: Path, source: str, budget: int = 12, coverage: float = 0.99,
                 protrusion: float = 0.01) -> tuple[list[Sphere], str]:
    """The spheres of `source` ('urdf', 'fit' or a URDF path) on the links of `urdf`, and a per-link report of
    count, coverage and protrusion against the link geometry of `urdf` (when it has any)."""
    if source == "fit":
        spheres = fitted(urdf, budget, coverage, protrusion)
    elif source == "urdf":
        spheres = urdf_spheres(urdf)
    elif Path(source).is_file():
        spheres = move_onto(urdf_spheres(Path(source)), _model(Path(source)), _model(urdf))
    else:
        raise RobotError(f"--spheres: {source!r} is neither 'urdf', 'fit' nor a file")
    return spheres, quality_table(urdf, {source: spheres})


def _per_link(spheres: list[Sphere], meshes: dict) -> dict[str, tuple[int, Quality | None]]:
    out = {}
    for link in meshes:
        mine = [s for s in spheres if s.link == link]
        out[link] = (len(mine), quality(meshes[link], np.array([s.center for s in mine]),
                                        np.array([s.radius for s in mine])) if mine else None)
    return out


def quality_table(urdf: Path, models: dict[str, list[Sphere]]) -> str:
    """Per link of `urdf` with collision geometry: for each named sphere model its count, coverage (%) and
    protrusion (mm) on that link's geometry; a last row sums the counts."""
    try:
        meshes = link_meshes(urdf)
    except RobotError as exc:
        return f"(no per-link quality: {exc})"
    columns = {name: _per_link(spheres, meshes) for name, spheres in models.items()}
    head = f"{'link':24s}" + "".join(f" | {name[-22:]:>22s}: n  cover%  protr mm" for name in models)
    lines = [head, "-" * len(head)]
    for link in meshes:
        cells = []
        for name in models:
            count, q = columns[name][link]
            cells.append(f" | {'':>22s} {count:2d}  " + (f"{100 * q.coverage:6.2f}  {1000 * q.protrusion:8.1f}"
                                                         if q else f"{'-':>6s}  {'-':>8s}"))
        lines.append(f"{link:24s}" + "".join(cells))
    totals = "".join(f" | {'':>22s} {sum(c for c, _ in columns[n].values()):2d}  {'':6s}  {'':8s}" for n in models)
    lines.append(f"{'total':24s}" + totals)
    return "\n".join(lines)


def comparison_table(urdf: Path, compare: Path | None, budget: int = 12, coverage: float = 0.99,
                     protrusion: float = 0.01) -> str:
    """The quality table of spheres fitted to `urdf`'s links beside those of the spherized URDF `compare`."""
    models = {"fit": fitted(urdf, budget, coverage, protrusion)}
    if compare is not None:
        models[compare.name] = move_onto(urdf_spheres(compare), _model(compare), _model(urdf))
    return quality_table(urdf, models)
