"""The MotionBenchMaker problems (Chamzas et al. 2022) as scenario files, from the vamp-planner source distribution.

`fetch_mbm(robot, directory)` downloads the `vamp-planner` sdist with pip (`pip download --no-deps --no-binary
vamp-planner`: the .tar.gz itself, nothing is built; pip only prepares its metadata), takes
resources/<robot>/problems.tar.bz2 and vamp's LICENSE out of it with tarfile, unpacks the MoveIt YAML pairs
(problems/<scene>_<robot>/sceneNNNN.yaml + requestNNNN.yaml) and converts each pair with `ocpkit.formats.moveit` to
DIR/<robot>/<scene>/NNNN.yaml. Every step is skipped when its result is already in DIR, so a second run only
checks. Layout of DIR (default ~/.cache/ocpkit/mbm, or $XDG_CACHE_HOME/ocpkit/mbm):

    vamp_planner-VERSION.tar.gz        the sdist, as downloaded
    LICENSE-vamp.txt                   vamp's Apache-2.0 licence (it covers the problem files)
    <robot>/moveit/problems/...        the MoveIt YAML pairs, as shipped
    <robot>/<scene>/NNNN.yaml          the scenarios
    <robot>/invalid.txt                problems ocpkit's model of the robot rejects, with the reason
    <robot>/robot/spec.yaml            a robot ocpkit does not build in (Fetch), imported from vamp's URDF, SRDF and
                                       spherized URDF (beside it) as `ocpkit robot import` does; its scenarios
                                       name it as `robot: {spec: ../robot/spec.yaml}`

MBM scenes have no workspace box: their tables, shelves and cages are obstacles, and MoveIt's
`workspace_parameters` bound a mobile base's virtual joint, not the arm.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path

import yaml
from tqdm import tqdm

from ocpkit.errors import OcpkitError, RobotError
from ocpkit.formats.moveit import read_moveit, resolve_robot, scenario_text
from ocpkit.formats.scenario import load_scenario
from ocpkit.formats.schema import one_line
from ocpkit.robots import load_robot
from ocpkit.robots.importer import import_urdf, spec_header, write_spec
from ocpkit.robots.sphere_models import sphere_model

VAMP_VERSION = "0.6.4"
"""The vamp-planner release whose problems.tar.bz2 files are read (pinned: the same problems on every machine)."""
SCENES = ("table_pick", "table_under_pick", "box", "bookshelf_small", "bookshelf_tall", "bookshelf_thin", "cage")
ROBOTS = ("panda", "ur5", "fetch")
MBM_JOINTS = {
    "panda": [f"panda_joint{i}" for i in range(1, 8)],
    "ur5": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
            "wrist_3_joint"],
    "fetch": ["torso_lift_joint", "shoulder_pan_joint", "shoulder_lift_joint", "upperarm_roll_joint",
              "elbow_flex_joint", "forearm_roll_joint", "wrist_flex_joint", "wrist_roll_joint"],
}
"""The planned joints of each MBM robot in MoveIt's group order, for when ocpkit has no such built-in robot."""
NOTICE = ("MotionBenchMaker problem from vamp-planner {version} (resources/{robot}/problems.tar.bz2; Apache License "
          "2.0, see LICENSE-vamp.txt),",
          "modified: converted from MoveIt YAML to an ocpkit scenario by `ocpkit data mbm`.")
"""The licence notice at the top of every converted file (format with version and robot)."""


class DataError(OcpkitError):
    """A data set cannot be obtained or unpacked."""


@dataclass(frozen=True)
class MbmSummary:
    """What `fetch_mbm` did: scenario files written now, found already there, and problems rejected by ocpkit's
    model of the robot (None: the robot is not built in here, nothing was validated)."""

    directory: Path
    written: int
    kept: int
    invalid: int | None


