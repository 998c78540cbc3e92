"""The convergence study on a tiny sweep: files, columns, and the rates it must show on the smooth variant."""

from __future__ import annotations

import csv

import pytest

from ocpkit.bench.convergence import COLUMNS, groups, read_rows, run_convergence

TINY = {"chebyshev": (6, 10, 14), "lgr": (6, 10, 14), "trapezoidal": (16, 32)}


@pytest.mark.slow
def test_tiny_sweep_writes_csv_and_plot_and_shows_the_rates(tmp_path):
    rows = run_convergence(tmp_path, sweep=TINY, references={"smooth": ("chebyshev", 20)})

    with (tmp_path / "convergence.csv").open(newline="") as handle:
        assert tuple(csv.DictReader(handle).fieldnames) == COLUMNS
    assert len(read_rows(tmp_path / "convergence.csv")) == len(rows) == 8
    assert (tmp_path / "convergence.png").stat().st_size > 10_000
    assert all(r["status"] == "verified" for r in rows)

    by = groups(rows)
    cheb, lgr, trap = by["smooth", "chebyshev"], by["smooth", "lgr"], by["smooth", "trapezoidal"]
    for pseudospectral in (cheb, lgr):
        # no bound active: the optimum is a quintic in t, which a degree-N polynomial at N ≥ 5 represents exactly
        assert all(r["tf_error"] < 1e-6 for r in pseudospectral)
        # while u interpolates rnea(q(t)) (not a polynomial): spectral decay of the dynamics residual
        residuals = [r["dynamics_residual"] for r in pseudospectral]
        assert residuals[0] > 10 * residuals[1] > 100 * residuals[2]
    # trapezoidal is second order: halving h quarters the t_f error
    assert 3.0 < trap[0]["tf_error"] / trap[1]["tf_error"] < 5.0
    assert trap[1]["tf_error"] > 100 * cheb[0]["tf_error"]
