"""The robot's surroundings: sphere obstacles and an axis-aligned workspace box (world frame, metres)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Workspace:
    """Axis-aligned box every robot sphere must stay inside; lower/upper have shape (3,)."""

    lower: np.ndarray
    upper: np.ndarray


@dataclass(frozen=True)
class Scene:
    """S obstacle spheres (centers (S, 3), radii (S,)) and an optional workspace box."""

    obstacle_centers: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    obstacle_radii: np.ndarray = field(default_factory=lambda: np.zeros(0))
    workspace: Workspace | None = None

    @property
    def n_obstacles(self) -> int:
        """Number of obstacle spheres S."""
        return len(self.obstacle_radii)
