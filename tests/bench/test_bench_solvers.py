"""`ocpkit bench solvers`: every solver × dynamics backend, a combination that cannot run recorded with its
reason (never a crash), results.csv in the paper suite's columns, the table sorted by median solve time."""

from __future__ import annotations

import csv
import shutil

import pytest
from helpers import REPO

from ocpkit.bench.solvers import combinations, run_solver_benchmark
from ocpkit.cli.main import main
from ocpkit.dynamics import DYNAMICS
from ocpkit.formats.record import RESULT_COLUMNS
from ocpkit.solvers import SOLVERS


def test_combinations_cover_every_solver_and_backend_plus_variants():
    combos = combinations()
    assert {(c.solver, c.dynamics) for c in combos} == {(s, d) for s in SOLVERS.names() for d in DYNAMICS.names()}
    assert "sqpmethod[qpsol=osqp]" in {c.label for c in combos}
    assert len({(c.label, c.dynamics) for c in combos}) == len(combos)


def test_more_than_one_knot_count_is_a_user_error(capsys):
    assert main(["bench", "solvers", "--knots", "8", "12"]) == 2
    assert "one knot count" in capsys.readouterr().err


@pytest.mark.slow
def test_bench_records_each_combination_and_sorts_by_solve_time(tmp_path, capsys):
    scenarios = tmp_path / "cases"
    scenarios.mkdir()
    shutil.copy(REPO / "scenarios/paper/case2.yaml", scenarios)
    rows = run_solver_benchmark(scenarios, tmp_path / "out", solvers=("ipopt", "fatrop"),
                                dynamics=("casadi-rnea", "pinocchio"), knots=8, transcription="hermite-simpson")
    with (tmp_path / "out/results.csv").open() as handle:
        reader = csv.DictReader(handle)
        assert tuple(reader.fieldnames) == RESULT_COLUMNS
        written = list(reader)
    status = {(r["solver"], r["dynamics"]): r["status"] for r in written}
    assert len(rows) == len(written) == 4
    assert status == {("ipopt", "casadi-rnea"): "verified", ("ipopt", "pinocchio"): "verified",
                      ("fatrop", "casadi-rnea"): "verified", ("fatrop", "pinocchio"): "unsupported"}
    lines = capsys.readouterr().out.splitlines()
    table = [cells for cells in map(str.split, lines) if cells[:1] in (["ipopt"], ["fatrop"]) and cells[1] != "+"]
    times = [float(cells[3]) for cells in table]
    assert times == sorted(times)  # the unsupported combination has no time (inf): last
    assert table[-1][:2] == ["fatrop", "pinocchio"] and "exact Hessian" in " ".join(table[-1])
    assert any(line.startswith("fastest combination verified on every case") for line in lines)
