"""`ocpkit robot import` on a small URDF with a prismatic joint; spec fields urdf, locked and base; their errors."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

from ocpkit.cli.main import main
from ocpkit.errors import RobotError
from ocpkit.geometry.clearances import sphere_centers
from ocpkit.robots import load_robot
from ocpkit.robots.importer import MOTOR_SPEED, TORQUE_RATE_PER_SECOND

# base --(revolute z, 0.3 m up)--> arm --(prismatic x)--> slider --(fixed)--> tool; --(revolute)--> spare
SMALL_URDF = """<robot name="slide">
  <link name="base"><collision><geometry><sphere radius="0.1"/></geometry></collision>
    <inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><collision><origin xyz="0.2 0 0"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision>
    <inertial><origin xyz="0.2 0 0"/><mass value="2"/>
      <inertia ixx="0.01" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="slider"><collision><origin xyz="0.05 0 0"/><geometry><sphere radius="0.04"/></geometry></collision>
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tool"><collision><geometry><sphere radius="0.03"/></geometry></collision>
    <inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="spare"><collision><origin xyz="0 0 0.2"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0.42 -0.3 0.3"/><geometry><sphere radius="0.03"/></geometry></collision>
    <inertial><mass value="0.2"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-2" upper="2" velocity="1.5" effort="40"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="slider"/><origin xyz="0.4 0 0"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.3" velocity="0.2" effort="100"/></joint>
  <joint name="mount" type="fixed"><parent link="slider"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>
  <joint name="flap" type="revolute"><parent link="base"/><child link="spare"/><origin xyz="0 0.3 0"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="5"/></joint>