def default_directory() -> Path:
    """~/.cache/ocpkit/mbm, or $XDG_CACHE_HOME/ocpkit/mbm."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "ocpkit" / "mbm"


def fetch_mbm(robot: str, directory: Path | None = None, progress: bool = True) -> MbmSummary:
    """Download (once), unpack (once) and convert (each missing file) the 700 MBM problems of `robot`."""
    if robot not in ROBOTS:
        raise DataError(f"unknown MBM robot {robot!r}; choose one of {', '.join(ROBOTS)}")
    directory = Path(directory or default_directory()).expanduser()
    try:
        sdist = download_vamp(directory)
        problems = unpack_problems(sdist, robot, directory)
        spec = None if _built_in(robot) else import_robot(sdist, robot, directory / robot / "robot")
        return convert_problems(robot, problems, directory / robot, progress, spec)
    except OSError as exc:  # a folder that cannot be written, a full disk
        raise DataError(f"cannot write the MBM cache: {exc.filename or directory}: {exc.strerror}") from exc


def download_vamp(directory: Path) -> Path:
    """The vamp-planner sdist in `directory`, downloaded with pip unless it is already there."""
    target = directory / f"vamp_planner-{VAMP_VERSION}.tar.gz"
    if target.is_file():
        return target
    directory.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=directory) as scratch:
        print(f"downloading the vamp-planner {VAMP_VERSION} source distribution (about 65 MB) with pip ...",
              file=sys.stderr)
        command = [sys.executable, "-m", "pip", "download", "--no-deps", "--no-binary", "vamp-planner",
                   f"vamp-planner=={VAMP_VERSION}", "-d", scratch, "--quiet"]
        done = subprocess.run(command, capture_output=True, text=True)
        found = list(Path(scratch).glob("vamp_planner-*.tar.gz"))
        if done.returncode != 0 or not found:
            tail = " ".join((done.stderr or done.stdout).strip().splitlines()[-3:])
            raise DataError(f"pip could not download vamp-planner {VAMP_VERSION}: {tail or 'no sdist found'}")
        shutil.move(found[0], target)
    return target


def unpack_problems(sdist: Path, robot: str, directory: Path) -> Path:
    """The folder of `robot`'s MoveIt problem pairs, unpacked from the sdist unless already there; vamp's licence
    is copied beside them."""
    moveit = directory / robot / "moveit"
    done = moveit / ".complete"
    if done.is_file():
        return moveit / "problems"
    inner = f"resources/{robot}/problems.tar.bz2"
    try:
        with tarfile.open(sdist) as outer:
            members = _members(outer)
            if inner not in members or "LICENSE.txt" not in members:
                raise DataError(f"{sdist} has no {inner} or LICENSE.txt: not a vamp-planner sdist?")
            (directory / "LICENSE-vamp.txt").write_bytes(outer.extractfile(members["LICENSE.txt"]).read())
            with tarfile.open(fileobj=outer.extractfile(members[inner]), mode="r:bz2") as problems:
                _extract(problems, moveit)
    except (tarfile.TarError, OSError, EOFError) as exc:
        raise DataError(f"cannot unpack {inner} from {sdist}: {one_line(str(exc))} (delete the file to download it "
                        "again)") from exc
    done.touch()
    return moveit / "problems"


def _members(sdist: tarfile.TarFile) -> dict[str, tarfile.TarInfo]:
    """The sdist's regular files by their path below its top folder (resources/..., LICENSE.txt)."""
    return {Path(*Path(m.name).parts[1:]).as_posix(): m for m in sdist.getmembers() if m.isfile()}


def _built_in(robot: str) -> bool:
    """Whether ocpkit has `robot` built in."""
    try:
        load_robot(robot)
    except RobotError:
        return False
    return True


def import_robot(sdist: Path, robot: str, folder: Path) -> Path:
    """folder/spec.yaml of `robot` (not built in here), imported unless already there: vamp's <robot>.urdf,
    <robot>.srdf (its pairs that never collide) and <robot>_spherized.urdf (its spheres) taken out of the sdist into
    `folder`, MBM_JOINTS[robot] planned, the other joints locked at 0 (ocpkit.robots.importer)."""
    spec = folder / "spec.yaml"
    if spec.is_file():
        return spec
    names = (f"{robot}.urdf", f"{robot}.srdf", f"{robot}_spherized.urdf")
    try:
        with tarfile.open(sdist) as outer:
            members = _members(outer)
            missing = [n for n in names if f"resources/{robot}/{n}" not in members]
            if missing:
                raise DataError(f"{sdist} has no resources/{robot}/{missing[0]}: not a vamp-planner sdist?")
            folder.mkdir(parents=True, exist_ok=True)
            for name in names:
                (folder / name).write_bytes(outer.extractfile(members[f"resources/{robot}/{name}"]).read())
    except (tarfile.TarError, EOFError) as exc:
        raise DataError(f"cannot read {robot}'s URDF from {sdist}: {one_line(str(exc))}") from exc
    urdf, srdf, spherized = (folder / name for name in names)
    spheres, _ = sphere_model(urdf, str(spherized))
    imported = import_urdf(urdf, spheres, folder, joints=MBM_JOINTS[robot], srdf=srdf)
    return write_spec(imported, folder, spec_header(imported, urdf, spherized.name, "`ocpkit data mbm`"))


