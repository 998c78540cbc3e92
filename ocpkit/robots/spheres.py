"""Collision spheres of a URDF's links: read from `<collision><sphere>` elements, moved onto another model's links.

A sphere is `Sphere(link, center, radius)`: the centre (m) in the URDF frame of `link`, the radius (m).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ocpkit.errors import RobotError


@dataclass(frozen=True)
class Sphere:
    """One collision sphere: centre (3,) m in the frame of URDF link `link`, radius m."""

    link: str
    center: tuple[float, float, float]
    radius: float

    def as_spec(self) -> dict:
        """The spec.yaml entry `{link, center, radius}`, rounded to 0.1 mm."""
        return {"link": self.link, "center": [round(float(c), 4) + 0.0 for c in self.center],
                "radius": round(float(self.radius), 4)}


def urdf_root(path: Path) -> ET.Element:
    """The parsed <robot> element of a URDF file; RobotError naming the file if it is not one."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise RobotError(f"{path}: cannot read the URDF: {exc}") from None
    if root.tag != "robot":
        raise RobotError(f"{path}: not a URDF (root element <{root.tag}>, expected <robot>)")
    return root


def _numbers(text: str | None, count: int, where: str) -> np.ndarray:
    values = np.array([float(v) for v in (text or " ".join(["0"] * count)).split()])
    if values.shape != (count,) or not np.all(np.isfinite(values)):
        raise RobotError(f"{where}: needs {count} finite numbers, got {text!r}")
    return values


def urdf_spheres(path: Path) -> list[Sphere]:
    """Every `<collision>` sphere of the URDF at `path`, in file order (origin xyz is the centre)."""
    spheres = []
    for link in urdf_root(path).iter("link"):
        for collision in link.iter("collision"):
            shape = collision.find("geometry/sphere")
            if shape is None:
                continue
            origin = collision.find("origin")
            where = f"{path}: link {link.get('name')}"
            center = _numbers(None if origin is None else origin.get("xyz"), 3, where + " collision origin")
            radius = _numbers(shape.get("radius"), 1, where + " sphere radius")[0]
            if radius <= 0:
                raise RobotError(f"{where}: sphere radius must be > 0, got {radius}")
            spheres.append(Sphere(link.get("name"), tuple(center), float(radius)))
    return spheres


def move_onto(spheres: list[Sphere], source: pin.Model, target: pin.Model) -> list[Sphere]:
    """`spheres` of the `source` model's links re-attached to `target`'s links: a sphere on a link `target`
    lacks moves to its nearest ancestor frame that `target` has, through the source's joints at their neutral
    values (fixed joints, e.g. a gripper's links). RobotError if no ancestor is shared."""
    data = source.createData()
    pin.framesForwardKinematics(source, data, pin.neutral(source))
    moved = []
    for sphere in spheres:
        if not source.existFrame(sphere.link):
            raise RobotError(f"sphere on link {sphere.link!r}, which the sphere URDF does not have")
        frame_id = source.getFrameId(sphere.link)
        world = data.oMf[frame_id].act(np.asarray(sphere.center))
        anchor = frame_id
        while not target.existFrame(source.frames[anchor].name):
            if anchor == 0:
                raise RobotError(f"link {sphere.link!r} of the sphere URDF has no ancestor in the robot's URDF")
            anchor = source.frames[anchor].parentFrame
        name = source.frames[anchor].name
        moved.append(Sphere(name, tuple(data.oMf[anchor].actInv(world)), sphere.radius))
    return moved
