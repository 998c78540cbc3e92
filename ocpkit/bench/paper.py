"""The paper's experiment (Table II): four pick-and-place cases at 12 and 8 knots, μ = 0.3, against the
path–velocity decomposition baselines: OMPL + TOPP-RA (which cannot bound torque rate) and OMPL + the path-timing
OCP (`ompl-topp3`: the same limits and cost, solved at the simultaneous planner's first knot count, transcription
and dynamics), plus hybrid seeding of the simultaneous planner. The simultaneous planner runs single shot
(`fallbacks=SINGLE_SHOT`), the paper's setting, not the default ladder.

Computation time is the wall time of one plan whose NLP shape is already built (all refinement rounds
and the dense verification included), median over `repeats` runs; set-up is the first build of a shape.
Every method runs in the same process, so their times compare on the same machine state.
"""

from __future__ import annotations

import dataclasses
import statistics
from dataclasses import dataclass
from pathlib import Path

from ocpkit.bench.common import Results, load_all, machine, measure, reported_on_interrupt, resumed_line
from ocpkit.formats.record import KEY_COLUMNS, RESULT_COLUMNS, Recorded, result_row, row_key, trajectory_header
from ocpkit.formats.trajectory import write_json
from ocpkit.planner.ladder import SINGLE_SHOT
from ocpkit.problem import Problem
from ocpkit.result import Plan

PAPER_TF = {12: [1.65, 1.23, 1.05, 1.08], 8: [1.98, 1.23, 1.09, 1.11]}
PAPER_SOLVE = {12: [2.55, 2.37, 2.39, 2.57], 8: [1.28, 1.75, 0.84, 1.32]}
PAPER_SETUP = 5.9
KNOTS = (12, 8)
WIDTH = 24
PAPER_GUESS, TIMED_GUESS = "paper", "line"
"""The paper's initial guess (its table's rows) and the planner's default, run beside it."""
COLUMNS = (*RESULT_COLUMNS, "guess")
"""results.csv of the paper bench: the result columns and the simultaneous planner's initial guess ('' for the
baseline), which is part of a row's key."""


def run_paper_benchmark(scenarios: Path, out: Path, repeats: int = 5,
                        dynamics: tuple[str, ...] = ("casadi-rnea", "casadi"), hard: Path | None = None,
                        transcription: str = "chebyshev", knots: tuple[int, ...] = KNOTS,
                        transcription_options: dict | None = None) -> list[dict]:
    """Solve every case at every knot count with every dynamics form and with the baseline; print the
    tables; write results.csv and trajectories/. With `hard` (a folder of scenarios), also compare the
    straight-line and the OMPL initial guess on the paper cases and those. The simultaneous planner uses
    `transcription` (with `transcription_options`); the single-knot-count comparisons use knots[0].

    Each row is added to results.csv as its plan finishes; rows already there (suite, case and method) are not
    run again, so a run stopped by Ctrl-C resumes where it stopped. The tables show every row, earlier or new."""
    problems = load_all(Path(scenarios))
    results = Results(Path(out) / "results.csv", COLUMNS, (*KEY_COLUMNS, "guess"))
    if results.resumed:
        print(resumed_line(results), flush=True)
    bench = _Bench(results, Path(out), repeats, transcription, transcription_options or {})
    with reported_on_interrupt(results):
        simultaneous = {(form, p.name, n): bench.simultaneous("paper", p, n, form, write=form == dynamics[0])
                        for form in dynamics for n in knots for p in problems}
        default = {(p.name, n): bench.simultaneous("paper", p, n, dynamics[0], guess=TIMED_GUESS)
                   for n in knots for p in problems}
        baseline = {p.name: bench.baseline(p) for p in problems}
        topp3 = {p.name: bench.topp3(p, knots[0], dynamics[0]) for p in problems}
        matched = {p.name: bench.simultaneous("matched-to-baseline", p, knots[0], dynamics[0], repeats=1)
                   for p in _matched_to_baseline(problems)}
        seeding = bench.seeding(problems + load_all(Path(hard)), knots[0], dynamics[0]) if hard is not None else {}
    first = {(c, k): m for (f, c, k), m in simultaneous.items() if f == dynamics[0]}
    options = "".join(f" {k}={v}" for k, v in bench.options.items())
    print(_paper_table(problems, first, f"{transcription}{options} + ipopt, dynamics {dynamics[0]}", knots))
    print(_comparison(problems, simultaneous, dynamics, knots))
    print(_guess_table(problems, first, default, knots))
    print(_baseline_table(problems, {c: m for (c, k), m in first.items() if k == knots[0]}, baseline, matched))
    print(_same_limits_table(problems, {c: m for (c, k), m in first.items() if k == knots[0]}, baseline, topp3))
    if hard is not None:
        print(_seeding_table(seeding))
    print(f"{machine()}; computation times are medians of {repeats} runs per plan (seeding: 1 run)")
    print(f"results: {results.path.resolve()} and {(Path(out) / 'trajectories').resolve()}/")
    return results.rows


