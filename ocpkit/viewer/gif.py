"""The headless viewer: the motion as an animated GIF, frames drawn with matplotlib 3D (Agg), joined by Pillow."""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
from PIL import Image  # noqa: E402

from ocpkit.geometry.scene import Workspace  # noqa: E402
from ocpkit.viewer.motion import (  # noqa: E402
    OBSTACLE_COLOR,
    ROBOT_COLOR,
    WORKSPACE_COLOR,
    Motion,
    Shape,
    box_corners,
    box_edges,
    scene_bounds,
)

MAX_FRAMES = 60
"""At most this many frames (evenly spread over the motion) go into a GIF."""


def _sphere(axes, center: np.ndarray, radius: float, color: tuple, alpha: float) -> None:
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 16), np.linspace(0, np.pi, 9))
    axes.plot_surface(center[0] + radius * np.cos(u) * np.sin(v), center[1] + radius * np.sin(u) * np.sin(v),
                      center[2] + radius * np.cos(v), color=np.array(color) / 255, alpha=alpha, linewidth=0,
                      shade=True)


BOX_FACES = ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5))
"""The 6 faces of a box as indices into box_corners (x = ∓, y = ∓, z = ∓ half-sizes)."""


def _box(axes, p: dict) -> None:
    corners = box_corners(p["center"], p["size"], p["rotation"])
    axes.add_collection3d(Poly3DCollection([corners[list(face)] for face in BOX_FACES], alpha=0.35,
                                           facecolor=np.array(OBSTACLE_COLOR) / 255, edgecolor="none"))


def _cylinder(axes, p: dict) -> None:
    u, h = np.meshgrid(np.linspace(0, 2 * np.pi, 16), np.array([-0.5, 0.5]) * p["length"])
    local = np.stack([p["radius"] * np.cos(u), p["radius"] * np.sin(u), h], axis=-1)
    x, y, z = np.moveaxis(np.asarray(p["center"]) + local @ np.asarray(p["rotation"]).T, -1, 0)
    axes.plot_surface(x, y, z, color=np.array(OBSTACLE_COLOR) / 255, alpha=0.35, linewidth=0, shade=True)


DRAW = {"sphere": lambda axes, p: _sphere(axes, np.asarray(p["center"]), p["radius"], OBSTACLE_COLOR, 0.35),
        "box": _box, "cylinder": _cylinder}
"""How each obstacle kind is drawn in matplotlib."""


def write_gif(path: str | Path, motion: Motion, shapes: list[Shape], workspace: Workspace | None,
              size: tuple[int, int] = (480, 400)) -> int:
    """Write the motion as a GIF at `path` (frame delay = the motion's real time per frame); returns the number of
    frames."""
    picks = np.unique(np.linspace(0, motion.frames - 1, min(motion.frames, MAX_FRAMES)).round().astype(int))
    lo, hi = (workspace.lower, workspace.upper) if workspace is not None else scene_bounds(motion, shapes)
    images = []
    for k in picks:
        figure = plt.figure(figsize=(size[0] / 100, size[1] / 100), dpi=100)
        axes = figure.add_subplot(projection="3d")
        for shape in shapes:
            DRAW[shape.kind](axes, shape.parameters)
        for center, radius in zip(motion.centers[k], motion.radii):
            _sphere(axes, center, radius, ROBOT_COLOR, 1.0)
        if workspace is not None:
            for start, end in box_edges(workspace):
                axes.plot(*zip(start, end), color=np.array(WORKSPACE_COLOR) / 255, lw=0.6)
        axes.set(xlim=(lo[0], hi[0]), ylim=(lo[1], hi[1]), zlim=(lo[2], hi[2]), xlabel="x [m]", ylabel="y [m]",
                 zlabel="z [m]", title=f"t = {motion.t[k]:.2f} s")
        axes.set_box_aspect(hi - lo)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png")
        plt.close(figure)
        images.append(Image.open(buffer).convert("RGB"))
    step = float(motion.t[picks[1]] - motion.t[picks[0]]) if len(picks) > 1 else 0.1
    images[0].save(path, save_all=True, append_images=images[1:], duration=int(1000 * step), loop=0)
    return len(images)
