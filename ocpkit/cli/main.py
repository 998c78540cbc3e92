"""Command line: `ocpkit plan SCENARIO`, `ocpkit bench paper|convergence|solvers|random|run|classics`, `ocpkit report`,
`ocpkit show`, `ocpkit list`.

Exit codes: 0 planned and verified (bench, list: done); 1 planned but not verified (the status and the hint say
why); 2 input error (one `error:` line); 130 interrupted by Ctrl-C (`interrupted`; no trajectory file is written,
a benchmark keeps its finished rows and resumes when run again)."""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import math
import sys
import tempfile
from pathlib import Path

from ocpkit import interrupt
from ocpkit.cli.scene import add_scene_commands
from ocpkit.errors import OcpkitError, OptionError
from ocpkit.problem import Problem
from ocpkit.result import Plan

INTERRUPTED = 130
WALL_TIME_OPTION = {"ompl-toppra": "planning_time"}
"""The planner option that --max-wall-time sets (default max_wall_time); OMPL's budget for the baseline."""
LIST_WIDTH = 120
"""Longest line of `ocpkit list`: a component's name and its docstring's first sentence, cut to fit."""


def _plan_command(args: argparse.Namespace) -> int:
    from ocpkit.formats.record import trajectory_header
    from ocpkit.formats.scenario import load_scenario
    from ocpkit.formats.trajectory import write_json
    from ocpkit.planner import plan

    if args.output:
        check_writable(Path(args.output))
    problem = load_scenario(args.scenario)
    if args.mu is not None:
        problem = dataclasses.replace(problem, mu=args.mu)
    result = plan(problem, planner=args.planner, **_planner_options(args))
    _print_plan(problem, result)
    if args.output:
        write_json(args.output, result.trajectory, trajectory_header(problem, result),
                   time_bounds=(problem.time.min, problem.time.max))
        print(f"wrote {Path(args.output).resolve()}")
    return 0 if result.ok else 1


def _planner_options(args: argparse.Namespace) -> dict:
    """The planner options given on the command line (a planner that does not take one names it)."""
    names = {"transcription": "transcription", "knots": "knots", "dynamics": "dynamics", "solver": "solver",
             "guess": "guess", "refinements": "refinements", "seed": "seed",
             "max_wall_time": WALL_TIME_OPTION.get(args.planner, "max_wall_time")}
    given = {option: getattr(args, key) for key, option in names.items() if getattr(args, key) is not None}
    if args.constraints is not None:
        given["constraints"] = tuple(name.strip() for name in args.constraints.split(","))
    if args.segments is not None:
        given["transcription_options"] = {"segments": args.segments}
    if args.single_shot:
        given["fallbacks"] = ()
    if "seed" in given and "guess_options" in _option_names(args.planner):  # the seed of the OMPL guess
        given["guess_options"] = {"seed": given.pop("seed")}
    return given


def _option_names(planner: str) -> list[str]:
    """The options the named planner takes."""
    from ocpkit.planner import PLANNERS

    return list(inspect.signature(PLANNERS.get(planner)).parameters)[1:]


def _print_plan(problem: Problem, result: Plan) -> None:
    """The plan's summary lines; for a plan that did not verify, the solver's message and the hint."""
    v = result.verification
    if result.found:
        print(f"{problem.name}: status {result.status}, t_f = {result.trajectory.tf:.3f} s "
              f"(velocity bound {problem.velocity_lower_bound():.3f} s), solve {result.stats.solve_time:.3f} s "
              f"+ set-up {result.stats.setup_time:.3f} s, {result.stats.iterations} iterations, "
              f"{result.stats.rounds} refinement rounds")
    else:
        print(f"{problem.name}: status {result.status}, no trajectory found (the plan holds the start for "
              f"{result.trajectory.tf:.3f} s), {result.stats.solve_time:.3f} s")
    print(f"checks: {v.summary()}")
    if not result.ok:
        print(f"solver: {result.stats.solver_message}")
    if result.hint:
        print(f"hint: {result.hint}")


def check_writable(path: Path, folder: bool = False) -> None:
    """OptionError unless `path` can be written as a file (or as a `folder`): it must be of that kind if it
    exists, its nearest existing ancestor must be a folder, and we must be able to write there (probed with a
    temporary file)."""
    existing = next(p for p in (path, *path.parents) if p.exists())
    if existing.is_dir() != (folder or existing != path):
        raise OptionError(f"cannot write {path}: {existing} is " + ("a folder" if existing.is_dir() else
                                                                     "a file, not a folder"))
    where = existing if existing.is_dir() else existing.parent
    try:
        with tempfile.TemporaryFile(dir=where):
            pass
    except OSError as exc:
        raise OptionError(f"cannot write {path}: {where} is not writable ({exc.strerror})") from exc


