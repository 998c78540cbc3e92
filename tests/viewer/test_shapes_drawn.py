"""The viewers draw a scenario's boxes and cylinders where the scenario puts them: corners and axis end points of
what is handed to viser (position, wxyz, dimensions) and to the GIF (box_corners) against those computed with
scipy straight from the scenario file's quaternions (x, y, z, w)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from helpers import REPO
from scipy.spatial.transform import Rotation

from ocpkit import load_scenario
from ocpkit.viewer.browser import DRAW
from ocpkit.viewer.motion import box_corners, obstacle_shapes

SCENARIO = REPO / "scenarios/mbm/panda/bookshelf_small/0001.yaml"  # yawed shelves (boxes) and cans (cylinders)
SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)


class RecordingScene:
    """Stands in for viser's scene: records every add_* call's arguments."""

    def __init__(self):
        self.calls = []

    def __getattr__(self, name):
        return lambda node, **kwargs: self.calls.append((name, kwargs))


def file_obstacles(kind: str) -> list[dict]:
    obstacles = yaml.safe_load(SCENARIO.read_text())["scene"]["obstacles"]
    return [o[kind] for o in obstacles if kind in o]


def drawn(kind: str) -> list[dict]:
    scene = RecordingScene()
    for k, shape in enumerate(obstacle_shapes(load_scenario(SCENARIO).scene)):
        DRAW[shape.kind](scene, f"/obstacles/{k}", shape.parameters)
    return [kwargs for name, kwargs in scene.calls if name == f"add_{kind}"]


def test_the_browser_draws_each_box_with_the_scenarios_corners():
    boxes, calls = file_obstacles("box"), drawn("box")
    assert len(boxes) == len(calls) == 4
    for box, call in zip(boxes, calls):
        expected = box["center"] + Rotation.from_quat(box["orientation"]).apply(SIGNS * np.array(box["size"]) / 2)
        rotation = Rotation.from_quat(np.roll(call["wxyz"], -1))
        assert call["position"] + rotation.apply(SIGNS * np.array(call["dimensions"]) / 2) == pytest.approx(
            expected, abs=1e-9)
        assert not np.allclose(rotation.as_matrix(), np.eye(3))  # the yaw is there, not dropped


def test_the_browser_draws_each_cylinder_along_the_scenarios_axis():
    cylinders, calls = file_obstacles("cylinder"), drawn("cylinder")
    assert len(cylinders) == len(calls) == 3
    for cylinder, call in zip(cylinders, calls):
        ends = lambda center, rotation, length: center + rotation.apply([[0, 0, -length / 2], [0, 0, length / 2]])  # noqa: E731
        expected = ends(np.array(cylinder["center"]), Rotation.from_quat(cylinder["orientation"]), cylinder["length"])
        got = ends(np.array(call["position"]), Rotation.from_quat(np.roll(call["wxyz"], -1)), call["height"])
        assert got == pytest.approx(expected, abs=1e-9) and call["radius"] == cylinder["radius"]


def test_the_gif_boxes_have_the_scenarios_corners():
    boxes = file_obstacles("box")
    shapes = [s for s in obstacle_shapes(load_scenario(SCENARIO).scene) if s.kind == "box"]
    for box, shape in zip(boxes, shapes):
        expected = box["center"] + Rotation.from_quat(box["orientation"]).apply(SIGNS * np.array(box["size"]) / 2)
        assert box_corners(**shape.parameters) == pytest.approx(expected, abs=1e-9)
