"""Bad inputs as a new user writes them: every one is refused by `ocpkit plan` with exit 2 and one `error:` line
naming the field, never a traceback and never a silent wrong answer. Also Problems built in Python."""

from __future__ import annotations

import copy
import dataclasses
import math
from typing import Any

import numpy as np
import pytest
import yaml
from helpers import REPO

import ocpkit
from ocpkit.cli.main import main
from ocpkit.errors import ScenarioError
from ocpkit.geometry.scene import Scene, Workspace
from ocpkit.problem import TimeBounds

ROBOT_DIR = REPO / "ocpkit/robots/data/industrial6"
SCENARIO = yaml.safe_load((REPO / "scenarios/paper/case1.yaml").read_text())
SPEC = yaml.safe_load((ROBOT_DIR / "spec.yaml").read_text())
DROP = object()
"""As a value: delete the key."""
SPHERE = {"center": [1.25, 0.0, 0.55], "radius": 0.3}

# (id, file, path of the changed entry, new value or DROP, text the error line must contain)
CASES = [
    # issue item 1: typos in nested keys
    ("obstacle-singular", "scenario", ("scene",), {"obstacle": [{"sphere": SPHERE}]}, "'scene.obstacle'"),
    ("time-maxx", "scenario", ("time", "maxx"), 3, "'time.maxx'"),
    ("cost-jerk-weight", "scenario", ("cost", "jerk_weight"), 1, "'cost.jerk_weight'"),
    ("sphere-radious", "scenario", ("scene", "obstacles", 0, "sphere"), {"center": [1, 0, 0], "radious": 0.2},
     "'scene.obstacles[0].sphere.radious'"),
    ("top-level-typo", "scenario", ("obstacles",), [], "unknown keys ['obstacles']"),
    ("obstacle-kind-unknown", "scenario", ("scene", "obstacles", 0), {"cone": SPHERE},
     "scene.obstacles[0] must be {sphere: ...} or {box: ...} or {cylinder: ...}"),
    ("obstacle-as-list", "scenario", ("scene", "obstacles", 0), [1.25, 0, 0.55, 0.3], "scene.obstacles[0] must be"),
    ("sphere-without-center", "scenario", ("scene", "obstacles", 0, "sphere", "center"), DROP,
     "missing 'scene.obstacles[0].sphere.center'"),
    ("obstacle-radius-negative", "scenario", ("scene", "obstacles", 0, "sphere", "radius"), -0.1,
     "scene.obstacles[0].sphere.radius must be > 0"),
    ("obstacle-radius-nan", "scenario", ("scene", "obstacles", 0, "sphere", "radius"), math.nan,
     "scene.obstacles[0].sphere.radius must be finite"),
    ("obstacle-center-short", "scenario", ("scene", "obstacles", 0, "sphere", "center"), [1, 0],
     "scene.obstacles[0].sphere.center needs 3 values"),
    ("obstacle-center-string", "scenario", ("scene", "obstacles", 0, "sphere", "center", 1), "0.0",
     "scene.obstacles[0].sphere.center[1] must be a number"),
    ("goal-inside-obstacle", "scenario", ("scene", "obstacles", 0, "sphere", "center"), [0.4, 1.09, 0.6],
     "goal configuration is in collision"),
    ("workspace-min-above-max", "scenario", ("scene", "workspace", "min", 0), 5.0, "scene.workspace: min"),
    ("workspace-without-max", "scenario", ("scene", "workspace", "max"), DROP, "missing 'scene.workspace.max'"),
    ("scene-null", "scenario", ("scene",), None, "scene must be a mapping"),
    # issue item 6: mu and booleans
    ("mu-nan", "scenario", ("cost", "mu"), math.nan, "cost.mu must be finite"),
    ("mu-inf", "scenario", ("cost", "mu"), math.inf, "cost.mu must be finite"),
    ("mu-string", "scenario", ("cost", "mu"), "0.3", "cost.mu must be a number"),
    ("mu-list", "scenario", ("cost", "mu"), [0.3], "cost.mu must be a number"),
    ("mu-null", "scenario", ("cost", "mu"), None, "cost.mu must be a number"),
    ("mu-negative", "scenario", ("cost", "mu"), -1, "cost.mu must be ≥ 0"),
    ("true-in-start", "scenario", ("start", 3), True, "start[3] must be a number, got True"),
    # start, goal, unit, name
    ("start-string", "scenario", ("start",), "0 0 0 0 0 0", "start must be a list"),
    ("start-too-short", "scenario", ("start",), [0, 0, 0], "'start' needs shape (6,)"),
    ("start-huge", "scenario", ("start",), list(range(5000)), "'start' needs shape (6,), got (5000,)"),
    ("goal-nan", "scenario", ("goal", 0), math.nan, "goal[0] must be finite"),
    ("goal-missing", "scenario", ("goal",), DROP, "missing 'goal'"),
    ("start-outside-limits", "scenario", ("start", 4), -130, "start: joint 5 (joint_5)"),
    ("unit-grad", "scenario", ("unit",), "grad", "unit must be 'deg' or 'rad'"),
    ("name-list", "scenario", ("name",), ["case"], "name must be a string"),
    # issue items 8, 9: robot
    ("robot-name-is-a-path", "scenario", ("robot",), "../data/industrial6", "unknown robot '../data/industrial6'"),
    ("robot-files-wrong-types", "scenario", ("robot",), {"urdf": 3, "spec": "s.yaml"}, "robot.urdf must be a string"),
    ("robot-without-spec", "scenario", ("robot",), {"urdf": "robot.urdf"}, "missing 'robot.spec'"),
    ("robot-number", "scenario", ("robot",), 6, "robot must be a built-in robot name or"),
    # time
    ("time-min-above-max", "scenario", ("time",), {"min": 2, "max": 1}, "0 < min ≤ max"),
    ("time-max-inf", "scenario", ("time", "max"), math.inf, "time.max must be finite"),
    ("time-min-negative", "scenario", ("time", "min"), -1, "time.min must be > 0"),
    ("time-guess-above-max", "scenario", ("time",), {"min": 1, "max": 5, "guess": 9}, "time.guess = 9.0"),
    ("time-max-below-velocity-bound", "scenario", ("time",), {"max": 0.3}, "time.max = 0.3 s is below"),
    # issue item 4: the robot spec
    ("velocity-nan", "spec", ("limits", "velocity", 0), math.nan, "limits.velocity[0] must be finite"),
    ("lower-limit-nan", "spec", ("limits", "position", "lower", 1), math.nan,
     "limits.position.lower[1] must be finite"),
    ("torque-inf", "spec", ("limits", "torque", 2), math.inf, "limits.torque[2] must be finite"),
    ("torque-rate-string", "spec", ("limits", "torque_rate", 0), "fast", "limits.torque_rate[0] must be a number"),
    ("velocity-typo", "spec", ("limits", "velocty"), [1] * 6, "'limits.velocty'"),
    ("gear-ratio-zero", "spec", ("gear_ratios", 0), 0, "gear_ratios[0] must be > 0"),
    ("gear-ratio-true", "spec", ("gear_ratios", 0), True, "gear_ratios[0] must be a number"),
    ("gear-ratios-short", "spec", ("gear_ratios",), [100, 100], "'gear_ratios' needs 6 values"),
    ("lower-above-upper", "spec", ("limits", "position", "lower", 0), 3.0, "limits.position.lower[0] = 3.0"),
    ("sphere-radius-negative", "spec", ("spheres", 0, "radius"), -0.1, "spheres[0].radius must be > 0"),
    ("spec-sphere-without-center", "spec", ("spheres", 0, "center"), DROP, "missing 'spheres[0].center'"),
    ("sphere-as-list", "spec", ("spheres", 0), ["base_link", [0, 0, 0.12], 0.24], "spheres[0] must be a mapping"),
    ("sphere-unknown-link", "spec", ("spheres", 0, "link"), "nowhere", "spheres[0] is on unknown link 'nowhere'"),
    ("friction-negative", "spec", ("friction", "coulomb", 1), -1.0, "friction.coulomb[1] must be ≥ 0"),
    ("friction-as-list", "spec", ("friction",), [0.1, 1.0, 0.05], "friction must be a mapping"),
    ("friction-without-smoothing", "spec", ("friction", "smoothing"), DROP, "missing 'friction.smoothing'"),
    ("self-collision-float-index", "spec", ("self_collision", 0, 0), 0.5, "self_collision[0][0] must be an integer"),
    ("self-collision-index-range", "spec", ("self_collision", 0, 1), 15, "self_collision index outside"),
    ("joints-empty", "spec", ("joints",), [], "joints needs at least 1 values"),
    ("joint-unknown", "spec", ("joints", 5), "joint_7", "joints not in the URDF: ['joint_7']"),
    # issue item 5: what can be known before solving
    ("torque-below-gravity", "spec", ("limits", "torque"), [t / 4 for t in SPEC["limits"]["torque"]],
     "start: joint 2 (joint_2) needs 449.8 N m to hold it against gravity, above its torque limit 350.5 N m"),
]

