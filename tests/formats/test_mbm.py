"""`ocpkit data mbm` on a stand-in vamp-planner sdist (the real MoveIt pair of tests/data, no network): unpacked
and converted once, reused on the second run, licence kept, bad archives refused; the shipped subset is complete.
The real download is the slow test at the end."""

from __future__ import annotations

import io
import tarfile
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml
from helpers import REPO
from outside_check import obstacle_distance

from ocpkit.cli.main import main
from ocpkit.errors import OcpkitError
from ocpkit.formats.mbm import MBM_JOINTS, SCENES, VAMP_VERSION, DataError, fetch_mbm
from ocpkit.formats.scenario import load_scenario
from ocpkit.formats.schema import SCENARIO, check
from ocpkit.robots import builtin_robots

DATA = REPO / "tests/data/moveit"
SHIPPED = REPO / "scenarios/mbm"


def tar_bytes(files: dict[str, bytes], mode: str) -> bytes:
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode=mode) as archive:
        for name, content in files.items():
            info = tarfile.TarInfo(name)
            info.size = len(content)
            archive.addfile(info, io.BytesIO(content))
    return buffer.getvalue()


def fake_sdist(directory: Path, problems: dict[str, bytes], robot: str = "panda",
               files: dict[str, bytes] | None = None) -> Path:
    """A vamp_planner-VERSION.tar.gz in `directory` holding LICENSE.txt, resources/<robot>/problems.tar.bz2 and
    `files` (name → content) in resources/<robot>/."""
    inner = tar_bytes(problems, "w:bz2")
    root = f"vamp_planner-{VAMP_VERSION}"
    outer = tar_bytes({f"{root}/LICENSE.txt": b"Apache License 2.0 (stand-in)\n",
                       f"{root}/resources/{robot}/problems.tar.bz2": inner,
                       **{f"{root}/resources/{robot}/{name}": content for name, content in (files or {}).items()}},
                      "w:gz")
    directory.mkdir(parents=True, exist_ok=True)
    path = directory / f"{root}.tar.gz"
    path.write_bytes(outer)
    return path


def one_problem() -> dict[str, bytes]:
    folder = "problems/table_pick_panda"
    return {f"{folder}/scene0001.yaml": (DATA / "mbm_table_pick_panda_scene0001.yaml").read_bytes(),
            f"{folder}/request0001.yaml": (DATA / "mbm_table_pick_panda_request0001.yaml").read_bytes()}


def test_a_cached_sdist_is_unpacked_converted_and_reused(tmp_path, capsys):
    fake_sdist(tmp_path, one_problem())
    first = fetch_mbm("panda", tmp_path, progress=False)
    target = tmp_path / "panda/table_pick/0001.yaml"
    assert (first.written, first.kept) == (1, 0) and target.is_file()
    assert (tmp_path / "LICENSE-vamp.txt").read_text().startswith("Apache License")
    text = target.read_text()
    assert text.startswith("# MotionBenchMaker problem from vamp-planner") and "Apache License 2.0" in text
    scenario = yaml.safe_load(text)
    check(scenario, SCENARIO, OcpkitError)
    assert scenario["name"] == "table_pick_0001" and scenario["robot"] == "panda" and len(scenario["start"]) == 7
    assert scenario == yaml.safe_load((SHIPPED / "panda/table_pick/0001.yaml").read_text())
    assert main(["data", "mbm", "--robot", "panda", "--dir", str(tmp_path)]) == 0  # second run: nothing redone
    assert "0 scenarios written, 1 already there" in capsys.readouterr().out
    assert target.read_text() == text


def test_a_robot_not_built_in_is_imported_from_the_sdist_and_named_by_its_spec(tmp_path, capsys):
    """Fetch: vamp's URDF, SRDF and spherized URDF imported once into fetch/robot/, every scenario naming that spec
    relative to its own folder, validated against it; a scenario written before, naming the robot, is redone."""
    vamp = REPO / "tests/robots/vamp"
    folder = "problems/box_fetch"
    problem = {f"{folder}/scene0001.yaml": (DATA / "mbm_box_fetch_scene0001.yaml").read_bytes(),
               f"{folder}/request0001.yaml": (DATA / "mbm_box_fetch_request0001.yaml").read_bytes()}
    files = {name: (vamp / name).read_bytes() for name in ("fetch.urdf", "fetch.srdf", "fetch_spherized.urdf")}
    fake_sdist(tmp_path, problem, "fetch", files)
    target = tmp_path / "fetch/box/0001.yaml"
    target.parent.mkdir(parents=True)
    target.write_text("name: box_0001\nrobot: fetch\n")  # an earlier conversion, by name
    summary = fetch_mbm("fetch", tmp_path, progress=False)
    assert (summary.written, summary.kept, summary.invalid) == (1, 0, 0)
    assert yaml.safe_load(target.read_text())["robot"] == {"spec": "../robot/spec.yaml"}
    scenario = load_scenario(target)
    assert list(scenario.robot.joint_names) == MBM_JOINTS["fetch"] and len(scenario.robot.sphere_radius) == 111
    assert main(["data", "mbm", "--robot", "fetch", "--dir", str(tmp_path)]) == 0
    assert "0 scenarios written, 1 already there" in capsys.readouterr().out


