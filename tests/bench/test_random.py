"""The random suite's problems: seeded, the original one-sphere suite unchanged, 1–3 spheres in the way."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from ocpkit.bench import random as suite
from ocpkit.bench.random import PATH_SPHERES, RADII, random_problems
from ocpkit.geometry.clearances import clearances, sphere_centers


def test_the_original_suite_keeps_its_problems():
    first = next(random_problems(1, 30))
    np.testing.assert_allclose(np.degrees(first.start[:2]), [3.5465, 73.0649], atol=1e-4)  # seed 1 of issue 9
    assert first.scene.obstacle_radii.shape == (1,) and first.name == "random30"


def test_more_obstacles_are_seeded_and_within_the_range():
    problems = list(random_problems(100, 30, (1, 3), room_to_pass=None))
    again = list(random_problems(100, 30, (1, 3), room_to_pass=None))
    counts = [len(p.scene.obstacle_radii) for p in problems]
    assert set(counts) == {1, 2, 3}
    assert all(np.array_equal(p.scene.obstacle_centers, q.scene.obstacle_centers) for p, q in zip(problems, again))
    radii = np.concatenate([p.scene.obstacle_radii for p in problems])
    assert RADII[0] <= radii.min() and radii.max() <= RADII[1]


def test_the_obstacles_are_in_the_way_of_the_straight_path():
    """Each problem's straight joint-space path passes within 0.3 m of every obstacle with some robot sphere."""
    for problem in random_problems(100, 10, (2, 3), room_to_pass=None):
        path = np.linspace(problem.start, problem.goal, 41)
        centres = sphere_centers(problem.robot, path)[:, PATH_SPHERES]  # (41, k, 3)
        for obstacle in problem.scene.obstacle_centers:
            assert np.linalg.norm(centres - obstacle, axis=-1).min() < 0.3 + RADII[1]
        ends = clearances(problem.robot, problem.scene, sphere_centers(problem.robot, np.stack([problem.start,
                                                                                               problem.goal])))
        assert ends.smallest() >= 0.0


def test_problems_without_room_to_pass_are_redrawn(monkeypatch):
    """A problem whose certificate finds no path is replaced by the next draw; the others are kept as drawn."""
    # seed 10: its first draws are certified at once (seed 100's second exhausts the certificate's budget, ~40 s)
    drawn = list(random_problems(10, 3, (1, 3), room_to_pass=None))
    certified = list(random_problems(10, 2, (1, 3)))
    assert [p.name for p in certified] == ["random2", "random1"]
    np.testing.assert_array_equal(certified[0].start, drawn[0].start)
    np.testing.assert_array_equal(certified[1].start, drawn[1].start)
    calls = []

    def no_path_first(problem, **options):
        calls.append(options)
        return None if len(calls) == 1 else np.stack([problem.start, problem.goal])

    monkeypatch.setattr(suite, "joint_path", no_path_first)
    redrawn = list(random_problems(10, 2, (1, 3)))
    np.testing.assert_array_equal(redrawn[0].start, drawn[1].start)
    np.testing.assert_array_equal(redrawn[1].start, drawn[2].start)
    assert calls[0]["seed"] == suite.PATH_SEED and calls[0]["max_checks"] == suite.PATH_CHECKS
    assert calls[0]["planner_name"] == "rrtconnect"  # the certificate's search, whatever the baselines' default


@pytest.mark.slow
def test_run_random_writes_results_trajectories_and_scenarios(tmp_path, capsys):
    statuses = suite.run_random(1, 2, knots=8, obstacles=(1, 2), out=tmp_path)
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    assert sum(statuses.values()) == 2 and len(rows) == 2
    assert len(list((tmp_path / "trajectories").glob("*.json"))) == 2
    assert len(list((tmp_path / "scenarios").glob("*.yaml"))) == 2
    printed = capsys.readouterr().out
    assert "90th percentile" in printed or "no verified plan" in printed


def test_blocked_draws_are_the_ones_the_certificate_rejects(monkeypatch):
    drawn = list(random_problems(10, 3, (1, 3), room_to_pass=None))
    monkeypatch.setattr(suite, "joint_path", lambda problem, **options: None if np.array_equal(
        problem.start, drawn[1].start) else np.stack([problem.start, problem.goal]))
    blocked = next(random_problems(10, 1, (1, 3), room_to_pass=False))
    np.testing.assert_array_equal(blocked.start, drawn[1].start)
