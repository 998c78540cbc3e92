"""The command-line part of `ocpkit report` (the work is in ocpkit.bench.report_page, imported when run)."""

from __future__ import annotations

import argparse
from pathlib import Path


def add_report_parser(commands) -> None:
    """`ocpkit report DIR [--plan TRAJ.json]` on the CLI's subcommands."""
    r = commands.add_parser("report", help="HTML page and Markdown summary (and Planner Arena logs) of an "
                            "`ocpkit bench run` output folder")
    r.add_argument("folder", help="the --out folder of `ocpkit bench run`")
    r.add_argument("--plan", default=None, help="trajectory file whose joint values to plot against the limits "
                   "(relative to the folder; default the first verified plan)")
    r.set_defaults(run=_report_command)


def _report_command(args: argparse.Namespace) -> int:
    from ocpkit.bench.report_page import write_report

    folder = Path(args.folder)
    html_path, md_path = write_report(folder, Path(args.plan) if args.plan else None)
    print(f"wrote {html_path.resolve()}, {md_path.resolve()} and {(folder / 'planner-arena').resolve()}/")
    return 0