</robot>
"""
SRDF = '<robot name="slide"><disable_collisions link1="base" link2="tool" reason="Never"/></robot>'


@pytest.fixture
def small(tmp_path) -> Path:
    (tmp_path / "slide.urdf").write_text(SMALL_URDF)
    (tmp_path / "slide.srdf").write_text(SRDF)
    return tmp_path


def run_import(folder: Path, *options: str) -> dict:
    assert main(["robot", "import", str(folder / "slide.urdf"), "--out", str(folder / "out"), *options]) == 0
    return yaml.safe_load((folder / "out/spec.yaml").read_text())


def test_import_reads_limits_and_fills_the_documented_rules(small, capsys):
    spec = run_import(small, "--joints", "turn,slide", "--srdf", str(small / "slide.srdf"))
    assert spec["urdf"] == "../slide.urdf" and spec["joints"] == ["turn", "slide"]
    lim = spec["limits"]
    assert lim["position"] == {"lower": [-2.0, 0.0], "upper": [2.0, 0.3]}
    assert lim["velocity"] == [1.5, 0.2] and lim["torque"] == [40.0, 100.0]
    assert lim["torque_rate"] == [TORQUE_RATE_PER_SECOND * 40, TORQUE_RATE_PER_SECOND * 100]
    assert spec["gear_ratios"] == [np.floor(MOTOR_SPEED / 1.5), np.floor(MOTOR_SPEED / 0.2)]
    assert spec["friction"]["viscous"] == [0.0, 0.0] and spec["friction"]["coulomb"] == [0.0, 0.0]
    links = [s["link"] for s in spec["spheres"]]
    assert links == ["base", "arm", "slider", "tool", "spare", "spare"]
    # joints: base and spare (locked: merged into base) on the universe, arm on turn, slider and tool on slide.
    # Adjacent (parent and child joint): base/arm, arm/spare, arm/slider, arm/tool; base/tool disabled by the
    # SRDF; the second spare sphere sits on the slider's at q = 0: slider/spare dropped as touching
    assert spec["self_collision"] == [[0, 2], [3, 4], [3, 5]]
    out = capsys.readouterr().out
    assert "disabled in the SRDF: base/tool" in out and "touching at the zero pose: slider/spare" in out


def test_imported_spec_loads_with_a_prismatic_joint_and_matches_pinocchio(small):
    run_import(small, "--joints", "turn,slide", "--locked", "flap=0.5")
    robot = load_robot({"spec": "out/spec.yaml"}, small)  # the spec names its URDF
    reference = pin.buildModelFromUrdf(str(small / "slide.urdf"))
    values = {"turn": 0.7, "slide": 0.2, "flap": 0.5}
    full_q = np.array([values[reference.names[j]] for j in range(1, reference.njoints)])
    data = reference.createData()
    pin.framesForwardKinematics(reference, data, full_q)
    tool = data.oMf[reference.getFrameId("tool")].translation
    q = np.array([values["turn"], values["slide"]])
    np.testing.assert_allclose(sphere_centers(robot, q)[3], tool, atol=1e-12)
    spare = data.oMf[reference.getFrameId("spare")].act(np.array([0, 0, 0.2]))
    np.testing.assert_allclose(sphere_centers(robot, q)[4], spare, atol=1e-12)  # locked at 0.5 rad
    qd, qdd = {"turn": 0.3, "slide": -0.1, "flap": 0.0}, {"turn": 1.0, "slide": 0.5, "flap": 0.0}
    order = [reference.names[j] for j in range(1, reference.njoints)]
    full_tau = dict(zip(order, pin.rnea(reference, data, full_q, np.array([qd[n] for n in order]),
                                        np.array([qdd[n] for n in order]))))
    tau = pin.rnea(robot.model, robot.model.createData(), q, np.array([qd["turn"], qd["slide"]]),
                   np.array([qdd["turn"], qdd["slide"]]))
    np.testing.assert_allclose(tau, [full_tau["turn"], full_tau["slide"]], atol=1e-10)


def test_overrides_and_base_pose(small):
    spec = run_import(small, "--joints", "turn,slide", "--set", "torque_rate.turn=123", "--set", "gear_ratio.slide=7")
    assert spec["limits"]["torque_rate"][0] == 123 and spec["gear_ratios"][1] == 7
    spec["base"] = {"xyz": [1.0, 2.0, 3.0], "rpy": [0.0, 0.0, np.pi / 2]}
    (small / "out/spec.yaml").write_text(yaml.safe_dump(spec))
    robot = load_robot({"spec": "out/spec.yaml"}, small)
    # the tool at q = 0: 0.4 + 0.1 m along the arm's x, 0.3 m up; the base turns x into y
    np.testing.assert_allclose(sphere_centers(robot, np.zeros(2))[3], [1.0, 2.5, 3.3], atol=1e-12)


@pytest.mark.parametrize("options, message", [
    (["--joints", "turn,nope"], "--joints: 'nope' is not a joint of"),
    (["--set", "torque.turn"], "--set: expected NAME=NUMBER, got 'turn'"),
    (["--set", "speed.turn=3"], "--set speed.…: unknown field"),
    (["--set", "torque.flap=3", "--joints", "turn,slide"], "--set torque.flap: not a planned joint"),
    (["--locked", "flap"], "--locked: expected NAME=NUMBER"),
    (["--spheres", "nothing.urdf"], "--spheres: 'nothing.urdf' is neither 'urdf', 'fit' nor a file"),
    (["--budget", "0"], "--budget must be ≥ 1"),
    (["--out", "/proc/none"], "--out: cannot write /proc/none/spec.yaml"),
])
def test_import_errors_are_one_line_naming_the_option(small, capsys, options, message):
    out = [] if "--out" in options else ["--out", str(small / "out")]
    assert main(["robot", "import", str(small / "slide.urdf"), *out, *options]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and message in err


def test_a_joint_without_limits_is_named(small, capsys):
    (small / "slide.urdf").write_text(SMALL_URDF.replace('velocity="0.2" effort="100"', 'velocity="0" effort="100"'))
    assert main(["robot", "import", str(small / "slide.urdf"), "--out", str(small / "out")]) == 2
    assert "joint slide: the URDF gives no velocity limit (0.0); set one with --set velocity.slide=VALUE" in \
        capsys.readouterr().err


@pytest.mark.parametrize("change, message", [
    ({"locked": {"nope": 0.1}}, "locked.nope: not a movable joint of the URDF"),
    ({"locked": {"turn": 0.1}}, "locked.turn: a planned joint (in 'joints') cannot be locked"),
    ({"locked": {"flap": "x"}}, "locked.flap must be a number, got 'x'"),
    ({"locked": [1]}, "locked must be a mapping of names to values, each a number"),
    ({"base": {"xyz": [1, 2]}}, "base.xyz needs 3 values"),
    ({"base": {"pos": [1, 2, 3]}}, "unknown keys ['base.pos']"),
    ({"urdf": 3}, "urdf must be a URDF path"),
])
def test_spec_errors_name_the_field(small, change, message):
    spec = run_import(small, "--joints", "turn,slide")
    (small / "out/spec.yaml").write_text(yaml.safe_dump({**spec, **change}))
    with pytest.raises(RobotError, match=re.escape(message)):
        load_robot({"spec": "out/spec.yaml"}, small)


def test_a_spec_without_urdf_needs_the_files_form(small):
    spec = run_import(small, "--joints", "turn,slide")
    del spec["urdf"]
    (small / "out/spec.yaml").write_text(yaml.safe_dump(spec))
    with pytest.raises(RobotError, match=re.escape("missing 'urdf' (the spec names no URDF")):
        load_robot({"spec": "out/spec.yaml"}, small)
    assert load_robot({"spec": "out/spec.yaml", "urdf": "slide.urdf"}, small).n == 2


def test_spheres_from_another_urdf_move_onto_the_nearest_link(small):
    """A sphere on a link the robot's URDF lacks lands on its nearest ancestor, at the same place."""
    spherized = SMALL_URDF.replace('<link name="tool">', '<link name="tip"><collision><origin xyz="0.01 0 0"/>'
                                   '<geometry><sphere radius="0.02"/></geometry></collision></link><link name="tool">')
    spherized = spherized.replace("</robot>", '<joint name="tip_mount" type="fixed"><parent link="tool"/>'
                                  '<child link="tip"/><origin xyz="0.05 0 0" rpy="0 0 1.5707963267948966"/></joint>'
                                  "</robot>")
    (small / "spherized.urdf").write_text(spherized)
    spec = run_import(small, "--joints", "turn,slide", "--spheres", str(small / "spherized.urdf"))
    assert [s for s in spec["spheres"] if s["radius"] == 0.02] == [{"link": "tool", "center": [0.05, 0.01, 0.0],
                                                                     "radius": 0.02}]


