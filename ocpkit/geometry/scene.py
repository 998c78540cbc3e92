"""The robot's surroundings: obstacle spheres, oriented boxes and cylinders, and an axis-aligned workspace box
(world frame, metres)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Workspace:
    """Axis-aligned box every robot sphere must stay inside; lower/upper have shape (3,)."""

    lower: np.ndarray
    upper: np.ndarray


@dataclass(frozen=True)
class Boxes:
    """B oriented boxes: centres (B, 3), full edge lengths `sizes` (B, 3), rotations (B, 3, 3) box → world."""

    centers: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    sizes: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    rotations: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))

    def __len__(self) -> int:
        return len(self.centers)

    def bounding_radii(self) -> np.ndarray:
        """Radius (B,) of the sphere about each centre that holds the box: half its diagonal."""
        return 0.5 * np.linalg.norm(self.sizes, axis=1)


@dataclass(frozen=True)
class Cylinders:
    """C solid cylinders along their local z axis: centres (C, 3), radii (C,), lengths (C,) (full, along the
    axis), rotations (C, 3, 3) cylinder → world."""

    centers: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    radii: np.ndarray = field(default_factory=lambda: np.zeros(0))
    lengths: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rotations: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))

    def __len__(self) -> int:
        return len(self.centers)

    def bounding_radii(self) -> np.ndarray:
        """Radius (C,) of the sphere about each centre that holds the cylinder."""
        return np.hypot(self.radii, 0.5 * self.lengths)


@dataclass(frozen=True)
class Scene:
    """S obstacle spheres (centers (S, 3), radii (S,)), oriented boxes and cylinders, and an optional workspace
    box. `names` labels the S + B + C obstacles in that order (spheres, boxes, cylinders) in messages; empty means
    'obstacle 0 (sphere)', ..."""

    obstacle_centers: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    obstacle_radii: np.ndarray = field(default_factory=lambda: np.zeros(0))
    workspace: Workspace | None = None
    boxes: Boxes = field(default_factory=Boxes)
    cylinders: Cylinders = field(default_factory=Cylinders)
    names: tuple[str, ...] = ()

    @property
    def n_obstacles(self) -> int:
        """Number of obstacles of every kind, S + B + C."""
        return len(self.obstacle_radii) + len(self.boxes) + len(self.cylinders)

    def obstacle_labels(self) -> list[str]:
        """One label per obstacle, spheres then boxes then cylinders: `names` if given (one per obstacle), else
        'obstacle 3 (box)'."""
        if len(self.names) == self.n_obstacles > 0:
            return list(self.names)
        counts = {"sphere": len(self.obstacle_radii), "box": len(self.boxes), "cylinder": len(self.cylinders)}
        kinds = [kind for kind, count in counts.items() for _ in range(count)]
        return [f"obstacle {j} ({kind})" for j, kind in enumerate(kinds)]