@dataclass(frozen=True)
class _Bench:
    """How the paper bench plans: each (suite, case, method) once into `results`, trajectories under `out`."""

    results: Results
    out: Path
    repeats: int
    transcription: str
    options: dict

    def simultaneous(self, suite: str, problem: Problem, knots: int, dynamics: str, write: bool = False,
                     repeats: int | None = None, **options) -> Recorded:
        """The simultaneous planner's row for `problem` at `knots` with `dynamics` (and `options`), single shot
        (no fallback ladder) from the paper's guess unless `options` name another, as in the paper."""
        method = {"planner": "simultaneous", "transcription": self.transcription, "knots": knots, "solver": "ipopt",
                  "dynamics": dynamics}
        return self._row(suite, problem, method, write, self.repeats if repeats is None else repeats,
                         transcription=self.transcription, transcription_options=self.options, knots=knots,
                         dynamics=dynamics, fallbacks=SINGLE_SHOT, **{"guess": PAPER_GUESS, **options})

    def seeding(self, problems: list[Problem], knots: int, dynamics: str) -> dict[tuple[str, str], Recorded]:
        """The straight-line and the OMPL guess on each of `problems`, one run each, by (case, guess)."""
        return {(p.name, guess): self.simultaneous(f"seeding-{guess}", p, knots, dynamics, repeats=1, guess=guess)
                for p in problems for guess in ("paper", "ompl")}

    def baseline(self, problem: Problem) -> Recorded:
        """The OMPL + TOPP-RA baseline's row for `problem`."""
        return self._row("paper", problem, {"planner": "ompl-toppra"}, True, self.repeats, planner="ompl-toppra")

    def topp3(self, problem: Problem, knots: int, dynamics: str) -> Recorded:
        """The ompl-topp3 baseline's row for `problem`: its timing OCP transcribed as the simultaneous planner's
        problem is (transcription and its options, `knots`, `dynamics`, ipopt)."""
        method = {"planner": "ompl-topp3", "transcription": self.transcription, "knots": knots, "solver": "ipopt",
                  "dynamics": dynamics}
        return self._row("paper", problem, method, True, self.repeats, planner="ompl-topp3",
                         transcription=self.transcription, transcription_options=self.options, knots=knots,
                         dynamics=dynamics)

    def _row(self, suite: str, problem: Problem, method: dict, write: bool, repeats: int, **options) -> Recorded:
        def measured() -> dict:
            m = measure(problem, repeats, **options)
            if write:
                _write_trajectory(self.out, problem, m.plan)
            return {**result_row(suite, problem.name, m.plan, m.solve_time, m.setup_time), "guess": guess}

        guess = options.get("guess", "")
        key = row_key({"suite": suite, "case": problem.name, **method, "guess": guess}, self.results.key_columns)
        return Recorded.of(self.results.row(key, measured))


def _matched_to_baseline(problems: list[Problem]) -> list[Problem]:
    """The problems with what TOPP-RA cannot enforce switched off: torque-rate limits ×1000, μ = 0.001."""
    robots = {}
    for p in problems:
        robots.setdefault(p.robot.key, dataclasses.replace(p.robot, taud_max=p.robot.taud_max * 1e3,
                                                           key=f"{p.robot.key}:torque-rate-x1000"))
    return [dataclasses.replace(p, robot=robots[p.robot.key], mu=1e-3) for p in problems]


