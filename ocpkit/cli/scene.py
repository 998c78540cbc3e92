"""`ocpkit convert moveit` and `ocpkit data mbm`: scenes from MoveIt files and the MotionBenchMaker problems."""

from __future__ import annotations

import argparse
from pathlib import Path

from ocpkit.errors import MoveItError, OcpkitError


def add_scene_commands(commands: argparse._SubParsersAction) -> None:
    """Add the `convert` and `data` sub-commands to the `ocpkit` parser."""
    convert = commands.add_parser("convert", help="convert another tool's problem files to a scenario file")
    formats = convert.add_subparsers(dest="format", required=True)
    moveit = formats.add_parser("moveit", help="a MoveIt PlanningScene YAML + MotionPlanRequest YAML: collision "
                                "objects (box, sphere, cylinder), start state, joint goal; the rest is listed as "
                                "ignored")
    moveit.add_argument("scene", help="PlanningScene YAML (world.collision_objects, robot_state)")
    moveit.add_argument("request", help="MotionPlanRequest YAML (start_state, goal_constraints.joint_constraints)")
    moveit.add_argument("--robot", required=True, help="a built-in robot name or a robot spec.yaml path")
    moveit.add_argument("--joints", help="comma-separated planned joint names in the robot's order (default: the "
                        "robot's own; needed for a robot not built in, whose scenario is then not validated)")
    moveit.add_argument("--name", help="the scenario's name (default: the output file's stem)")
    moveit.add_argument("-o", "--output", required=True, help="the scenario YAML to write")
    moveit.set_defaults(run=_convert_moveit)
    data = commands.add_parser("data", help="obtain a public problem set as scenario files")
    sets = data.add_subparsers(dest="dataset", required=True)
    from ocpkit.formats.mbm import ROBOTS, VAMP_VERSION
    mbm = sets.add_parser("mbm", help=f"the MotionBenchMaker problems (7 scenes x 100) from the vamp-planner "
                          f"{VAMP_VERSION} source distribution (pip download; nothing is built)")
    mbm.add_argument("--robot", required=True, choices=ROBOTS)
    mbm.add_argument("--dir", help="cache folder (default ~/.cache/ocpkit/mbm or $XDG_CACHE_HOME/ocpkit/mbm); "
                     "what is already there is reused")
    mbm.set_defaults(run=_data_mbm)


def _convert_moveit(args: argparse.Namespace) -> int:
    from ocpkit.formats.moveit import read_moveit, resolve_robot, scenario_text
    from ocpkit.formats.scenario import problem_from_dict

    out = Path(args.output)
    joints = [name.strip() for name in args.joints.split(",")] if args.joints else None
    if joints is not None and (not all(joints) or len(set(joints)) != len(joints)):
        raise MoveItError(f"--joints needs distinct non-empty names, got {args.joints!r}")
    out.parent.mkdir(parents=True, exist_ok=True)  # relative robot paths are resolved through it
    field, joints, robot = resolve_robot(args.robot, out.parent, joints)
    conversion = read_moveit(args.scene, args.request, joints, field, args.name or out.stem)
    if robot is not None:
        try:
            problem_from_dict(conversion.scenario, base_dir=out.parent)
        except OcpkitError as exc:
            raise MoveItError(f"the converted problem is not valid for ocpkit ({out} not written): {exc}") from exc
    out.write_text(scenario_text(conversion, [f"Converted by `ocpkit convert moveit` from {args.scene} and "
                                              f"{args.request}"]))
    for line in conversion.ignored:
        print(f"ignored: {line}")
    obstacles = len(conversion.scenario["scene"]["obstacles"])
    checked = "validated" if robot is not None else f"not validated: robot {args.robot!r} is not built in here"
    print(f"wrote {out}: {len(joints)} joints, {obstacles} obstacles ({checked})")
    return 0


def _data_mbm(args: argparse.Namespace) -> int:
    from ocpkit.formats.mbm import fetch_mbm

    summary = fetch_mbm(args.robot, Path(args.dir) if args.dir else None)
    checked = ("not validated: the robot is not built in here" if summary.invalid is None else
               f"{summary.invalid} rejected by ocpkit's {args.robot} model, listed in "
               f"{summary.directory / 'invalid.txt'}")
    print(f"MBM {args.robot}: {summary.written} scenarios written, {summary.kept} already there, in "
          f"{summary.directory.resolve()} ({checked})")
    return 0
