"""`ocpkit robot import|spheres|show`: robots from any URDF, their sphere models, and a picture of them."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ocpkit.errors import RobotError

SPHERE_SOURCES = "'urdf' (the URDF's own <collision><sphere>), a path to a URDF whose links carry sphere collisions " \
                 "(e.g. a spherized URDF), or 'fit' (fit spheres to each link's collision geometry)"


def add_robot_parser(commands: argparse._SubParsersAction) -> None:
    """Add `robot import`, `robot spheres` and `robot show` to the `ocpkit` subcommands."""
    robot = commands.add_parser("robot", help="import a robot from a URDF, fit or compare its spheres, draw them")
    sub = robot.add_subparsers(dest="robot_command", required=True)
    i = sub.add_parser("import", help="write DIR/spec.yaml for a URDF (limits from the URDF, documented rules for the "
                       "rest; see ocpkit.robots.importer)")
    i.add_argument("urdf", help="the robot's URDF")
    i.add_argument("--srdf", help="SRDF whose <disable_collisions> link pairs are not checked")
    i.add_argument("--joints", help="planned joints, comma-separated, in tree order (default: every revolute and "
                   "prismatic joint)")
    i.add_argument("--locked", help="values of joints not planned, e.g. finger1=0.04,finger2=0.04 (rad or m; "
                   "default 0)")
    i.add_argument("--spheres", default="urdf", help=f"sphere source: {SPHERE_SOURCES} (default urdf)")
    i.add_argument("--set", action="append", default=[], metavar="FIELD.JOINT=VALUE",
                   help="override a value, e.g. torque_rate.joint_1=500 (fields: lower, upper, velocity, torque, "
                   "torque_rate, gear_ratio, viscous, coulomb); repeatable")
    i.add_argument("--name", help="robot name (default: the URDF's)")
    _fit_options(i)
    i.add_argument("--out", default=".", help="folder for spec.yaml (default: the current folder)")
    i.set_defaults(run=_import_command)
    s = sub.add_parser("spheres", help="fit spheres to each link's collision geometry and print per link count, "
                       "coverage and protrusion, beside another sphere model's")
    s.add_argument("urdf", help="URDF with the links' collision geometry (meshes, boxes, cylinders)")
    s.add_argument("--compare", help="a URDF whose links carry sphere collisions (e.g. a spherized URDF)")
    _fit_options(s)
    s.set_defaults(run=_spheres_command)
    d = sub.add_parser("show", help="draw a robot's spheres at its zero pose (PNG)")
    d.add_argument("dir", help="folder with spec.yaml (naming its URDF), or a built-in robot name")
    d.add_argument("--out", default="spheres.png", help="PNG file (default spheres.png)")
    d.set_defaults(run=_show_command)


def _fit_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--budget", type=int, default=12, help="fit: at most this many spheres per link (default 12)")
    p.add_argument("--coverage", type=float, default=0.99, help="fit: coverage target, share of mesh-surface "
                   "samples inside the spheres (default 0.99)")
    p.add_argument("--protrusion", type=float, default=0.01, help="fit: protrusion tolerance, m (default 0.01)")


def _pairs_of(text: str | None, option: str) -> dict[str, float]:
    """`a=1,b=2` → {a: 1.0, b: 2.0}; RobotError naming the option for anything else."""
    out = {}
    for item in filter(None, (text or "").split(",")):
        key, sep, value = item.partition("=")
        try:
            out[key.strip()] = float(value)
        except ValueError:
            sep = ""
        if not sep or not key.strip():
            raise RobotError(f"{option}: expected NAME=NUMBER, got {item!r}")
    return out


def _overrides(items: list[str]) -> dict[str, dict[str, float]]:
    out: dict[str, dict[str, float]] = {}
    for item in items:
        field, dot, rest = item.partition(".")
        if not dot:
            raise RobotError(f"--set: expected FIELD.JOINT=VALUE, got {item!r}")
        out.setdefault(field, {}).update(_pairs_of(rest, "--set"))
    return out


def _check_fit_options(args: argparse.Namespace) -> None:
    if args.budget < 1:
        raise RobotError(f"--budget must be ≥ 1, got {args.budget}")
    if not 0 < args.coverage <= 1:
        raise RobotError(f"--coverage must be in (0, 1], got {args.coverage}")
    if not args.protrusion >= 0:
        raise RobotError(f"--protrusion must be ≥ 0 m, got {args.protrusion}")


def _import_command(args: argparse.Namespace) -> int:
    from ocpkit.robots.importer import import_urdf, pair_report, spec_header, write_spec
    from ocpkit.robots.sphere_models import sphere_model

    _check_fit_options(args)
    urdf = Path(args.urdf)
    if not urdf.is_file():
        raise RobotError(f"URDF not found: {urdf}")
    spheres, report = sphere_model(urdf, args.spheres, budget=args.budget, coverage=args.coverage,
                                   protrusion=args.protrusion)
    if not spheres:
        raise RobotError(f"--spheres {args.spheres}: no spheres found; use --spheres fit or a spherized URDF")
    joints = [j.strip() for j in args.joints.split(",")] if args.joints else None
    imported = import_urdf(urdf, spheres, Path(args.out), name=args.name, joints=joints,
                           srdf=Path(args.srdf) if args.srdf else None, locked=_pairs_of(args.locked, "--locked"),
                           overrides=_overrides(args.set))
    print(report)
    print(pair_report(imported.pairs))
    header = spec_header(imported, urdf, args.spheres, "`ocpkit robot import`")
    print(f"wrote {write_spec(imported, Path(args.out), header).resolve()}")
    return 0


def _spheres_command(args: argparse.Namespace) -> int:
    from ocpkit.robots.sphere_models import comparison_table

    _check_fit_options(args)
    print(comparison_table(Path(args.urdf), Path(args.compare) if args.compare else None, budget=args.budget,
                           coverage=args.coverage, protrusion=args.protrusion))
    return 0


def _show_command(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ocpkit.robots import builtin_robots, load_robot
    from ocpkit.robots.robot import robot_from_spec

    if args.dir not in builtin_robots() and not (Path(args.dir) / "spec.yaml").is_file():
        raise RobotError(f"{args.dir}: neither a built-in robot ({', '.join(builtin_robots())}) nor a folder with "
                         "spec.yaml")
    robot = load_robot(args.dir) if args.dir in builtin_robots() else robot_from_spec(Path(args.dir) / "spec.yaml")
    out = Path(args.out)
    if not out.parent.is_dir():
        raise RobotError(f"--out: folder {out.parent} does not exist")
    from ocpkit.geometry.clearances import sphere_centers

    q = np.clip(np.zeros(robot.n), robot.q_lower, robot.q_upper)
    centres = sphere_centers(robot, q)
    figure = plt.figure(figsize=(7, 7))
    axes = figure.add_subplot(projection="3d")
    u, v = np.mgrid[0:2 * np.pi:16j, 0:np.pi:9j]
    unit = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)])
    links = sorted(set(robot.sphere_link))
    colours = plt.get_cmap("tab20")
    for c, r, link in zip(centres, robot.sphere_radius, robot.sphere_link):
        x, y, z = c[:, None, None] + r * unit
        axes.plot_surface(x, y, z, color=colours(links.index(link) % 20), alpha=0.5, linewidth=0)
    low, high = (centres - robot.sphere_radius[:, None]).min(0), (centres + robot.sphere_radius[:, None]).max(0)
    middle, half = (low + high) / 2, (high - low).max() / 2
    axes.set(xlim=(middle[0] - half, middle[0] + half), ylim=(middle[1] - half, middle[1] + half),
             zlim=(middle[2] - half, middle[2] + half), xlabel="x [m]", ylabel="y [m]", zlabel="z [m]",
             title=f"{robot.name}: {len(robot.sphere_radius)} spheres on {len(links)} links at q = 0 (clipped)")
    figure.savefig(out, dpi=110)
    print(f"wrote {out.resolve()}")
    return 0
