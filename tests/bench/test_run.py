"""`ocpkit bench run`: the same rows serially, with --jobs 2 and on a two-worker Dask LocalCluster; interrupted
and resumed; suite files checked with errors naming the field."""

from __future__ import annotations

import csv
import math
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import REPO

from ocpkit.bench import suite as suite_module
from ocpkit.bench.run import run_suite
from ocpkit.bench.suite import SuiteError, load_suite
from ocpkit.cli.main import main

TIMINGS = ("solve_time_s", "setup_time_s", "wall_time_s", "extra")  # extra holds the baseline's stage times
SUITE = f"""name: small
scenarios:
  - paths: [{REPO}/scenarios/paper/case2.yaml, {REPO}/scenarios/paper/case3.yaml]
methods:
  - {{planner: simultaneous, knots: 8, single_shot: true}}
  - {{planner: ompl-toppra}}
repeats: REPEATS
"""


def write_suite(folder: Path, repeats: int = 1) -> Path:
    path = folder / "suite.yaml"
    path.write_text(SUITE.replace("REPEATS", str(repeats)))
    return path


def comparable(rows: list[dict]) -> list[tuple]:
    """The rows without their timings, as strings, sorted by key."""
    return sorted(tuple((k, str(v)) for k, v in row.items() if k not in TIMINGS) for row in rows)


def read_rows(path: Path) -> list[dict]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def serial(tmp_path_factory) -> list[dict]:
    folder = tmp_path_factory.mktemp("serial")
    run_suite(write_suite(folder), folder / "out", progress=False)
    return read_rows(folder / "out" / "results.csv")


def test_serial_run_writes_one_row_per_scenario_method_and_repeat_and_every_trajectory(serial, tmp_path):
    assert len(serial) == 4
    assert {(r["case"], r["planner"]) for r in serial} == {(c, p) for c in ("case2", "case3")
                                                            for p in ("simultaneous", "ompl-toppra")}
    assert {r["scene"] for r in serial} == {"paper"} and {r["robot"] for r in serial} == {"industrial6"}
    sim = [r for r in serial if r["planner"] == "simultaneous"]
    assert all(r["status"] == "verified" and r["guess"] == "paper" and r["seed"] == "" for r in sim)
    assert all(r["seed"] == "0" for r in serial if r["planner"] == "ompl-toppra")
    assert all(0 < float(r["peak_torque_use"]) <= 1.01 for r in sim)


def test_jobs_2_gives_the_rows_of_a_serial_run(serial, tmp_path):
    assert main(["bench", "run", str(write_suite(tmp_path)), "--out", str(tmp_path / "out"), "--jobs", "2"]) == 0
    rows = read_rows(tmp_path / "out" / "results.csv")
    assert comparable(rows) == comparable(serial)
    assert all((tmp_path / "out" / r["trajectory"]).is_file() for r in rows)


def test_a_two_worker_dask_local_cluster_gives_the_rows_of_a_serial_run(serial, tmp_path):
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        run_suite(write_suite(tmp_path), tmp_path / "out", scheduler=cluster.scheduler_address, progress=False)
    assert comparable(read_rows(tmp_path / "out" / "results.csv")) == comparable(serial)


