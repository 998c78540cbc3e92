"""`ocpkit show` as a person sees it: the viser page in headless Chromium shows the robot (orange, ROBOT_COLOR);
the GIF moves."""

from __future__ import annotations

import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest
from helpers import REPO
from PIL import Image, ImageSequence
from viewer_helpers import chromium, free_port

from ocpkit import load_scenario, plan
from ocpkit.cli.main import main
from ocpkit.formats.record import trajectory_header
from ocpkit.formats.trajectory import write_json

SCENARIO = REPO / "scenarios/paper/case2.yaml"


@pytest.fixture(scope="module")
def trajectory(tmp_path_factory):
    problem = load_scenario(SCENARIO)
    result = plan(problem, knots=8, fallbacks=())
    path = tmp_path_factory.mktemp("show") / "case2.json"
    write_json(path, result.trajectory, trajectory_header(problem, result))
    return path


def robot_pixels(image: Image.Image) -> int:
    """How many pixels have the robot's hue, orange, at any shading: red well above green above blue."""
    r, g, b = np.moveaxis(np.asarray(image.convert("RGB"), dtype=int), -1, 0)
    return int(((r - g > 40) & (g - b > 20)).sum())


def test_the_browser_viewer_shows_the_robot(trajectory, tmp_path):
    port = free_port()
    viewer = subprocess.Popen([sys.executable, "-m", "ocpkit.cli.main", "show", str(trajectory), "--scenario",
                               str(SCENARIO), "--port", str(port)], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}", timeout=1)
                break
            except OSError:
                assert viewer.poll() is None and time.monotonic() < deadline, viewer.stderr.read()
                time.sleep(0.2)
        shot = tmp_path / "viewer.png"
        subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
                        "--enable-unsafe-swiftshader", "--window-size=1000,700", "--virtual-time-budget=15000",
                        f"--screenshot={shot}", f"http://127.0.0.1:{port}"], check=True, capture_output=True,
                       timeout=120)
        image = Image.open(shot)
        middle = image.crop((image.width // 5, image.height // 5, 4 * image.width // 5, 4 * image.height // 5))
        assert robot_pixels(middle) > 2000  # in the 3D view, away from viser's panels and notices
    finally:
        viewer.terminate()
        viewer.wait(timeout=30)


def test_the_gif_frames_differ_and_show_the_robot(trajectory, tmp_path):
    gif = tmp_path / "motion.gif"
    assert main(["show", str(trajectory), "--scenario", str(SCENARIO), "--gif", str(gif)]) == 0
    frames = [np.asarray(f.convert("RGB"), dtype=int) for f in ImageSequence.Iterator(Image.open(gif))]
    assert len(frames) > 10
    assert np.abs(frames[0] - frames[-1]).sum(axis=-1).astype(bool).sum() > 1000  # the robot moved
    assert robot_pixels(Image.fromarray(frames[len(frames) // 2].astype(np.uint8))) > 1000


def test_a_trajectory_of_another_robot_is_one_error_line(trajectory, tmp_path, capsys):
    other = tmp_path / "other.yaml"
    other.write_text("robot: industrial6\nunit: rad\nstart: [0, 0, 0, 0, 0, 0]\ngoal: [0.1, 0, 0, 0, 0, 0]\n")
    bad = tmp_path / "bad.json"
    bad.write_text(trajectory.read_text().replace('"robot": "industrial6"', '"robot": "ur5"'))
    assert main(["show", str(bad), "--scenario", str(other), "--gif", str(tmp_path / "x.gif")]) == 2
    assert "trajectory of robot 'ur5'" in capsys.readouterr().err
