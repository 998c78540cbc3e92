"""The interactive viewer: a viser server showing the robot's spheres, the obstacles and the workspace box, with
a timeline slider and Play / Pause buttons (playing loops from the start)."""

from __future__ import annotations

import threading
import time

import numpy as np
import pinocchio as pin
import viser

from ocpkit.geometry.scene import Workspace
from ocpkit.viewer.motion import OBSTACLE_COLOR, ROBOT_COLOR, WORKSPACE_COLOR, Motion, Shape, box_edges, scene_bounds

OPACITY = 0.6


def wxyz(rotation: np.ndarray) -> tuple[float, float, float, float]:
    """The unit quaternion (w, x, y, z), viser's order, of a rotation matrix (3, 3)."""
    x, y, z, w = pin.Quaternion(np.asarray(rotation, dtype=float)).coeffs()
    return float(w), float(x), float(y), float(z)


DRAW = {
    "sphere": lambda scene, name, p: scene.add_icosphere(name, radius=p["radius"], color=OBSTACLE_COLOR,
                                                         position=tuple(p["center"]), opacity=OPACITY),
    "box": lambda scene, name, p: scene.add_box(name, color=OBSTACLE_COLOR, dimensions=tuple(p["size"]),
                                                wxyz=wxyz(p["rotation"]), position=tuple(p["center"]),
                                                opacity=OPACITY),
    "cylinder": lambda scene, name, p: scene.add_cylinder(name, radius=p["radius"], height=p["length"],
                                                          color=OBSTACLE_COLOR, wxyz=wxyz(p["rotation"]),
                                                          position=tuple(p["center"]), opacity=OPACITY),
}
"""How each obstacle kind is drawn on a viser scene (viser's cylinders, like ours, lie along their local z)."""


def serve(motion: Motion, shapes: list[Shape], workspace: Workspace | None, host: str = "127.0.0.1",
          port: int = 8080, title: str = "ocpkit") -> viser.ViserServer:
    """Start the viewer on host:port and return its server (it runs in background threads; `server.stop()`)."""
    server = viser.ViserServer(host=host, port=port, label=title, verbose=False)
    server.scene.set_up_direction("+z")
    server.scene.add_grid("/ground", width=4.0, height=4.0, cell_size=0.25)
    for k, shape in enumerate(shapes):
        DRAW[shape.kind](server.scene, f"/obstacles/{k}", shape.parameters)
    if workspace is not None:
        server.scene.add_line_segments("/workspace", box_edges(workspace), WORKSPACE_COLOR, thickness=2.0,
                                       thickness_units="screen")
    lower, upper = (workspace.lower, workspace.upper) if workspace is not None else scene_bounds(motion, shapes)
    middle, extent = (upper + lower) / 2, float(np.max(upper - lower))
    server.initial_camera.look_at = tuple(middle)
    server.initial_camera.position = tuple(middle + extent * np.array([0.6, -0.85, 0.5]))
    spheres = [server.scene.add_icosphere(f"/robot/{j}", radius=float(r), color=ROBOT_COLOR,
                                          position=tuple(motion.centers[0, j])) for j, r in enumerate(motion.radii)]
    timeline = server.gui.add_slider("t [s]", min=0.0, max=float(motion.t[-1]), step=float(motion.t[1] - motion.t[0])
                                     if motion.frames > 1 else 0.01, initial_value=0.0)
    playing = threading.Event()
    server.gui.add_button("Play", icon=viser.Icon.PLAYER_PLAY).on_click(lambda _: playing.set())
    server.gui.add_button("Pause", icon=viser.Icon.PLAYER_PAUSE).on_click(lambda _: playing.clear())

    @timeline.on_update
    def _(_) -> None:
        k = int(np.clip(np.searchsorted(motion.t, timeline.value), 0, motion.frames - 1))
        with server.atomic():
            for j, sphere in enumerate(spheres):
                sphere.position = tuple(motion.centers[k, j])

    def play() -> None:
        period = motion.t[1] - motion.t[0] if motion.frames > 1 else 0.1
        while True:
            time.sleep(period)
            if playing.is_set():
                timeline.value = 0.0 if timeline.value >= motion.t[-1] else min(timeline.value + period,
                                                                                float(motion.t[-1]))

    threading.Thread(target=play, daemon=True).start()
    return server