def _write_trajectory(out: Path, problem: Problem, result: Plan) -> None:
    name = "-".join([problem.name] + [str(result.method[k]) for k in ("planner", "transcription", "knots")
                                      if k in result.method]) + ".json"
    write_json(out / "trajectories" / name, result.trajectory, trajectory_header(problem, result))


def _paper_table(problems: list[Problem], measured: dict, label: str, counts: tuple[int, ...]) -> str:
    head = f"{'time [s]':<20}{'knots':>6}" + "".join(f"{p.name:>{WIDTH}}" for p in problems)
    lines = [f"Table II, simultaneous planner ({label}, single shot as in the paper: no fallback ladder): ours "
             "(paper) [velocity lower bound]", head, "-" * len(head)]
    for knots in counts:
        cells = [f"{measured[p.name, knots].tf:.2f} {_paper(PAPER_TF, knots, k)} "
                 f"[{p.velocity_lower_bound():.2f}]" for k, p in enumerate(problems)]
        lines.append(_row("motion time t_f", knots, cells))
    for knots in counts:
        cells = [f"{measured[p.name, knots].solve_time:.3f} {_paper(PAPER_SOLVE, knots, k)}"
                 for k, p in enumerate(problems)]
        lines.append(_row("computation time", knots, cells))
    for knots in counts:
        lines.append(_row("status", knots, [measured[p.name, knots].status for p in problems]))
    return "\n".join(lines)


def _paper(figures: dict, knots: int, case: int) -> str:
    """The paper's figure for this knot count and case, in parentheses; (-) where the paper has none."""
    values = figures.get(knots, [])
    return f"({values[case]:.2f})" if case < len(values) else "(-)"


def _comparison(problems: list[Problem], measured: dict, dynamics: tuple[str, ...], counts: tuple[int, ...]) -> str:
    lines = ["", f"{'dynamics':<14}{'knots':>6}{'median computation':>20}{'vs paper':>10}{'set-up':>9}"
             f"{'paper set-up':>14}{'verified':>10}"]
    for form in dynamics:
        for knots in counts:
            cases = [measured[form, p.name, knots] for p in problems]
            median = statistics.median(m.solve_time for m in cases)
            setup = max(m.setup_time for m in cases)
            speedup = f"{statistics.median(PAPER_SOLVE[knots]) / median:.1f}x" if knots in PAPER_SOLVE else "-"
            verified = sum(m.ok for m in cases)
            lines.append(f"{form:<14}{knots:>6}{median:>19.3f}s{speedup:>10}{setup:>8.2f}s{PAPER_SETUP:>13.1f}s"
                         f"{verified:>8}/{len(cases)}")
    return "\n".join(lines)


def _guess_table(problems: list[Problem], paper: dict, default: dict, counts: tuple[int, ...]) -> str:
    """The paper's guess (straight line, t_f = time.guess) beside the timed line (ocpkit.planner.guesses) per knot
    count."""
    lines = ["", f"Initial guess: the paper's ({PAPER_GUESS}: straight line over t_f = time.guess) vs the timed line "
             f"({TIMED_GUESS}: straight line over a velocity/torque estimate of t_f), single shot",
             f"{'guess':<8}{'knots':>6}{'median computation':>20}{'iterations':>12}{'per case':>18}{'verified':>10}"]
    for label, measured in ((PAPER_GUESS, paper), (TIMED_GUESS, default)):
        for knots in counts:
            cases = [measured[p.name, knots] for p in problems]
            lines.append(f"{label:<8}{knots:>6}{statistics.median(m.solve_time for m in cases):>19.3f}s"
                         f"{sum(m.iterations for m in cases):>12}{' '.join(str(m.iterations) for m in cases):>18}"
                         f"{sum(m.ok for m in cases):>8}/{len(cases)}")
    return "\n".join(lines)


