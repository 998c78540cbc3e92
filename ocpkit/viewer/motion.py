"""What the viewers draw: the robot's spheres along a trajectory file, and the scenario's obstacles and workspace.

Obstacles are listed by kind (`obstacle_shapes`); each viewer has one table from kind to drawing function, so a
new obstacle kind is one entry here and one per viewer.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ocpkit.errors import OptionError
from ocpkit.geometry.clearances import sphere_centers
from ocpkit.geometry.scene import Scene, Workspace
from ocpkit.problem import Problem

ROBOT_COLOR = (235, 110, 20)
"""RGB of the robot's spheres (orange: the viewer test looks for it)."""
OBSTACLE_COLOR = (70, 110, 200)
WORKSPACE_COLOR = (120, 120, 120)


@dataclass(frozen=True)
class Shape:
    """One obstacle: its `kind` and the kind's parameters (metres, world frame): 'sphere' {center (3,), radius};
    'box' {center (3,), size (3,) full edge lengths, rotation (3, 3) box → world}; 'cylinder' {center (3,), radius,
    length (full, along its local z axis), rotation (3, 3) cylinder → world}."""

    kind: str
    parameters: dict


@dataclass(frozen=True)
class Motion:
    """The robot's spheres at frame times t (K,), s: centres (K, M, 3) and radii (M,), m."""

    t: np.ndarray
    centers: np.ndarray
    radii: np.ndarray

    @property
    def frames(self) -> int:
        return len(self.t)


def obstacle_shapes(scene: Scene) -> list[Shape]:
    """The scene's obstacles as Shapes: spheres, then boxes, then cylinders (the Scene's order)."""
    boxes, cylinders = scene.boxes, scene.cylinders
    return ([Shape("sphere", {"center": c, "radius": float(r)})
             for c, r in zip(scene.obstacle_centers, scene.obstacle_radii)]
            + [Shape("box", {"center": c, "size": s, "rotation": R})
               for c, s, R in zip(boxes.centers, boxes.sizes, boxes.rotations)]
            + [Shape("cylinder", {"center": c, "radius": float(r), "length": float(h), "rotation": R})
               for c, r, h, R in zip(cylinders.centers, cylinders.radii, cylinders.lengths, cylinders.rotations)])


def box_corners(center: np.ndarray, size: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """The 8 corners (8, 3), m, of the box of full edge lengths `size` (3,) rotated by `rotation` (3, 3) about
    `center` (3,); corner k has the signs of bits 2, 1, 0 of k on x, y, z (lower first)."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    return np.asarray(center) + (signs * np.asarray(size) / 2) @ np.asarray(rotation).T


def scene_bounds(motion: Motion, shapes: list[Shape]) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corner (3,), m, of what there is to see: the robot's spheres over the motion and the
    obstacles' bounding spheres."""
    points = [motion.centers.reshape(-1, 3)]
    for shape in shapes:
        p = shape.parameters
        reach = {"sphere": lambda: p["radius"], "box": lambda: np.linalg.norm(p["size"]) / 2,
                 "cylinder": lambda: np.hypot(p["radius"], p["length"] / 2)}[shape.kind]()
        points.append(np.asarray(p["center"]) + reach * np.array([[-1, -1, -1], [1, 1, 1]]))
    points = np.concatenate(points)
    return points.min(axis=0), points.max(axis=0)


def load_motion(path: str | Path, problem: Problem, fps: float = 30.0) -> Motion:
    """The motion of trajectory file `path` (its samples, else its knots) at `fps` frames per second on the
    problem's robot; OptionError if the file is not a trajectory of that robot."""
    path = Path(path)
    try:
        document = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        raise OptionError(f"cannot read trajectory {path}: {exc}") from None
    robot = problem.robot
    if not isinstance(document, dict) or "knots" not in document:
        raise OptionError(f"{path} is not an ocpkit trajectory file (no 'knots')")
    if document.get("robot") != robot.name or len(document.get("joint_names", ())) != robot.n:
        raise OptionError(f"{path} is a trajectory of robot {document.get('robot')!r} with "
                          f"{len(document.get('joint_names', ()))} joints, the scenario's robot is {robot.name!r} "
                          f"with {robot.n}")
    source = document.get("samples") or document["knots"]
    t, q = np.asarray(source["t"], dtype=float), np.asarray(source["q"], dtype=float)
    frames = np.append(np.arange(0.0, t[-1], 1.0 / fps), t[-1])
    q_frames = np.stack([np.interp(frames, t, q[:, j]) for j in range(robot.n)], axis=1)
    return Motion(frames, sphere_centers(robot, q_frames), robot.sphere_radius.copy())


def box_edges(workspace: Workspace) -> np.ndarray:
    """The 12 edges of the workspace box as segment end points, shape (12, 2, 3), m."""
    lo, hi = workspace.lower, workspace.upper
    corners = box_corners((lo + hi) / 2, hi - lo, np.eye(3))
    return np.array([(corners[a], corners[b]) for a in range(8) for b in range(a + 1, 8)
                     if np.count_nonzero(corners[a] != corners[b]) == 1])