def _bench_command(args: argparse.Namespace) -> int:
    if args.suite == "run":
        from ocpkit.cli.bench_run import run_command

        return run_command(args, check_writable)
    out = Path(args.out or f"results/{args.suite}")
    check_writable(out, folder=True)
    if args.suite == "classics":
        from ocpkit.bench.classics import run_classics

        run_classics(out, problems=tuple(args.problems or ()), transcriptions=tuple(args.transcriptions or ()),
                     grids=tuple(args.knots or ()), solvers=tuple(args.solvers or ("ipopt",)),
                     peers=tuple(args.peers or ()))
    elif args.suite == "perf":
        from ocpkit.bench.perf import run_perf

        run_perf(Path(args.scenarios), out, repeats=args.repeats or 5, quick=args.quick)
    elif args.suite == "convergence":
        from ocpkit.bench.convergence import DEFAULT_CASE, run_convergence

        run_convergence(out, case=Path(args.case or DEFAULT_CASE))
    elif args.suite == "random":
        from ocpkit.bench.random import run_random
        from ocpkit.planner.ladder import DEFAULT_LADDER, SINGLE_SHOT

        run_random(args.seed, args.count, _one_knot_count(args, "chebyshev"), obstacles=tuple(args.obstacles),
                   out=out, fallbacks=SINGLE_SHOT if args.single_shot else DEFAULT_LADDER, planner=args.planner,
                   blocked=args.blocked)
    elif args.suite == "shapes":
        from ocpkit.bench.shapes import run_shapes_benchmark

        run_shapes_benchmark(knots=_one_knot_count(args, "chebyshev"), repeats=args.repeats or 5)
    elif args.suite == "solvers":
        from ocpkit.bench.solvers import run_solver_benchmark

        run_solver_benchmark(Path(args.scenarios), out, solvers=tuple(args.solvers) if args.solvers else None,
                             dynamics=tuple(args.dynamics) if args.dynamics else None,
                             knots=_one_knot_count(args, args.transcription), repeats=args.repeats or 1,
                             max_wall_time=args.max_wall_time, transcription=args.transcription,
                             transcription_options={"staged": True} if args.staged else None)
    else:
        from ocpkit.bench.paper import KNOTS, run_paper_benchmark

        for n in args.knots or ():
            _check_knots(args.transcription, n, args.segments)
        run_paper_benchmark(Path(args.scenarios), out, repeats=args.repeats or 5,
                            hard=Path(args.hard) if args.hard else None, transcription=args.transcription,
                            knots=tuple(args.knots) if args.knots else KNOTS,
                            transcription_options={"segments": args.segments} if args.segments else None)
    return 0


def _one_knot_count(args: argparse.Namespace, transcription: str) -> int:
    """The one knot count of `bench solvers` or `bench random` (default 12), checked for `transcription`."""
    if args.knots and len(args.knots) != 1:
        raise OptionError(f"bench {args.suite} runs one knot count, got --knots {' '.join(map(str, args.knots))}")
    knots = args.knots[0] if args.knots else 12
    _check_knots(transcription, knots)
    return knots


def _check_knots(transcription: str, knots: int, segments: int | None = None) -> None:
    """OptionError now, before any plan, if `transcription` does not take `knots` (and `segments`)."""
    from ocpkit.registry import construct
    from ocpkit.transcription import TRANSCRIPTIONS

    options = {"knots": knots, **({"segments": segments} if segments else {})}
    construct(TRANSCRIPTIONS.get(transcription), transcription, options)


def _check_numbers(args: argparse.Namespace) -> None:
    """OptionError for a count below its minimum or a non-finite or negative --mu / --max-wall-time."""
    for name, lowest in (("knots", 1), ("segments", 1), ("repeats", 1), ("count", 1), ("refinements", 0)):
        values = getattr(args, name, None)
        for value in values if isinstance(values, list) else [values]:
            if value is not None and value < lowest:
                raise OptionError(f"--{name} must be ≥ {lowest}, got {value}")
    for name in ("mu", "max_wall_time"):
        value = getattr(args, name, None)
        if value is not None and not (math.isfinite(value) and value >= 0):
            raise OptionError(f"--{name.replace('_', '-')} must be a finite number ≥ 0, got {value}")
    low, high = getattr(args, "obstacles", None) or (1, 1)
    if not 0 <= low <= high:
        raise OptionError(f"--obstacles MIN MAX needs 0 ≤ MIN ≤ MAX, got {low} {high}")