def test_show_draws_a_png(small, tmp_path):
    run_import(small, "--joints", "turn,slide")
    assert main(["robot", "show", str(small / "out"), "--out", str(tmp_path / "s.png")]) == 0
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_import_copies_nothing_and_names_urdf_relative(small, tmp_path):
    target = tmp_path / "elsewhere" / "deep"
    target.mkdir(parents=True)
    shutil.copy(small / "slide.urdf", tmp_path / "slide2.urdf")
    assert main(["robot", "import", str(tmp_path / "slide2.urdf"), "--out", str(target), "--joints", "turn"]) == 0
    assert yaml.safe_load((target / "spec.yaml").read_text())["urdf"] == "../../slide2.urdf"


def test_import_with_fitted_spheres_reports_each_link(small, capsys):
    spec = run_import(small, "--joints", "turn,slide", "--spheres", "fit", "--budget", "3")
    rows = {line.split()[0]: line.split("|")[1].split() for line in capsys.readouterr().out.splitlines()
            if line.split() and line.split()[0] in ("base", "arm", "slider", "tool", "spare")}
    assert set(rows) == {"base", "arm", "slider", "tool", "spare"}
    assert all(1 <= int(count) <= 3 and float(cover) >= 99.0 for count, cover, _ in rows.values())
    assert sum(int(count) for count, _, _ in rows.values()) == len(spec["spheres"])
