"""`ocpkit bench shapes`: the boxes and cylinders add their rows and both variants are planned and reported."""

from __future__ import annotations

import pytest
from helpers import REPO

from ocpkit.bench.shapes import run_shapes_benchmark


@pytest.mark.slow
def test_shapes_table_counts_the_primitive_rows(capsys):
    with_shapes, without = run_shapes_benchmark(REPO / "scenarios/shapes/boxes.yaml", knots=12, repeats=1)
    assert with_shapes["primitive_rows"] > 0 and without["primitive_rows"] == 0
    assert with_shapes["collision_rows"] - without["collision_rows"] == with_shapes["primitive_rows"]
    assert with_shapes["nlp_rows"] > without["nlp_rows"]
    assert with_shapes["status"] == without["status"] == "verified"
    printed = capsys.readouterr().out
    assert "with boxes and cylinders" in printed and "medians of 1 runs" in printed
