"""`ocpkit report`: the HTML page (self-contained, rendered by headless Chromium), the Markdown summary and the
Planner Arena logs, read into SQLite by OMPL's own ompl_benchmark_statistics.py (shipped in the ompl wheel)."""

from __future__ import annotations

import re
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers import REPO
from PIL import Image
from viewer_helpers import chromium

from ocpkit.bench.run import run_suite
from ocpkit.cli.main import main

SUITE = f"""name: small
scenarios:
  - paths: [{REPO}/scenarios/paper/case2.yaml, {REPO}/scenarios/paper/case3.yaml]
methods:
  - {{planner: simultaneous, knots: 8, single_shot: true, label: sim-8}}
  - {{planner: ompl-toppra, label: baseline}}
repeats: 2
"""


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    folder = tmp_path_factory.mktemp("report")
    (folder / "suite.yaml").write_text(SUITE)
    run_suite(folder / "suite.yaml", folder / "out", progress=False)
    assert main(["report", str(folder / "out")]) == 0
    return folder / "out"


def test_the_page_is_self_contained_with_tables_and_figures(out):
    page = (out / "report.html").read_text()
    assert "src='http" not in page and 'src="http' not in page  # nothing loaded from elsewhere
    assert len(re.findall(r"data:image/png;base64,", page)) == 4  # success, times, t_f vs time, the plan
    assert "time_p98_s" in page and "sim-8" in page and "baseline" in page
    markdown = (out / "report.md").read_text()
    assert "| sim-8 | 4 | 100 |" in markdown  # 2 cases x 2 repeats, all verified


def test_headless_chromium_renders_the_page(out, tmp_path):
    shot = tmp_path / "report.png"
    subprocess.run([chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--window-size=1200,2400",
                    f"--screenshot={shot}", (out / "report.html").as_uri()], check=True, capture_output=True,
                   timeout=120)
    pixels = np.asarray(Image.open(shot).convert("RGB"), dtype=int)
    assert pixels.std() > 20  # tables and figures drawn, not a blank page
    green = (pixels[..., 1] > 150) & (pixels[..., 0] < 120) & (pixels[..., 2] < 120)
    assert green.sum() > 500  # the success grid's 100 % cells


def test_the_planner_arena_logs_load_into_sqlite_with_ompl_benchmark_statistics(out, tmp_path):
    import ompl

    script = Path(ompl.__file__).parent / "ompl_benchmark_statistics.py"  # shipped in the ompl wheel
    database = tmp_path / "benchmark.db"
    subprocess.run([sys.executable, str(script), "-d", str(database), *map(str, (out / "planner-arena").glob("*.log"))],
                   check=True, capture_output=True, timeout=60)
    with sqlite3.connect(database) as db:
        planners = dict(db.execute("SELECT id, name FROM plannerConfigs"))
        runs = db.execute("SELECT plannerid, solved, time, motion_time, status FROM runs").fetchall()
        assert db.execute("SELECT name, runcount FROM experiments").fetchall() == [("small-paper", 4)]
    assert sorted(planners.values()) == ["baseline", "sim-8"]
    assert len(runs) == 8
    sim = [r for r in runs if planners[r[0]] == "sim-8"]
    assert all(r[1] == 1 and r[2] > 0 and r[3] > 0 and r[4] == 0 for r in sim)  # status enum 0 = verified


def test_a_folder_without_results_is_one_error_line(tmp_path, capsys):
    assert main(["report", str(tmp_path)]) == 2
    assert "results.csv does not exist" in capsys.readouterr().err


def test_the_run_writes_trajectories_and_scenarios_the_outside_checker_accepts(out):
    import csv
    import json

    import yaml
    from outside_check import TOLERANCE, check

    from ocpkit.robots.robot import DATA_DIR

    with (out / "results.csv").open(newline="") as handle:
        verified = [r for r in csv.DictReader(handle) if r["status"] == "verified"]
    assert len(verified) == 4
    robot = DATA_DIR / "industrial6"
    spec = yaml.safe_load((robot / "spec.yaml").read_text())
    for row in verified:
        scenario = yaml.safe_load((out / "scenarios" / row["scene"] / f"{row['case']}.yaml").read_text())
        worst = check(json.loads((out / row["trajectory"]).read_text()), spec, str(robot / "robot.urdf"), scenario)
        assert all(value <= TOLERANCE.get(name, 0.01) for name, value in worst.items()), (row["trajectory"], worst)


def test_plan_chooses_the_plotted_trajectory_and_a_missing_one_is_one_error_line(out, capsys):
    baseline = "trajectories/paper/case3--baseline--r1.json"
    assert main(["report", str(out), "--plan", baseline]) == 0
    assert f"Plan {baseline}" in (out / "report.html").read_text()
    assert main(["report", str(out), "--plan", "nope.json"]) == 2
    assert "--plan nope.json: no such trajectory file" in capsys.readouterr().err