def test_an_unreachable_scheduler_is_one_error_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("ocpkit.bench.run.CONNECT_TIMEOUT", "2s")
    assert main(["bench", "run", str(write_suite(tmp_path)), "--out", str(tmp_path / "out"),
                 "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "--scheduler tcp://127.0.0.1:1: cannot connect" in capsys.readouterr().err


@pytest.mark.slow
def test_ctrl_c_keeps_the_finished_rows_and_a_rerun_ends_with_the_rows_of_an_uninterrupted_run(tmp_path):
    suite, out = write_suite(tmp_path, repeats=2), tmp_path / "out"  # 8 rows
    command = [sys.executable, "-m", "ocpkit.cli.main", "bench", "run", str(suite), "--out", str(out), "--jobs", "2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    results = out / "results.csv"
    while process.poll() is None and not (results.exists() and len(read_rows(results)) >= 2):
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    kept = read_rows(results)
    assert process.returncode == 130, stderr
    assert 2 <= len(kept) < 8 and "interrupted:" in stdout
    assert main(["bench", "run", str(suite), "--out", str(out)]) == 0
    resumed = read_rows(results)
    assert len(resumed) == 8 and comparable(resumed[:len(kept)]) == comparable(kept)
    fresh = tmp_path / "fresh"
    run_suite(suite, fresh, progress=False)
    assert comparable(resumed) == comparable(read_rows(fresh / "results.csv"))


@pytest.mark.parametrize("text, message", [
    ("scenarios: [{paths: [x.yaml]}]", "missing 'methods'"),
    ("scenarios: []\nmethods: [{planner: simultaneous}]", "scenarios needs at least 1 values"),
    ("scenarios: [{paths: [nothing*.yaml]}]\nmethods: [{planner: simultaneous}]",
     "scenarios[0].paths[0]: no scenario file matches"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, knots: 0}]", "methods[0].knots must be > 0"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: nope}]", "methods[0].planner: unknown planner"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: ompl-toppra, knots: 8}]",
     "methods[0].knots: planner 'ompl-toppra' takes no option 'knots'"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, solver: nope}]", "methods[0].solver"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: ompl-toppra, planner_name: rrt}]",
     "methods[0].planner_name: unknown OMPL planner 'rrt'"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, seed: 2}]",
     "methods[0].seed: the simultaneous planner uses a seed only with guess: ompl"),
    ("scenarios: [{mbm: {robot: panda, scenes: [cage]}}]\nmethods: [{planner: simultaneous}]",
     "run `ocpkit data mbm`"),
    ("scenarios: [{random: {count: 2, obstacles: [3, 1]}}]\nmethods: [{planner: simultaneous}]",
     "scenarios[0].random.obstacles needs [min, max]"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, max_wall_time: .nan}]",
     "methods[0].max_wall_time must be finite or .inf (no limit)"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, max_wall_time: -.inf}]",
     "methods[0].max_wall_time must be finite or .inf"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, knots: .inf}]",
     "methods[0].knots must be an integer"),
    ("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: ompl-toppra, planning_time: .inf}]",
     "methods[0].planning_time: .inf needs max_checks"),
])
def test_a_bad_suite_is_an_error_naming_the_field(tmp_path, monkeypatch, text, message):
    monkeypatch.setattr("ocpkit.bench.suite.MBM_CACHE", tmp_path / "no-cache")  # not this machine's `data mbm`
    shutil.copy(REPO / "scenarios/paper/case1.yaml", tmp_path / "a.yaml")
    (tmp_path / "suite.yaml").write_text(text)
    with pytest.raises(SuiteError) as error:
        load_suite(tmp_path / "suite.yaml")
    assert message in str(error.value)


def test_wall_time_limits_may_be_lifted_so_that_budgets_in_work_end_the_plan(tmp_path):
    shutil.copy(REPO / "scenarios/paper/case1.yaml", tmp_path / "a.yaml")
    (tmp_path / "s.yaml").write_text("scenarios: [{paths: [a.yaml]}]\nmethods: [{planner: simultaneous, "
                                     "max_wall_time: .inf}, {planner: ompl-toppra, planning_time: .inf, "
                                     "max_checks: 1000}]")
    simultaneous, ompl = load_suite(tmp_path / "s.yaml").methods
    assert simultaneous.options == {"max_wall_time": math.inf}
    assert ompl.options == {"planning_time": math.inf, "max_checks": 1000}