def _list_command(args: argparse.Namespace) -> int:
    from ocpkit.constraints import CONSTRAINTS
    from ocpkit.dynamics import DYNAMICS
    from ocpkit.planner import GUESSES, PLANNERS
    from ocpkit.solvers import SOLVERS
    from ocpkit.transcription import TRANSCRIPTIONS

    for registry in (TRANSCRIPTIONS, DYNAMICS, CONSTRAINTS, SOLVERS, PLANNERS, GUESSES):
        print(registry.group.removeprefix("ocpkit."))
        for name in registry.names():
            head = f"  {name:<17} "
            print(f"{head}{registry.description(name, LIST_WIDTH - len(head))}".rstrip())
    return 0


def _names(registry) -> str:
    """The registered names of `registry`, for a help text."""
    return ", ".join(registry.names())


def parser() -> argparse.ArgumentParser:
    """The `ocpkit` argument parser; the component options list what the registries hold."""
    from ocpkit.cli.bench_run import add_run_arguments
    from ocpkit.cli.report import add_report_parser
    from ocpkit.cli.show import add_show_parser
    from ocpkit.constraints import CONSTRAINTS, DEFAULT_CONSTRAINTS
    from ocpkit.dynamics import DYNAMICS
    from ocpkit.planner import GUESSES, PLANNERS
    from ocpkit.solvers import SOLVERS
    from ocpkit.transcription import TRANSCRIPTIONS

    exit_codes = __doc__.split("\n\n", 1)[1]
    main = argparse.ArgumentParser(prog="ocpkit", description=__doc__,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    commands = main.add_subparsers(dest="command", required=True)
    p = commands.add_parser("plan", help="plan one scenario file and verify the result", epilog=exit_codes)
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument("--planner", default="simultaneous", help=f"planner: {_names(PLANNERS)} (default simultaneous); "
                   "--transcription to --refinements are the simultaneous planner's options")
    p.add_argument("--transcription", help=f"{_names(TRANSCRIPTIONS)} (default chebyshev)")
    p.add_argument("--knots", type=int, help="number of knot intervals N (default 12); each transcription names its "
                   "smallest and largest when given one out of range")
    p.add_argument("--segments", type=int, help="pseudospectral segments K (chebyshev, lgl, lgr; default 1)")
    p.add_argument("--dynamics", help=f"dynamics backend: {_names(DYNAMICS)} (default casadi-rnea)")
    p.add_argument("--solver", help=f"NLP solver: {_names(SOLVERS)} (default ipopt)")
    p.add_argument("--guess", help=f"initial guess: {_names(GUESSES)} (default paper)")
    p.add_argument("--constraints", help="simultaneous: the path constraints, comma-separated names from "
                   f"{_names(CONSTRAINTS)} (default {','.join(DEFAULT_CONSTRAINTS)}; add dynamics-consistency to "
                   "bound the dynamics residual between knots too)")
    p.add_argument("--refinements", type=int, help="at most this many re-solve rounds after verification (default 5)")
    p.add_argument("--seed", type=int, help="OMPL's random seed (default 0): of ompl-toppra, or of the simultaneous "
                   "planner's --guess ompl")
    p.add_argument("--max-wall-time", type=float, help="time limit of the whole plan, s (ompl-toppra: OMPL's "
                   "planning time, default 1)")
    p.add_argument("--single-shot", action="store_true", help="simultaneous: one solve with the given options, "
                   "no fallback ladder (the paper's setting; default: the ladder of ocpkit.planner.ladder, first "
                   "verified rung wins)")
    p.add_argument("--mu", type=float, default=None, help="jerk weight μ ≥ 0 (default: the scenario's)")
    p.add_argument("-o", "--output", help="write the trajectory JSON here (checked before planning; not written "
                   "when interrupted)")
    p.set_defaults(run=_plan_command)
    b = commands.add_parser("bench", help="run a benchmark suite", epilog=exit_codes)
    b.add_argument("suite", choices=["paper", "convergence", "solvers", "random", "shapes", "run", "perf", "classics"],
                   help="paper: Table II; convergence: t_f error and dynamics residual vs knots per transcription; "
                   "solvers: every NLP solver x dynamics backend on the paper cases; random: seeded random "
                   "industrial6 problems with obstacles in the way; shapes: what boxes and cylinders cost "
                   "(scenarios/shapes/boxes.yaml with and without them); run: a suite file (scenarios x methods x "
                   "repeats); perf: where a paper plan's time goes, and growth with knots, obstacles and joints; "
                   "classics: the classic OCPs against their published optima, every transcription (and --peers "
                   "rockit)")
    b.add_argument("--scenarios", default="scenarios/paper", help="folder with case1..4.yaml (default "
                   "scenarios/paper, relative to the current folder)")
    b.add_argument("--hard", default="scenarios/hard", help="folder of harder scenarios for the seeding comparison "
                   "('' to skip it)")
    b.add_argument("--out", default=None, help="output folder (default results/SUITE in the current folder; the "
                   "absolute path is printed at the end): results.csv and trajectories/, or convergence.csv and "
                   "convergence.png. paper: rows already in its results.csv are kept and not run again (resume)")
    b.add_argument("--case", default=None, help="convergence: the scenario file (default scenarios/paper/case2.yaml)")
    b.add_argument("--repeats", type=int, default=None, help="solves per plan; the median is reported "
                   "(default 5 for paper, 1 for solvers)")
    b.add_argument("--transcription", default="chebyshev", help="paper, solvers: the simultaneous planner's "
                   f"transcription: {_names(TRANSCRIPTIONS)} (default chebyshev)")
    b.add_argument("--staged", action="store_true", help="solvers: give the mesh transcriptions' NLP its stage "
                   "structure (what fatrop exploits)")
    b.add_argument("--knots", type=int, nargs="+", help="paper: knot counts N (default 12 8); solvers, random: one N "
                   "(default 12); classics: the grids (default each transcription's own; several: convergence plots)")
    b.add_argument("--segments", type=int, help="paper: pseudospectral segments K (chebyshev, lgl, lgr)")
    b.add_argument("--problems", nargs="+", help="classics: the problems (default all: ocpkit.problems)")
    b.add_argument("--transcriptions", nargs="+", help=f"classics: the transcriptions (default all: "
                   f"{_names(TRANSCRIPTIONS)})")
    b.add_argument("--peers", nargs="+", help="classics: other tools solving the same problems: rockit (pip install "
                   "ocpkit[peers])")
    b.add_argument("--solvers", nargs="+", help=f"solvers: the solvers to run (default all: {_names(SOLVERS)})")
    b.add_argument("--dynamics", nargs="+", help=f"solvers: the dynamics backends to run (default all: "
                   f"{_names(DYNAMICS)})")
    b.add_argument("--max-wall-time", type=float, default=30.0, help="solvers: time limit per NLP solve, s")
    b.add_argument("--seed", type=int, default=1, help="random: the seed of the problem set (default 1)")
    b.add_argument("--count", type=int, default=30, help="random: number of problems (default 30)")
    b.add_argument("--obstacles", type=int, nargs=2, default=[1, 1], metavar=("MIN", "MAX"),
                   help="random: obstacles per problem, drawn from MIN..MAX (default 1 1)")
    b.add_argument("--single-shot", action="store_true", help="random: plan without the fallback ladder (the "
                   "paper's one solve; bench paper always plans so)")
    b.add_argument("--planner", default="simultaneous", help="random: the planner (default simultaneous)")
    b.add_argument("--blocked", action="store_true", help="random: the draws whose obstacles leave no room to pass "
                   "(the certificate's search found no path) instead of those with room")
    add_run_arguments(b)
    b.add_argument("--quick", action="store_true", help="perf: 2 repeats and a short growth curve (for tests)")
    b.set_defaults(run=_bench_command)
    add_report_parser(commands)
    add_show_parser(commands)
    ls = commands.add_parser("list", help="list the registered components (transcriptions, dynamics, constraints, "
                             "solvers, planners, guesses) with one line each")
    ls.set_defaults(run=_list_command)
    from ocpkit.cli.robot import add_robot_parser
    add_robot_parser(commands)
    add_scene_commands(commands)
    return main


def main(argv: list[str] | None = None) -> int:
    """Run the command of `argv` (default: sys.argv); return the exit code (module docstring)."""
    args = parser().parse_args(argv)
    try:
        _check_numbers(args)
        with interrupt.watching():
            return args.run(args)
    except OcpkitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        interrupt.ignore()
        print("interrupted", file=sys.stderr)
        return INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
