"""The collision geometry of each URDF link as one trimesh (metres, in the link's frame): meshes (STL, DAE, OBJ
via trimesh, with their `scale`), boxes, cylinders and spheres, each placed at its `<origin>`.

Mesh files: `package://example-robot-data/<path>` is looked up in the example-robot-data package;
`package://PKG/<path>`, `file://<path>` and relative paths next to the URDF or in a folder above it
(`PKG/<path>` or `<path>`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import trimesh

from ocpkit.errors import RobotError
from ocpkit.robots.spheres import urdf_root
from ocpkit.robots.urdf import example_robot_data_dir

CYLINDER_SECTIONS = 32
"""Facets around a cylinder or on a sphere's mesh."""


def link_meshes(urdf: Path) -> dict[str, trimesh.Trimesh]:
    """Each link with collision geometry → its collision shapes merged into one mesh in the link's frame."""
    urdf = Path(urdf)
    meshes = {}
    for link in urdf_root(urdf).iter("link"):
        parts = [_shape(collision, urdf, link.get("name")) for collision in link.iter("collision")]
        parts = [p for p in parts if p is not None]
        if parts:
            meshes[link.get("name")] = trimesh.util.concatenate(parts)
    return meshes


def _origin(element: ET.Element | None) -> np.ndarray:
    """The 4 × 4 transform of an `<origin xyz rpy>` (identity when absent)."""
    if element is None:
        return np.eye(4)
    xyz = np.array([float(v) for v in element.get("xyz", "0 0 0").split()])
    rpy = np.array([float(v) for v in element.get("rpy", "0 0 0").split()])
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz).homogeneous


def _shape(collision: ET.Element, urdf: Path, link: str) -> trimesh.Trimesh | None:
    geometry = collision.find("geometry")
    if geometry is None or len(geometry) == 0:
        return None
    kind = geometry[0]
    if kind.tag == "mesh":
        mesh = _load_mesh(_mesh_file(kind.get("filename", ""), urdf, link))
        mesh.apply_scale([float(v) for v in kind.get("scale", "1 1 1").split()])
    elif kind.tag == "box":
        mesh = trimesh.creation.box(extents=[float(v) for v in kind.get("size").split()])
    elif kind.tag == "cylinder":
        mesh = trimesh.creation.cylinder(radius=float(kind.get("radius")), height=float(kind.get("length")),
                                         sections=CYLINDER_SECTIONS)
    elif kind.tag == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=float(kind.get("radius")))
    else:
        raise RobotError(f"{urdf}: link {link}: unknown collision geometry <{kind.tag}>")
    mesh.apply_transform(_origin(collision.find("origin")))
    return mesh


def _load_mesh(path: Path) -> trimesh.Trimesh:
    try:
        loaded = trimesh.load(path, force="mesh")
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise RobotError(f"cannot read mesh {path}: {exc}") from None
    return loaded


def _mesh_file(uri: str, urdf: Path, link: str) -> Path:
    """The file a mesh `filename` names (module docstring); RobotError naming the link if none exists."""
    if uri.startswith("package://example-robot-data/"):
        path = example_robot_data_dir() / uri.removeprefix("package://example-robot-data/")
        candidates = [path]
    else:
        rest = uri.removeprefix("package://").removeprefix("file://")
        parts = Path(rest).parts
        tails = [Path(rest)] + ([Path(*parts[1:])] if uri.startswith("package://") and len(parts) > 1 else [])
        candidates = [Path(rest)] if Path(rest).is_absolute() else [
            folder / tail for folder in [urdf.parent, *urdf.resolve().parents] for tail in tails]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise RobotError(f"{urdf}: link {link}: mesh file {uri!r} not found")