def test_mbm_problems_resolve_to_the_shipped_scene_folder_in_natural_order(tmp_path, monkeypatch):
    folder = tmp_path / "scenarios/mbm/panda/cage"
    folder.mkdir(parents=True)
    text = (REPO / "scenarios/paper/case1.yaml").read_text().replace("name: case1\n", "")
    for k in (1, 2, 10):
        (folder / f"problem{k}.yaml").write_text(text)  # named by the file
    (tmp_path / "suites").mkdir()
    (tmp_path / "suites/s.yaml").write_text("scenarios: [{mbm: {robot: panda, scenes: [cage], problems: [3, 1]}}]\n"
                                            "methods: [{planner: simultaneous}]")
    suite = load_suite(tmp_path / "suites/s.yaml")
    assert [(s.scene, s.case) for s in suite.scenarios] == [("panda/cage", "problem10"), ("panda/cage", "problem1")]
    monkeypatch.setattr(suite_module, "MBM_CACHE", tmp_path / "cache")  # empty
    (tmp_path / "suites/s.yaml").write_text("scenarios: [{mbm: {robot: panda, scenes: [cage], problems: [4]}}]\n"
                                            "methods: [{planner: simultaneous}]")
    with pytest.raises(SuiteError, match=r"problems\[0\]: problem 4 does not exist: the most problems found for "
                                         r"panda/cage are 3"):
        load_suite(tmp_path / "suites/s.yaml")
    cached = tmp_path / "cache/panda/cage"
    cached.mkdir(parents=True)
    for k in range(1, 5):
        (cached / f"{k:04d}.yaml").write_text(text)
    assert [s.case for s in load_suite(tmp_path / "suites/s.yaml").scenarios] == ["0004"]  # from `ocpkit data mbm`
    (tmp_path / "cache/panda/invalid.txt").write_text(f"{cached / '0004.yaml'}: goal configuration is in collision\n"
                                                      f"{tmp_path / 'cache/panda/box/0004.yaml'}: start ...\n")
    suite = load_suite(tmp_path / "suites/s.yaml")  # as vamp's evaluation, problems invalid for the model are left out
    assert suite.scenarios == () and suite.left_out == (f"{cached / '0004.yaml'}: goal configuration is in collision",)


def test_random_source_and_repeats_give_seeded_problems_and_seeds(tmp_path):
    # seed 5: its first two draws are certified at once (seed 3's second draw exhausts the certificate's budget,
    # ~40 s per load; redrawing is tests/bench/test_random.py's)
    (tmp_path / "s.yaml").write_text("scenarios: [{random: {count: 2, seed: 5, obstacles: [1, 2]}}]\n"
                                     "methods: [{planner: ompl-toppra, seed: 5}]\nrepeats: 2")
    suite = load_suite(tmp_path / "s.yaml")
    assert [s.scene for s in suite.scenarios] == ["random-seed5"] * 2
    assert [suite.methods[0].plan_options(r)[1] for r in range(2)] == [5, 6]
    assert load_suite(tmp_path / "s.yaml").scenarios == suite.scenarios  # deterministic in the seed


def test_the_shipped_suites_are_well_formed():
    paper = load_suite(REPO / "suites/paper.yaml")
    assert [s.case for s in paper.scenarios] == ["case1", "case2", "case3", "case4"]
    assert [m.label for m in paper.methods] == ["simultaneous", "ompl-toppra"] and paper.repeats == 3
    mbm = load_suite(REPO / "suites/mbm-small.yaml")
    scenes = ["bookshelf_small", "bookshelf_tall", "bookshelf_thin", "box", "cage", "table_pick", "table_under_pick"]
    assert [(s.scene, s.case) for s in mbm.scenarios] == [(f"{robot}/{scene}", f"{scene}_0001")
                                                          for robot in ("panda", "ur5") for scene in scenes]
    assert [m.planner for m in mbm.methods] == ["simultaneous", "ompl-topp3", "ompl-toppra"]


def test_an_out_folder_of_another_command_or_suite_is_refused_not_overwritten(tmp_path, capsys):
    suite = write_suite(tmp_path)
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "results.csv").write_text("suite,case\npaper,case1\n")
    assert main(["bench", "run", str(suite), "--out", str(tmp_path / "out")]) == 2
    assert "is not a results file of `ocpkit bench run`" in capsys.readouterr().err
    assert (tmp_path / "out" / "results.csv").read_text() == "suite,case\npaper,case1\n"
    other = tmp_path / "other"
    other.mkdir()
    (other / "suite.yaml").write_text(suite.read_text().replace("name: small", "name: other"))
    run_suite(other / "suite.yaml", tmp_path / "out2", progress=False, repeats=1)
    assert main(["bench", "run", str(suite), "--out", str(tmp_path / "out2")]) == 2
    assert "holds rows of suite 'other', not 'small'" in capsys.readouterr().err