def test_an_archive_member_outside_the_cache_is_refused(tmp_path):
    fake_sdist(tmp_path, {**one_problem(), "../escape.yaml": b"x: 1\n"})
    with pytest.raises(DataError, match="refusing the archive member '../escape.yaml'"):
        fetch_mbm("panda", tmp_path, progress=False)
    assert not (tmp_path / "panda/escape.yaml").exists() and not (tmp_path / "escape.yaml").exists()


def test_a_broken_or_foreign_archive_and_an_unknown_robot_are_named(tmp_path, capsys):
    (tmp_path / f"vamp_planner-{VAMP_VERSION}.tar.gz").write_bytes(b"not a tar file")
    with pytest.raises(DataError, match="cannot unpack resources/panda/problems.tar.bz2 .*delete the file"):
        fetch_mbm("panda", tmp_path, progress=False)
    fake_sdist(tmp_path, one_problem())
    with pytest.raises(DataError, match="has no resources/ur5/problems.tar.bz2"):
        fetch_mbm("ur5", tmp_path, progress=False)
    with pytest.raises(DataError, match="unknown MBM robot 'kuka'"):
        fetch_mbm("kuka", tmp_path)
    assert main(["data", "mbm", "--robot", "ur5", "--dir", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith("error: ")


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_the_shipped_subset_has_three_problems_per_scene(robot):
    assert (SHIPPED / "LICENSE-vamp.txt").read_text().lstrip().startswith("Apache License")
    for scene in SCENES:
        files = sorted((SHIPPED / robot / scene).glob("*.yaml"))
        assert [f.name for f in files] == ["0001.yaml", "0002.yaml", "0003.yaml"]
        for file in files:
            text = file.read_text()
            assert "Apache License 2.0" in text.splitlines()[0]
            scenario = yaml.safe_load(text)
            check(scenario, SCENARIO, OcpkitError)
            assert scenario["robot"] == robot and len(scenario["goal"]) == len(MBM_JOINTS[robot])
            assert scenario["scene"]["obstacles"] and "workspace" not in scenario["scene"]


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_the_shipped_subset_is_valid_for_the_built_in_robot(robot):
    if robot not in builtin_robots():
        pytest.skip(f"{robot} is not built in on this branch")
    for file in sorted((SHIPPED / robot).glob("*/*.yaml")):
        load_scenario(file)


@pytest.mark.slow
@pytest.mark.network  # pip downloads vamp-planner's sdist from PyPI
def test_real_download_from_a_clean_cache(tmp_path, capsys):
    """pip download of the real sdist (about 65 MB), both robots of the acceptance, 700 problems each."""
    for robot in ("panda", "ur5"):
        assert main(["data", "mbm", "--robot", robot, "--dir", str(tmp_path)]) == 0
        assert "700 scenarios written, 0 already there" in capsys.readouterr().out
        for scene in SCENES:
            assert len(list((tmp_path / robot / scene).glob("*.yaml"))) == 100
        shipped = yaml.safe_load((SHIPPED / robot / "cage/0003.yaml").read_text())
        assert yaml.safe_load((tmp_path / robot / "cage/0003.yaml").read_text()) == shipped
        clearance = start_goal_clearance(tmp_path, robot)
        assert len(clearance) == 1400 and (clearance < 0).sum() <= 2 and clearance.min() > -0.01


def start_goal_clearance(cache: Path, robot: str) -> np.ndarray:
    """Smallest clearance (m) of each converted start and goal against its scene, for vamp's own spherized model of
    the robot (read from the cached sdist, joints set by name in pinocchio; distances of tests/outside_check.py).
    MBM's starts and goals are valid, so a wrong pose composition or size convention would show as overlaps; the
    spheres approximate the meshes MBM checked, so a few millimetres of overlap are allowed on a couple of them."""
    with tarfile.open(cache / f"vamp_planner-{VAMP_VERSION}.tar.gz") as sdist:
        name = f"vamp_planner-{VAMP_VERSION}/resources/{robot}/{robot}_spherized.urdf"
        urdf = sdist.extractfile(name).read().decode()
    model = pin.buildModelFromXML(urdf)
    geometry = pin.buildGeomFromUrdfString(model, urdf, pin.COLLISION)
    data, geometry_data = model.createData(), geometry.createData()
    radii = np.array([g.geometry.radius for g in geometry.geometryObjects])
    smallest = []
    for file in sorted(cache.glob(f"{robot}/*/*.yaml")):
        scenario = yaml.load(file.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        for values in (scenario["start"], scenario["goal"]):
            q = pin.neutral(model)
            for joint, value in zip(MBM_JOINTS[robot], values):
                q[model.joints[model.getJointId(joint)].idx_q] = value
            pin.updateGeometryPlacements(model, data, geometry, geometry_data, q)
            centers = np.array([placement.translation for placement in geometry_data.oMg])
            smallest.append(min((obstacle_distance(o, centers) - radii).min() for o in scenario["scene"]["obstacles"]))
    return np.array(smallest)


def test_a_cache_folder_that_cannot_be_made_is_named(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(DataError, match=r"cannot write the MBM cache: .*file/mbm"):
        fetch_mbm("panda", tmp_path / "file" / "mbm", progress=False)