def _extract(archive: tarfile.TarFile, target: Path) -> None:
    """Extract the regular files of `archive` below `target`, refusing any path that leaves it."""
    target.mkdir(parents=True, exist_ok=True)
    root = target.resolve()
    for member in archive.getmembers():
        path = (target / member.name).resolve()
        if not path.is_relative_to(root):
            raise DataError(f"refusing the archive member {member.name!r}: outside {target}")
        if member.isfile():
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(archive.extractfile(member).read())


def convert_problems(robot: str, problems: Path, out: Path, progress: bool = True,
                     spec: Path | None = None) -> MbmSummary:
    """Convert every problems/<scene>_<robot>/sceneNNNN.yaml + requestNNNN.yaml to out/<scene>/NNNN.yaml (files
    already there are kept unless they name another robot entry) for `robot` built in, or for the robot of `spec`
    (a spec.yaml); load each (validation) and list the rejected ones in out/invalid.txt. A robot neither built in
    nor given by a spec is written by name in MBM's joint order, unvalidated."""
    pairs = sorted((scene, request) for scene in SCENES
                   for request in (problems / f"{scene}_{robot}").glob("request*.yaml"))
    if not pairs:
        raise DataError(f"no MBM problems under {problems}")
    written = kept = 0
    rejected: list[str] = []
    entries: dict[str, tuple] = {}  # per scene folder: resolve_robot's answer (a spec path is relative to it)
    for scene, request in tqdm(pairs, desc=f"MBM {robot}", unit="problem", disable=not progress):
        if scene not in entries:
            entries[scene] = _robot_entry(robot, spec, out / scene)
        field, joints, loaded = entries[scene]
        number = request.stem.removeprefix("request")
        target = out / scene / f"{number}.yaml"
        if _names(target, field):
            kept += 1
        else:
            conversion = read_moveit(request.with_name(f"scene{number}.yaml"), request, joints, field,
                                     f"{scene}_{number}")
            source = f"{robot}/moveit/problems/{scene}_{robot}/{{scene,request}}{number}.yaml"
            notice = [line.format(version=VAMP_VERSION, robot=robot) for line in NOTICE]
            target.parent.mkdir(parents=True, exist_ok=True)
            partial = target.with_suffix(".part")  # renamed when complete: an interrupted run leaves no half file
            partial.write_text(scenario_text(conversion, [*notice, f"Source: {source}"]))
            partial.replace(target)
            written += 1
        if loaded is not None:
            try:
                load_scenario(target)
            except OcpkitError as exc:
                rejected.append(f"{exc}")
    validated = any(loaded is not None for _, _, loaded in entries.values())
    if validated:
        (out / "invalid.txt").write_text("".join(f"{line}\n" for line in rejected))
    return MbmSummary(out, written, kept, len(rejected) if validated else None)


def _robot_entry(robot: str, spec: Path | None, folder: Path) -> tuple:
    """resolve_robot's (scenario entry, joints, Robot or None) for scenarios in `folder`."""
    try:
        return resolve_robot(str(spec) if spec is not None else robot, folder)
    except RobotError:  # not built in here and no spec: the MBM joint order, no validation
        if spec is not None:
            raise
        return robot, MBM_JOINTS[robot], None


def _names(target: Path, field: str | dict) -> bool:
    """Whether the scenario file `target` exists and its `robot:` line is the entry `field` (a conversion to keep)."""
    if not target.is_file():
        return False
    line = next((line for line in target.read_text().splitlines() if line.startswith("robot:")), "robot:")
    return yaml.safe_load(line)["robot"] == field