def _baseline_table(problems: list[Problem], simultaneous: dict, baseline: dict, matched: dict) -> str:
    head = f"{'':<26}" + "".join(f"{p.name:>{WIDTH}}" for p in problems)
    lines = ["", "Path-velocity decomposition baseline (OMPL RRTConnect + TOPP-RA), same problems, same verify",
             head, "-" * len(head)]
    stat = lambda key: [baseline[p.name].extra.get(key, 0.0) for p in problems]  # noqa: E731
    cells = {
        "t_f baseline": [f"{baseline[p.name].tf:.3f}" for p in problems],
        "t_f simultaneous": [f"{simultaneous[p.name].tf:.3f}" for p in problems],
        "ratio sim / baseline": [f"{simultaneous[p.name].tf / baseline[p.name].tf:.3f}"
                                 for p in problems],
        "t_f sim, matched": [f"{matched[p.name].tf:.3f} {matched[p.name].status[:3]}"
                             for p in problems],
        "ratio matched / baseline": [f"{matched[p.name].tf / baseline[p.name].tf:.3f}"
                                     for p in problems],
        "computation [s]": [f"{baseline[p.name].solve_time:.3f}" for p in problems],
        "  path + simplify [s]": [f"{a + b:.3f}" for a, b in zip(stat("path_time_s"), stat("simplify_time_s"))],
        "  smoothing [s]": [f"{t:.3f}" for t in stat("smooth_time_s")],
        "  TOPP-RA [s]": [f"{t:.3f}" for t in stat("toppra_time_s")],
        "status": [baseline[p.name].status for p in problems],
    }
    lines += [f"{label:<26}" + "".join(f"{c:>{WIDTH}}" for c in row) for label, row in cells.items()]
    for p in problems:
        lines.append(f"  {p.name} baseline checks: {baseline[p.name].checks}")
    lines.append("  matched: the simultaneous planner given only what TOPP-RA enforces (torque-rate limits x1000, "
                 "mu = 0.001), verified against those relaxed limits")
    return "\n".join(lines)


def _same_limits_table(problems: list[Problem], simultaneous: dict, toppra: dict, topp3: dict) -> str:
    """Per case: ompl-toppra (t_f, status, largest violation), ompl-topp3 (t_f, status, computation), the
    simultaneous planner (t_f, computation) and t_f(simultaneous) / t_f(ompl-topp3)."""
    head = f"{'':<30}" + "".join(f"{p.name:>{WIDTH}}" for p in problems)
    lines = ["", "Decomposition held to the same limits and cost (ompl-topp3: the same OMPL path, quintic, timing OCP "
             "with torque-rate limits and the jerk cost)", head, "-" * len(head)]
    cells = {
        "ompl-toppra t_f [s]": [f"{toppra[p.name].tf:.3f}" for p in problems],
        "ompl-toppra status": [toppra[p.name].status for p in problems],
        "ompl-toppra violation": [f"{toppra[p.name].max_violation:.3g}" for p in problems],
        "ompl-topp3 t_f [s]": [f"{topp3[p.name].tf:.3f}" for p in problems],
        "ompl-topp3 status": [topp3[p.name].status for p in problems],
        "ompl-topp3 computation [s]": [f"{topp3[p.name].solve_time:.3f}" for p in problems],
        "simultaneous t_f [s]": [f"{simultaneous[p.name].tf:.3f}" for p in problems],
        "simultaneous computation [s]": [f"{simultaneous[p.name].solve_time:.3f}" for p in problems],
        "ratio sim / ompl-topp3": [f"{simultaneous[p.name].tf / topp3[p.name].tf:.3f}" for p in problems],
    }
    lines += [f"{label:<30}" + "".join(f"{c:>{WIDTH}}" for c in row) for label, row in cells.items()]
    lines.append("  violation: the largest excess over a limit (relative; the torque rate for ompl-toppra)")
    return "\n".join(lines)


def _seeding_table(seeding: dict) -> str:
    lines = ["", "Hybrid seeding at 12 knots: the paper's straight-line guess vs the OMPL + TOPP-RA motion as guess "
             "(the baseline's time included)", f"{'case':<12}{'guess':<7}{'status':>12}{'t_f':>8}{'time [s]':>10}"
             f"{'iterations':>12}"]
    for (name, guess), m in seeding.items():
        lines.append(f"{name:<12}{guess:<7}{m.status:>12}{m.tf:>8.3f}{m.solve_time:>10.2f}"
                     f"{m.iterations:>12}")
    return "\n".join(lines)


def _row(label: str, knots: int, cells: list[str]) -> str:
    return f"{label:<20}{knots:>6}" + "".join(f"{c:>{WIDTH}}" for c in cells)
