"""results.csv grows a row at a time and a re-run resumes: finished rows are kept and not planned again; Ctrl-C
during `ocpkit bench paper` ends with exit 130 and every finished row on disk."""

from __future__ import annotations

import csv
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import REPO

from ocpkit.bench.common import Results
from ocpkit.formats.record import KEY_COLUMNS, RESULT_COLUMNS, row_key

ROW = {**dict.fromkeys(RESULT_COLUMNS, ""), "suite": "paper", "case": "case1", "planner": "simultaneous",
       "knots": 12, "status": "verified", "tf": 1.5, "extra": "{}"}
KEY = row_key(ROW)


def file_rows(path: Path) -> list[dict]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def test_a_row_is_on_disk_as_soon_as_it_is_added_and_is_not_measured_again(tmp_path):
    path = tmp_path / "out/results.csv"
    first = Results(path)
    assert first.row(KEY, lambda: ROW) is ROW
    assert [row_key(r) for r in file_rows(path)] == [KEY]

    again = Results(path)
    assert again.resumed == 1
    assert again.row(KEY, lambda: pytest.fail("measured again")) == {k: str(v) for k, v in ROW.items()}
    assert len(file_rows(path)) == 1


def test_a_line_cut_short_is_dropped_and_later_rows_stay_whole(tmp_path):
    path = tmp_path / "results.csv"
    Results(path).add(ROW)
    with path.open("a") as handle:
        handle.write("paper,case2,simul")  # a crash in the middle of a line
    resumed = Results(path)
    assert resumed.resumed == 1
    resumed.add({**ROW, "case": "case3"})
    assert [r["case"] for r in file_rows(path)] == ["case1", "case3"]


@pytest.mark.slow
def test_ctrl_c_keeps_finished_rows_and_a_rerun_completes_each_row_once(tmp_path):
    cases = tmp_path / "cases"
    cases.mkdir()
    shutil.copy(REPO / "scenarios/paper/case4.yaml", cases)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "ocpkit.cli.main", "bench", "paper", "--repeats", "1", "--scenarios", str(cases),
               "--hard", "", "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    while process.poll() is None and len(_rows_if_any(out / "results.csv")) < 1:
        time.sleep(0.1)  # the first plan has finished: interrupt the second
    time.sleep(0.5)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 130, stdout + stderr
    assert stderr.splitlines() == ["interrupted"]
    kept = file_rows(out / "results.csv")
    assert 1 <= len(kept) < 8 and f"interrupted: {len(kept)} finished rows kept in {out / 'results.csv'}" in stdout

    rerun = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert rerun.returncode == 0, rerun.stderr
    assert f"resuming: {len(kept)} rows already in" in rerun.stdout
    rows = file_rows(out / "results.csv")
    assert rows[:len(kept)] == kept
    keys = [row_key(r, (*KEY_COLUMNS, "guess")) for r in rows]
    # 4 simultaneous (2 dynamics x 2 knot counts), 2 from the default guess, 2 baselines, matched
    assert len(keys) == len(set(keys)) == 9
    assert sorted(r["guess"] for r in rows) == ["", "", "line", "line", "paper", "paper", "paper", "paper", "paper"]
    assert "Initial guess: the paper's" in rerun.stdout
    assert "motion time t_f" in rerun.stdout and "ratio sim / baseline" in rerun.stdout
    assert f"results: {out / 'results.csv'}" in rerun.stdout


def _rows_if_any(path: Path) -> list[dict]:
    return file_rows(path) if path.exists() else []