@pytest.mark.parametrize("arguments, message", [
    (["bench", "run"], "bench run needs a suite file"),
    (["bench", "run", "SUITE", "--jobs", "0"], "--jobs must be ≥ 1"),
])
def test_bad_run_options_are_one_error_line(tmp_path, capsys, arguments, message):
    arguments = [str(write_suite(tmp_path)) if a == "SUITE" else a for a in arguments]
    assert main([*arguments, "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err


@pytest.mark.slow
def test_the_paper_suite_gives_the_same_rows_with_jobs_2_on_a_local_cluster_and_interrupted(tmp_path):
    from dask.distributed import LocalCluster

    # the shipped suite with 1 of its 3 repeats: 8 rows a run, not 24 (the repeats and their OMPL seeds the same
    # whether serial, in jobs or interrupted: test_ctrl_c_keeps_the_finished_rows_and_a_rerun_ends_with_the_rows...)
    suite, repeats = REPO / "suites/paper.yaml", ["--repeats", "1"]
    assert main(["bench", "run", str(suite), "--out", str(tmp_path / "jobs"), "--jobs", "2", *repeats]) == 0
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        run_suite(suite, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False, repeats=1)
    command = [sys.executable, "-m", "ocpkit.cli.main", "bench", "run", str(suite), "--out", str(tmp_path / "cut"),
               "--jobs", "2", *repeats]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    results = tmp_path / "cut" / "results.csv"
    while process.poll() is None and not (results.exists() and len(read_rows(results)) >= 2):
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)
    process.communicate(timeout=60)
    assert process.returncode == 130 and len(read_rows(results)) < 8
    assert main(["bench", "run", str(suite), "--out", str(tmp_path / "cut"), "--jobs", "2", *repeats]) == 0
    jobs = comparable(read_rows(tmp_path / "jobs" / "results.csv"))
    assert len(jobs) == 8
    assert comparable(read_rows(tmp_path / "dask" / "results.csv")) == jobs
    assert comparable(read_rows(results)) == jobs
    assert main(["report", str(tmp_path / "cut")]) == 0


def test_the_guess_and_seed_columns_follow_the_fallback_rung_that_gave_the_plan():
    from ocpkit.bench.task import _guess_and_seed

    assert _guess_and_seed("simultaneous", {}, None, "first") == ("paper", None)
    assert _guess_and_seed("simultaneous", {}, None, "ompl-1-segments-3") == ("ompl", 1)
    assert _guess_and_seed("simultaneous", {"guess": "ompl", "fallbacks": ()}, 4, None) == ("ompl", 4)
    assert _guess_and_seed("ompl-toppra", {"seed": 2}, 2, None) == ("", 2)


def test_a_planner_that_raises_gives_a_failed_row_naming_the_exception_not_a_crashed_run(monkeypatch):
    import json

    import ocpkit.bench.task as task_module
    from ocpkit.bench.task import make_task, run_task

    def broken(problem, **options):
        raise ZeroDivisionError("a planner bug")

    monkeypatch.setattr(task_module, "plan", broken)
    suite = load_suite(REPO / "suites/paper.yaml")
    outcome = run_task(make_task("paper", suite.scenarios[0], suite.methods[1], 0))
    row = outcome["row"]
    assert row["status"] == "failed" and row["method"] == "ompl-toppra"
    assert json.loads(row["extra"])["error"] == "ompl-toppra raised ZeroDivisionError: a planner bug"
    assert json.loads(outcome["trajectory"])["status"] == "failed"


def test_a_worker_keeps_its_builds_within_a_scenario_and_drops_the_screened_ones_when_it_changes(monkeypatch):
    import ocpkit.bench.task as task_module
    from ocpkit.bench.task import make_task, run_task

    def broken(problem, **options):
        raise ZeroDivisionError("not planned here")

    cleared = []
    monkeypatch.setattr(task_module, "plan", broken)
    monkeypatch.setattr(task_module, "drop_screened", lambda: cleared.append(True))
    monkeypatch.setattr(task_module, "_planning", None)
    suite = load_suite(REPO / "suites/paper.yaml")
    first, second = suite.scenarios[:2]
    for scenario, method, repeat, clears in [(first, 0, 0, 1), (first, 0, 1, 1), (first, 1, 0, 1), (second, 0, 0, 2),
                                             (first, 0, 0, 3)]:
        run_task(make_task("paper", scenario, suite.methods[method], repeat))
        assert len(cleared) == clears
