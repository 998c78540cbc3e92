"""Shared test helpers."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
EXAMPLE_ROBOTS = {
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",  # 9 DoF incl. the prismatic fingers
}


def example_robot_urdf(name: str) -> Path:
    """URDF of an example-robot-data robot (a test dependency); fails the test if missing."""
    suffix = "robots/" + EXAMPLE_ROBOTS[name]
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.fail("example-robot-data is not installed; it is a test dependency (.[test])")
    for file in dist.files or []:
        if file.as_posix().endswith(suffix):
            return Path(dist.locate_file(file))
    pytest.fail(f"{suffix} is not part of the installed example-robot-data")
