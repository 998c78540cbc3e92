"""`ocpkit bench classics`: rows against the published optimum, certified, a convergence picture per problem,
rockit side by side, and clear errors."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from ocpkit.bench.classics import run_classics
from ocpkit.cli.main import main
from ocpkit.errors import OptionError


def test_a_convergence_run_writes_rows_and_a_picture(tmp_path: Path, capsys):
    rows = run_classics(tmp_path, problems=("brachistochrone",), transcriptions=("lgr", "trapezoidal"),
                        grids=(8, 24))
    assert [(r.method, r.grid) for r in rows] == [("lgr", 8), ("lgr", 24), ("trapezoidal", 8), ("trapezoidal", 24)]
    by = {(r.method, r.grid): r for r in rows}
    assert by["lgr", 24].error < 1e-8 and by["lgr", 24].certified  # spectral on a smooth optimum
    assert by["trapezoidal", 24].error < by["trapezoidal", 8].error / 4  # second order
    with open(tmp_path / "classics.csv") as handle:
        assert len(list(csv.DictReader(handle))) == 4
    assert (tmp_path / "convergence-brachistochrone.png").stat().st_size > 10_000
    assert "brachistochrone" in capsys.readouterr().out


def test_rockit_solves_the_same_problem_and_is_certified_the_same_way(tmp_path: Path):
    pytest.importorskip("rockit")
    rows = run_classics(tmp_path, problems=("bryson-denham",), transcriptions=("hermite-simpson",), grids=(40,),
                        peers=("rockit",))
    assert [r.method for r in rows] == ["hermite-simpson", "rockit multiple-shooting", "rockit direct-collocation"]
    for row in rows:
        assert row.status == "converged" and row.error < 1e-2 and row.certified, row


def test_bad_names_are_refused_before_any_solve(tmp_path: Path):
    with pytest.raises(OptionError, match="unknown peer"):
        run_classics(tmp_path, peers=("dymos",))
    assert main(["bench", "classics", "--problems", "nope", "--out", str(tmp_path)]) == 2
