"""Command line: `ocpkit plan SCENARIO`, `ocpkit bench paper|convergence|solvers|random`, `ocpkit list`.

User mistakes print one line and exit with 2."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from ocpkit.errors import OcpkitError, OptionError


def _plan_command(args: argparse.Namespace) -> int:
    from ocpkit import load_scenario, plan
    from ocpkit.report import trajectory_header
    from ocpkit.trajectory import write_json

    problem = load_scenario(args.scenario)
    if args.mu is not None:
        problem = dataclasses.replace(problem, mu=args.mu)
    given = {key: getattr(args, key) for key in ("transcription", "knots", "dynamics", "solver")
             if getattr(args, key) is not None}
    if args.segments is not None:
        given["transcription_options"] = {"segments": args.segments}
    result = plan(problem, planner=args.planner, **given)
    v = result.verification
    print(f"{problem.name}: status {result.status}, t_f = {result.trajectory.tf:.3f} s "
          f"(velocity bound {problem.velocity_lower_bound():.3f} s), solve {result.stats.solve_time:.3f} s "
          f"+ set-up {result.stats.setup_time:.3f} s, {result.stats.iterations} iterations, "
          f"{result.stats.rounds} refinement rounds")
    print(f"checks: {v.summary()}")
    if any(c.name == "dynamics" and not c.ok for c in v.checks):
        print("hint: the polynomial does not resolve the dynamics between knots; try more knots (--knots)")
    if args.output:
        write_json(args.output, result.trajectory, trajectory_header(problem, result))
        print(f"wrote {args.output}")
    return 0 if result.ok else 1


def _bench_command(args: argparse.Namespace) -> int:
    if args.suite == "convergence":
        from ocpkit.bench.convergence import DEFAULT_CASE, run_convergence

        run_convergence(Path(args.out or "results/convergence"), case=Path(args.case or DEFAULT_CASE))
        return 0
    if args.suite == "random":
        from ocpkit.bench.random import run_random

        if args.knots and len(args.knots) != 1:
            raise OptionError(f"bench random runs one knot count, got --knots {' '.join(map(str, args.knots))}")
        run_random(args.seed, args.count, args.knots[0] if args.knots else 12)
        return 0
    if args.suite == "solvers":
        from ocpkit.bench.solvers import run_solver_benchmark

        if args.knots and len(args.knots) != 1:
            raise OptionError(f"bench solvers runs one knot count, got --knots {' '.join(map(str, args.knots))}")
        run_solver_benchmark(Path(args.scenarios), Path(args.out or "results/solvers"),
                             solvers=tuple(args.solvers) if args.solvers else None,
                             dynamics=tuple(args.dynamics) if args.dynamics else None,
                             knots=args.knots[0] if args.knots else 12, repeats=args.repeats or 1,
                             max_wall_time=args.max_wall_time, transcription=args.transcription,
                             transcription_options={"staged": True} if args.staged else None)
        return 0
    from ocpkit.bench.paper import KNOTS, run_paper_benchmark

    run_paper_benchmark(Path(args.scenarios), Path(args.out or "results/paper"), repeats=args.repeats or 5,
                        hard=Path(args.hard) if args.hard else None, transcription=args.transcription,
                        knots=tuple(args.knots) if args.knots else KNOTS,
                        transcription_options={"segments": args.segments} if args.segments else None)
    return 0


def _list_command(args: argparse.Namespace) -> int:
    from ocpkit.constraints import CONSTRAINTS
    from ocpkit.dynamics import DYNAMICS
    from ocpkit.planner import GUESSES, PLANNERS
    from ocpkit.solvers import SOLVERS
    from ocpkit.transcription import TRANSCRIPTIONS

    for registry in (TRANSCRIPTIONS, DYNAMICS, CONSTRAINTS, SOLVERS, PLANNERS, GUESSES):
        print(registry.group.removeprefix("ocpkit."))
        for name in registry.names():
            print(f"  {name:<17} {registry.description(name)}".rstrip())
    return 0


def parser() -> argparse.ArgumentParser:
    """The `ocpkit` argument parser."""
    main = argparse.ArgumentParser(prog="ocpkit", description=__doc__)
    commands = main.add_subparsers(dest="command", required=True)
    p = commands.add_parser("plan", help="plan one scenario file and verify the result")
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument("--planner", default="simultaneous", help="planner (default simultaneous; see `ocpkit list`); "
                   "the options below are the simultaneous planner's")
    p.add_argument("--transcription", help="transcription (default chebyshev; see `ocpkit list`)")
    p.add_argument("--knots", type=int, help="number of knot intervals N (default 12)")
    p.add_argument("--segments", type=int, help="pseudospectral segments K (chebyshev, lgl, lgr; default 1)")
    p.add_argument("--dynamics", help="dynamics backend (default casadi-rnea; see `ocpkit list`)")
    p.add_argument("--solver", help="NLP solver (default ipopt; see `ocpkit list`)")
    p.add_argument("--mu", type=float, default=None, help="jerk weight μ (default: the scenario's)")
    p.add_argument("-o", "--output", help="write the trajectory JSON here")
    p.set_defaults(run=_plan_command)
    b = commands.add_parser("bench", help="run a benchmark suite")
    b.add_argument("suite", choices=["paper", "convergence", "solvers", "random"],
                   help="paper: Table II; convergence: t_f error and dynamics residual vs knots per transcription; "
                   "solvers: every NLP solver x dynamics backend on the paper cases; random: seeded random "
                   "industrial6 problems with an obstacle in the way")
    b.add_argument("--scenarios", default="scenarios/paper", help="folder with case1..4.yaml")
    b.add_argument("--hard", default="scenarios/hard", help="folder of harder scenarios for the seeding comparison "
                   "('' to skip it)")
    b.add_argument("--out", default=None, help="output folder (default results/SUITE): results.csv and "
                   "trajectories/, or convergence.csv and convergence.png")
    b.add_argument("--case", default=None, help="convergence: the scenario file (default scenarios/paper/case2.yaml)")
    b.add_argument("--repeats", type=int, default=None, help="solves per plan; the median is reported "
                   "(default 5 for paper, 1 for solvers)")
    b.add_argument("--transcription", default="chebyshev", help="paper, solvers: the simultaneous planner's "
                   "transcription")
    b.add_argument("--staged", action="store_true", help="solvers: give the mesh transcriptions' NLP its stage "
                   "structure (what fatrop exploits)")
    b.add_argument("--knots", type=int, nargs="+", help="paper: knot counts N (default 12 8); solvers: one N "
                   "(default 12)")
    b.add_argument("--segments", type=int, help="paper: pseudospectral segments K (chebyshev, lgl)")
    b.add_argument("--solvers", nargs="+", help="solvers: the solvers to run (default: all registered)")
    b.add_argument("--dynamics", nargs="+", help="solvers: the dynamics backends to run (default: all registered)")
    b.add_argument("--max-wall-time", type=float, default=30.0, help="solvers: time limit per NLP solve, s")
    b.add_argument("--seed", type=int, default=1, help="random: the seed of the problem set (default 1)")
    b.add_argument("--count", type=int, default=30, help="random: number of problems (default 30)")
    b.set_defaults(run=_bench_command)
    ls = commands.add_parser("list", help="list the registered components (transcriptions, dynamics, constraints, "
                             "solvers, planners, guesses) with one line each")
    ls.set_defaults(run=_list_command)
    return main


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.run(args)
    except OcpkitError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
