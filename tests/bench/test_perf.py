"""`ocpkit bench perf`: the split of a plan's computation time adds up, and its growth problems are sound."""

from __future__ import annotations

import os
import shutil

import numpy as np
import pytest
from helpers import REPO

from ocpkit.bench.perf import (EVALUATIONS, GROWTH_CASE, PARTS, cluttered, cold_compile, fitted_exponent, ipopt_timing,
                               linear_share, planned, run_perf)
from ocpkit.formats.scenario import load_scenario
from ocpkit.geometry.clearances import clearances, sphere_centers
from ocpkit.solvers.compiled import compiler

CASE2 = load_scenario(REPO / "scenarios/paper/case2.yaml")


def test_split_adds_up_to_the_wall_time():
    first = planned(CASE2, 8, fresh=True)
    assert first.setup == pytest.approx(sum(first.setup_parts.values()), rel=0.01)
    assert first.setup_parts["graph"] > 0 and first.setup_parts["solver"] > 0
    timing = ipopt_timing(CASE2, 8)
    assert 0 < timing["linear"] < timing["total"] and 0 < timing["evaluations"] < timing["total"]
    share = linear_share([timing])
    assert 0 < share < 1
    s = planned(CASE2, 8, linear_share=share)  # the build reused, as in every timed repeat
    assert s.status == "verified" and s.setup == 0
    assert s.parts["linear solves"] / (s.parts["linear solves"] + s.parts["ipopt overhead"]) == pytest.approx(share)
    assert set(s.parts) == set(PARTS)
    assert all(s.parts[p] > 0 for p in (*EVALUATIONS[1:], "linear solves", "ipopt overhead", "verification"))
    # every measured part is a real interval inside the plan: the unaccounted Python rest is small and not negative
    assert -1e-3 <= s.parts["python"] <= 0.2 * s.computation + 0.01
    assert sum(s.solves) <= s.computation + 1e-6


@pytest.mark.skipif(compiler() is None, reason="no C compiler (make test installs gcc as root)")
def test_a_cold_compile_is_measured_apart_and_a_warm_build_compiles_nothing(monkeypatch):
    monkeypatch.delenv("OCPKIT_COMPILED_DIR", raising=False)
    cold = cold_compile(CASE2, 6)
    assert cold["compile"] > 0 and "OCPKIT_COMPILED_DIR" not in os.environ
    planned(CASE2, 6, fresh=True)  # the machine's own cache: compiles on a fresh machine
    warm = planned(CASE2, 6, fresh=True)
    assert warm.status == "verified" and warm.setup_parts["compile"] == 0 and warm.setup_parts["solver"] > 0


def test_cluttered_adds_spheres_clear_of_the_straight_line():
    busy = cluttered(CASE2, 6)
    assert busy.scene.n_obstacles == 6
    np.testing.assert_array_equal(busy.scene.obstacle_centers[0], CASE2.scene.obstacle_centers[0])
    line = CASE2.start + np.linspace(0, 1, 41)[:, None] * (CASE2.goal - CASE2.start)
    extra = type(busy.scene)(busy.scene.obstacle_centers[1:], busy.scene.obstacle_radii[1:])
    assert clearances(CASE2.robot, extra, sphere_centers(CASE2.robot, line)).obstacles.min() >= 0.1 - 1e-9
    np.testing.assert_array_equal(cluttered(CASE2, 6).scene.obstacle_centers, busy.scene.obstacle_centers)  # seeded


def test_fitted_exponent_recovers_a_power_law():
    x = [8, 12, 16, 24, 32]
    assert fitted_exponent(x, [3.0 * v**2.4 for v in x]) == pytest.approx(2.4)


@pytest.mark.slow
def test_perf_quick_writes_split_growth_and_png(tmp_path, capsys):
    cases = tmp_path / "cases"  # one of the four paper cases, the growth case: a quarter of the split's plans
    cases.mkdir()
    shutil.copy(REPO / f"scenarios/paper/{GROWTH_CASE}.yaml", cases)
    split = run_perf(cases, tmp_path, quick=True)
    assert all(s.status == "verified" for samples in split.values() for s in samples)
    assert (tmp_path / "growth.png").stat().st_size > 10_000
    assert len((tmp_path / "split.csv").read_text().splitlines()) == 1 + 2 * 1 * 2  # knots x cases x repeats
    assert "fitted exponent against knots" in capsys.readouterr().out