# (id, file, its whole text, text the error line must contain)
TEXTS = [
    ("scenario-not-utf8", "scenario", b"robot: \xff\n", "case.yaml: not UTF-8 text"),
    ("scenario-malformed", "scenario", b"robot: industrial6\nstart: [0, 0\n", "malformed YAML at line 3, column 1"),
    ("scenario-empty", "scenario", b"", "the file must be a mapping"),
    ("scenario-a-list", "scenario", b"- industrial6\n", "the file must be a mapping"),
    ("spec-malformed", "spec", b"name: x\njoints: [a\n", "spec.yaml: malformed YAML at line 3"),
    ("spec-not-utf8", "spec", b"name: \xfe\n", "spec.yaml: not UTF-8 text"),
    ("urdf-broken", "urdf", b"<robot name='x'><link name='a'/>", "robot.urdf: not a valid URDF"),
]


def changed(data: dict, path: tuple, value: Any) -> dict:
    """A deep copy of `data` with the entry at `path` set to `value` (or deleted for DROP)."""
    data = copy.deepcopy(data)
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    if value is DROP:
        del parent[path[-1]]
    else:
        parent[path[-1]] = value
    return data


def write_files(folder, scenario: dict, spec: dict) -> dict[str, Any]:
    """case.yaml on industrial6's URDF and `spec`, all in `folder`; returns the paths by file kind."""
    paths = {"scenario": folder / "case.yaml", "spec": folder / "spec.yaml", "urdf": folder / "robot.urdf"}
    paths["urdf"].write_bytes((ROBOT_DIR / "robot.urdf").read_bytes())
    paths["spec"].write_text(yaml.safe_dump(spec))
    paths["scenario"].write_text(yaml.safe_dump(scenario))
    return paths


