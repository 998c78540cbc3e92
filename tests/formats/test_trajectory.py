"""Trajectory sampling (grid spacing, t_f included) and the JSON exchange format."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ocpkit.formats.trajectory import FORMAT, Samples, Trajectory, write_json

N = 3
HEADER = {"robot": "toy", "joint_names": ["a", "b", "c"], "method": {"planner": "test"}, "status": "verified",
          "solve_time_s": 0.25, "iterations": 17}


def linear(tf: float) -> Trajectory:
    """q(t) = t · [1, 2, 3] on [0, tf]; the other fields are recognisable functions of t."""
    slope = np.arange(1.0, N + 1)

    def at(t: np.ndarray) -> Samples:
        t = np.asarray(t, dtype=float)
        q = np.outer(t, slope)
        return Samples(t, q, np.tile(slope, (len(t), 1)), np.zeros_like(q), 10 * q, np.full_like(q, 10.0))

    return Trajectory(at(np.linspace(0.0, tf, 4)), at)


def test_tf_is_the_last_knot_time():
    assert linear(0.37).tf == 0.37


def test_sample_grid_is_dt_spaced_with_a_shorter_last_step():
    t = linear(0.0105).sample(1e-3).t
    assert t[0] == 0.0 and t[-1] == 0.0105
    np.testing.assert_allclose(np.diff(t)[:-1], 1e-3)
    assert np.diff(t)[-1] == pytest.approx(0.5e-3)
    assert len(t) == 12


@pytest.mark.parametrize("tf, dt, count", [(0.3, 0.1, 4), (0.7, 0.1, 8), (1.0, 0.25, 5), (0.01, 1e-3, 11)])
def test_tf_that_is_a_multiple_of_dt_is_sampled_once(tf, dt, count):
    t = linear(tf).sample(dt).t
    assert len(t) == count and t[-1] == tf
    np.testing.assert_allclose(np.diff(t), dt, rtol=1e-9)


def test_sample_evaluates_the_interpolant():
    samples = linear(0.05).sample(0.01)
    np.testing.assert_allclose(samples.q, np.outer(samples.t, [1.0, 2.0, 3.0]))
    assert samples.tau.shape == (len(samples.t), N)


def test_dt_larger_than_tf_gives_the_two_ends():
    np.testing.assert_array_equal(linear(0.2).sample(1.0).t, [0.0, 0.2])


def test_write_json_writes_the_documented_fields(tmp_path):
    path = tmp_path / "nested/dir/out.json"
    write_json(path, linear(0.0105), HEADER, dt=1e-3)
    document = json.loads(path.read_text())
    assert set(document) == {"format", *HEADER, "tf", "knots", "samples"}
    assert document["format"] == FORMAT == "ocpkit.trajectory/1"
    assert {k: document[k] for k in HEADER} == HEADER
    assert document["tf"] == 0.0105
    assert set(document["knots"]) == {"t", "q", "qd", "tau"}
    assert set(document["samples"]) == {"t", "q", "qd", "qdd", "tau"}


def test_write_json_round_trips_with_the_right_shapes(tmp_path):
    trajectory = linear(0.0105)
    write_json(tmp_path / "out.json", trajectory, HEADER, dt=1e-3)
    document = json.loads((tmp_path / "out.json").read_text())
    knots, samples = document["knots"], document["samples"]
    assert np.shape(knots["t"]) == (4,) and all(np.shape(knots[k]) == (4, N) for k in ("q", "qd", "tau"))
    assert np.shape(samples["t"]) == (12,)
    assert all(np.shape(samples[k]) == (12, N) for k in ("q", "qd", "qdd", "tau"))
    expected = trajectory.sample(1e-3)
    for key in ("t", "q", "qd", "qdd", "tau"):
        np.testing.assert_array_equal(samples[key], getattr(expected, key))
    np.testing.assert_array_equal(knots["q"], trajectory.knots.q)
    assert samples["t"][-1] == document["tf"]


def test_write_json_sample_step_follows_dt(tmp_path):
    write_json(tmp_path / "out.json", linear(0.1), HEADER, dt=0.02)
    t = json.loads((tmp_path / "out.json").read_text())["samples"]["t"]
    np.testing.assert_allclose(t, [0.0, 0.02, 0.04, 0.06, 0.08, 0.1])


@pytest.mark.parametrize("tf, words", [(4369.0, "outside the time bounds [0.1, 10] s"),
                                       (0.05, "outside the time bounds"), (np.nan, "outside the time bounds")])
def test_write_json_leaves_out_the_samples_of_a_tf_outside_the_time_bounds(tmp_path, tf, words):
    write_json(tmp_path / "out.json", linear(tf), HEADER, time_bounds=(0.1, 10.0))
    document = json.loads((tmp_path / "out.json").read_text())
    assert document["samples"] is None and words in document["samples_omitted"]
    assert len(document["knots"]["t"]) == 4  # the knots are still there


def test_write_json_caps_the_sample_count_without_time_bounds(tmp_path):
    write_json(tmp_path / "out.json", linear(4369.0), HEADER)  # 4.4 million samples at 1 ms
    document = json.loads((tmp_path / "out.json").read_text())
    assert document["samples"] is None and "more than 100000 samples" in document["samples_omitted"]
    assert (tmp_path / "out.json").stat().st_size < 10_000


def test_write_json_samples_a_tf_within_one_percent_of_its_bounds(tmp_path):
    write_json(tmp_path / "out.json", linear(10.05), HEADER, time_bounds=(0.1, 10.0), dt=0.01)
    document = json.loads((tmp_path / "out.json").read_text())
    assert "samples_omitted" not in document and document["samples"]["t"][-1] == 10.05
