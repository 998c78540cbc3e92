"""`ocpkit show TRAJ.json --scenario FILE [--gif out.gif]`: the command line of the viewers."""

from __future__ import annotations

import argparse
import time
from pathlib import Path


def add_show_parser(commands) -> None:
    """`ocpkit show` on the CLI's subcommands."""
    s = commands.add_parser("show", help="view a trajectory file in 3D in the browser (viser), or write a GIF")
    s.add_argument("trajectory", help="trajectory JSON (ocpkit plan -o, or trajectories/ of a benchmark)")
    s.add_argument("--scenario", required=True, help="the scenario file it was planned for (a benchmark's "
                   "scenarios/SCENE/CASE.yaml)")
    s.add_argument("--gif", default=None, help="write an animated GIF here instead of serving the viewer")
    s.add_argument("--host", default="127.0.0.1", help="viewer address (default 127.0.0.1; 0.0.0.0 for all)")
    s.add_argument("--port", type=int, default=8080, help="viewer port (default 8080)")
    s.set_defaults(run=_show_command)


def _show_command(args: argparse.Namespace) -> int:
    from ocpkit.formats.scenario import load_scenario
    from ocpkit.viewer.motion import load_motion, obstacle_shapes

    problem = load_scenario(args.scenario)
    motion = load_motion(args.trajectory, problem)
    shapes = obstacle_shapes(problem.scene)
    if args.gif:
        from ocpkit.viewer.gif import write_gif

        count = write_gif(args.gif, motion, shapes, problem.scene.workspace)
        print(f"wrote {Path(args.gif).resolve()} ({count} frames)")
        return 0
    from ocpkit.viewer.browser import serve

    server = serve(motion, shapes, problem.scene.workspace, args.host, args.port, title=Path(args.trajectory).name)
    print(f"viewer at http://{args.host}:{server.get_port()} (Ctrl-C to stop)", flush=True)
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        server.stop()
    return 0
