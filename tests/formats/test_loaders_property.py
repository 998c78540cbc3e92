"""Property: whatever a scenario or robot spec file holds, its loader returns or raises an OcpkitError (which the
CLI prints as one line); no other exception escapes."""

from __future__ import annotations

import copy
import math
from typing import Any

import pytest
import yaml
from helpers import REPO
from hypothesis import given, settings
from hypothesis import strategies as st

from ocpkit import load_robot, load_scenario
from ocpkit.errors import OcpkitError
from ocpkit.formats.scenario import problem_from_dict

ROBOT_DIR = REPO / "ocpkit/robots/data/industrial6"
SCENARIO = yaml.safe_load((REPO / "scenarios/paper/case1.yaml").read_text())
SPEC = yaml.safe_load((ROBOT_DIR / "spec.yaml").read_text())
KEYS = ["robot", "unit", "start", "goal", "scene", "obstacles", "sphere", "center", "radius", "workspace", "min",
        "max", "time", "guess", "cost", "mu", "urdf", "spec", "name", "joints", "limits", "position", "lower",
        "upper", "velocity", "torque", "friction", "smoothing", "spheres", "link", "self_collision"]
"""Real key names, so that generated mappings also reach the checks below the top level."""
FAST = settings(max_examples=200, deadline=None, derandomize=True)

scalars = st.one_of(st.none(), st.booleans(), st.integers(), st.integers(-10**400, 10**400),
                    st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([math.nan, math.inf, -math.inf]),
                    st.text(max_size=12), st.sampled_from(KEYS + ["industrial6", "deg", "rad", "link_1"]))
keys = st.one_of(st.sampled_from(KEYS), st.text(max_size=8), st.integers(), st.none(), st.booleans())
nested = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=8),
                                                       st.dictionaries(keys, inner, max_size=6)), max_leaves=30)
huge = st.builds(lambda item, count: [item] * count, scalars, st.integers(0, 5000))
anything = st.one_of(nested, huge)


def paths(data: Any, prefix: tuple = ()) -> list[tuple]:
    """Every entry's path in nested dicts and lists, e.g. ('scene', 'obstacles', 0, 'sphere', 'radius')."""
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else []
    return [p for key, value in items for p in [(*prefix, key), *paths(value, (*prefix, key))]]


def replaced(data: dict, path: tuple, value: Any) -> dict:
    data = copy.deepcopy(data)
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    parent[path[-1]] = value
    return data


def loads_or_refuses(load, *args) -> None:
    try:
        load(*args)
    except OcpkitError:
        pass


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """A folder with industrial6's URDF; the tests write spec.yaml and case.yaml next to it."""
    path = tmp_path_factory.mktemp("robot")
    (path / "robot.urdf").write_bytes((ROBOT_DIR / "robot.urdf").read_bytes())
    return path


def load_spec(folder, spec: Any) -> None:
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)  # libyaml: fast on huge lists
    (folder / "spec.yaml").write_text(yaml.dump(spec, Dumper=dumper))
    load_robot({"urdf": "robot.urdf", "spec": "spec.yaml"}, folder)


@FAST
@given(data=anything)
def test_any_data_as_a_scenario(folder, data):
    loads_or_refuses(problem_from_dict, data, folder)


@FAST
@given(path=st.sampled_from(paths(SCENARIO)), value=anything)
def test_any_data_in_one_field_of_a_valid_scenario(folder, path, value):
    loads_or_refuses(problem_from_dict, replaced(SCENARIO, path, value), folder)


@FAST
@given(text=st.one_of(st.binary(max_size=200), st.text(max_size=200).map(str.encode)))
def test_any_bytes_as_a_scenario_file(folder, text):
    (folder / "case.yaml").write_bytes(text)
    loads_or_refuses(load_scenario, folder / "case.yaml")


@FAST
@given(data=anything)
def test_any_data_as_a_robot_spec(folder, data):
    loads_or_refuses(load_spec, folder, data)


@FAST
@given(path=st.sampled_from(paths(SPEC)), value=anything)
def test_any_data_in_one_field_of_a_valid_robot_spec(folder, path, value):
    loads_or_refuses(load_spec, folder, replaced(SPEC, path, value))