def own_robot(scenario: dict) -> dict:
    return changed(scenario, ("robot",), {"urdf": "robot.urdf", "spec": "spec.yaml"})


def assert_one_error_line(path, capsys, expected: str) -> None:
    """`ocpkit plan path` exits with 2 and prints exactly one line, `error: ...` containing `expected`."""
    assert main(["plan", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert expected in lines[0]
    assert len(lines[0]) < 400  # a value is echoed cut short, never the whole input


@pytest.mark.parametrize("case_id, file, path, value, expected", CASES, ids=[c[0] for c in CASES])
def test_a_bad_input_is_one_error_line_naming_the_field(tmp_path, capsys, case_id, file, path, value, expected):
    scenario, spec = own_robot(SCENARIO), SPEC
    if file == "scenario":
        scenario = changed(scenario, path, value)
    else:
        spec = changed(spec, path, value)
    assert_one_error_line(write_files(tmp_path, scenario, spec)["scenario"], capsys, expected)


@pytest.mark.parametrize("case_id, file, text, expected", TEXTS, ids=[t[0] for t in TEXTS])
def test_a_broken_file_is_one_error_line(tmp_path, capsys, case_id, file, text, expected):
    paths = write_files(tmp_path, own_robot(SCENARIO), SPEC)
    paths[file].write_bytes(text)
    assert_one_error_line(paths["scenario"], capsys, expected)


def test_the_table_covers_at_least_40_inputs():
    assert len(CASES) + len(TEXTS) >= 40 and len({c[0] for c in CASES + TEXTS}) == len(CASES) + len(TEXTS)


PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case1.yaml")
OBSTACLE = PROBLEM.scene.obstacle_centers[0]
PYTHON_CASES = [
    ("start-list", {"start": [0.0] * 6}, "start must be a numpy array of numbers"),
    ("start-short", {"start": np.zeros(3)}, "start needs 6 finite joint values"),
    ("goal-inf", {"goal": np.full(6, np.inf)}, "goal needs 6 finite joint values"),
    ("mu-nan", {"mu": np.nan}, "cost.mu must be finite"),
    ("mu-string", {"mu": "0.3"}, "cost.mu must be a number"),
    ("mu-negative", {"mu": -0.1}, "cost.mu must be ≥ 0"),
    ("time-max-inf", {"time": TimeBounds(0.1, np.inf, 1.0)}, "time.max must be finite"),
    ("time-min-above-max", {"time": TimeBounds(2.0, 1.0, 1.0)}, "time bounds need 0 < min ≤ max"),
    ("time-guess-outside", {"time": TimeBounds(0.1, 5.0, 10.0)}, "time.guess = 10.0 must lie in [0.1, 5.0]"),
    ("radius-negative", {"scene": Scene(OBSTACLE[None], np.array([-0.1]))},
     "scene.obstacles[0].sphere.radius must be > 0"),
    ("center-nan", {"scene": Scene(np.full((1, 3), np.nan), np.array([0.1]))},
     "scene.obstacles[0].sphere.center[0] must be finite"),
    ("centers-shape", {"scene": Scene(np.zeros((1, 2)), np.array([0.1]))}, "obstacle centres need shape (S, 3)"),
    ("workspace-inverted", {"scene": Scene(workspace=Workspace(np.ones(3), np.zeros(3)))}, "scene.workspace: min"),
    ("workspace-nan", {"scene": Scene(workspace=Workspace(np.full(3, np.nan), np.ones(3)))},
     "scene.workspace.min[0] must be finite"),
]


@pytest.mark.parametrize("case_id, changes, expected", PYTHON_CASES, ids=[c[0] for c in PYTHON_CASES])
def test_plan_refuses_a_python_problem_with_bad_numbers_naming_the_field(case_id, changes, expected):
    with pytest.raises(ScenarioError) as error:
        # an unregistered planner: a problem that wrongly passed validation fails fast, with another error
        ocpkit.plan(dataclasses.replace(PROBLEM, **changes), planner="not-a-planner")
    assert expected in str(error.value)
