"""The command-line part of `ocpkit bench run`: its options and the call."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from ocpkit.errors import OptionError


def add_run_arguments(bench: argparse.ArgumentParser) -> None:
    """The options of `ocpkit bench run SUITE.yaml` on the `bench` parser."""
    bench.add_argument("suite_file", nargs="?", metavar="SUITE.yaml", help="run: the suite file (docs/formats.md, "
                       "'Suite files')")
    bench.add_argument("--jobs", type=int, default=1, help="run: local worker processes (default 1); --repeats "
                       "overrides the suite's repeats")
    bench.add_argument("--scheduler", default=None, metavar="ADDRESS", help="run: run the tasks on this Dask "
                       "scheduler, e.g. tcp://host:8786, instead of local processes")


def run_command(args: argparse.Namespace, check_writable: Callable[..., None]) -> int:
    """`ocpkit bench run`: check the options (the output folder with the CLI's `check_writable`), run the suite
    (default output results/SUITE-NAME)."""
    from ocpkit.bench.run import run_suite
    from ocpkit.bench.suite import load_suite

    if not args.suite_file:
        raise OptionError("bench run needs a suite file: ocpkit bench run SUITE.yaml --out DIR")
    if args.jobs < 1:
        raise OptionError(f"--jobs must be ≥ 1, got {args.jobs}")
    out = Path(args.out or f"results/{load_suite(args.suite_file).name}")
    check_writable(out, folder=True)
    run_suite(args.suite_file, out, jobs=args.jobs, scheduler=args.scheduler, repeats=args.repeats)
    return 0
