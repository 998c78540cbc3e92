"""Solver × dynamics benchmark (`ocpkit bench solvers`): every registered NLP solver with every dynamics backend
on the paper cases, through the same `plan(...)` call, verified by the same dense checks.

A combination that cannot run (a solver that needs a symbolic graph given a callback backend, a QP solver
that rejects the NLP's structure) is recorded with status `unsupported` and the reason; one that runs but
does not verify keeps its status (`time_limit`, `iteration_limit`, `failed`, `violated`, ...) and the solver's
last message. Solve time is one plan's wall time with its NLP already built (refinement rounds and dense
verification included), median over `repeats` runs and then over the cases; set-up is the first build of
the shape (the cases share one shape, so the first case pays it). Every combination runs in the same process.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass
from pathlib import Path

from ocpkit.bench.common import Measured, load_all, machine, measure, write_csv
from ocpkit.dynamics import DYNAMICS
from ocpkit.errors import OcpkitError
from ocpkit.formats.record import RESULT_COLUMNS, max_violation, result_row
from ocpkit.problem import Problem
from ocpkit.solvers import SOLVERS

VARIANTS = {"sqpmethod": ((("qpsol", "osqp"),),)}
"""Solver options benchmarked besides each solver's defaults."""
REFERENCE = ("ipopt", "casadi-rnea")
"""The combination whose t_f the others are compared with (the default one)."""


@dataclass(frozen=True)
class Combination:
    """A solver with its options ((name, value) pairs) and a dynamics backend."""

    solver: str
    dynamics: str
    options: tuple[tuple[str, object], ...] = ()

    @property
    def label(self) -> str:
        """The solver's name with its non-default options, e.g. `sqpmethod[qpsol=osqp]`."""
        extra = ",".join(f"{k}={v}" for k, v in self.options)
        return f"{self.solver}[{extra}]" if extra else self.solver


@dataclass(frozen=True)
class Outcome:
    """One combination on one case: the measurement, or the reason it could not run."""

    measured: Measured | None
    reason: str = ""

    @property
    def status(self) -> str:
        return self.measured.plan.status if self.measured else "unsupported"

    @property
    def why(self) -> str:
        """Why it did not verify ('' if it did): the reason it could not run, or the solver's last message."""
        if self.measured is None:
            return self.reason
        plan = self.measured.plan
        if plan.ok:
            return ""
        return plan.verification.summary() if plan.status == "violated" else plan.stats.solver_message


def combinations(solvers: tuple[str, ...] | None = None, dynamics: tuple[str, ...] | None = None) -> list[Combination]:
    """Every solver (defaults, then its VARIANTS) × every dynamics backend; None means all registered."""
    entries = [(s, options) for s in (solvers or SOLVERS.names()) for options in ((), *VARIANTS.get(s, ()))]
    return [Combination(s, d, options) for s, options in entries for d in (dynamics or DYNAMICS.names())]


def run_combination(problem: Problem, combination: Combination, method: dict, repeats: int,
                    max_wall_time: float) -> Outcome:
    """Plan `problem` with `combination` and the transcription `method` (transcription, knots,
    transcription_options); an OcpkitError (the combination cannot run) becomes the reason."""
    options = {"max_wall_time": max_wall_time, **dict(combination.options)}
    try:
        return Outcome(measure(problem, repeats, **method, solver=combination.solver,
                               dynamics=combination.dynamics, solver_options=options))
    except OcpkitError as exc:
        return Outcome(None, str(exc))


def run_solver_benchmark(scenarios: Path, out: Path, solvers: tuple[str, ...] | None = None,
                         dynamics: tuple[str, ...] | None = None, knots: int = 12, repeats: int = 1,
                         max_wall_time: float = 30.0, transcription: str = "chebyshev",
                         transcription_options: dict | None = None) -> list[dict]:
    """Run every combination on every scenario in `scenarios` with the transcription (its `knots` and
    `transcription_options`, e.g. {"staged": True} for fatrop's stage structure); print the table sorted by median
    solve time and the recommended default; write `out`/results.csv (the paper suite's columns).
    `max_wall_time` (s) limits each NLP solve."""
    problems = load_all(Path(scenarios))
    method = {"transcription": transcription, "knots": knots, "transcription_options": transcription_options or {}}
    outcomes: dict[Combination, list[Outcome]] = {}
    for combination in combinations(solvers, dynamics):
        outcomes[combination] = [run_combination(p, combination, method, repeats, max_wall_time) for p in problems]
        print(f"  {combination.label} + {combination.dynamics}: "
              f"{', '.join(o.status for o in outcomes[combination])}", flush=True)
    rows = [_row(p, c, o) for c, row in outcomes.items() for p, o in zip(problems, row)]
    write_csv(out / "results.csv", rows)
    options = "".join(f" {k}={v}" for k, v in method["transcription_options"].items())
    print(solver_table(problems, outcomes, f"{transcription}{options} at {knots} knots"))
    print(recommendation(outcomes))
    print(f"{machine()}; solve times are "
          f"medians of {repeats} run(s) per plan, then over the cases; each NLP solve limited to {max_wall_time:g} s")
    return rows


def _row(problem: Problem, combination: Combination, outcome: Outcome) -> dict:
    """The results.csv row; an unsupported combination has its names and status only."""
    names = {"solver": combination.label, "dynamics": combination.dynamics}
    if outcome.measured is None:
        return {**dict.fromkeys(RESULT_COLUMNS, ""), "suite": "solvers", "case": problem.name,
                "planner": "simultaneous", **names, "status": "unsupported"}
    m = outcome.measured
    return {**result_row("solvers", problem.name, m.plan, m.solve_time, m.setup_time), **names}


def median_solve_time(row: list[Outcome]) -> float:
    """Median solve time (s) over the cases that ran; inf if none did."""
    times = [o.measured.solve_time for o in row if o.measured]
    return statistics.median(times) if times else math.inf


def solver_table(problems: list[Problem], outcomes: dict[Combination, list[Outcome]], transcription: str) -> str:
    """One line per combination, fastest median solve time first; t_f deviation relative to REFERENCE."""
    reference = next((row for c, row in outcomes.items() if (c.solver, c.dynamics) == REFERENCE and not c.options),
                     None)
    head = (f"{'solver':<24}{'dynamics':<16}{'verified':>9}{'solve [s]':>11}{'set-up [s]':>11}{'iter':>6}"
            f"{'Δt_f [%]':>10}{'worst viol.':>12}  why not verified")
    lines = [f"Solvers x dynamics backends, {transcription}, {len(problems)} cases "
             f"(Δt_f: largest deviation from {' + '.join(REFERENCE)})", head, "-" * len(head)]
    for combination, row in sorted(outcomes.items(), key=lambda item: median_solve_time(item[1])):
        ran = [o.measured for o in row if o.measured]
        verified = sum(o.status == "verified" for o in row)
        setup = max((m.setup_time for m in ran), default=math.nan)
        iterations = statistics.median(m.plan.stats.iterations for m in ran) if ran else math.nan
        deviation = _tf_deviation(row, reference)
        worst = max((max_violation(m.plan) for m in ran), default=math.nan)
        why = "; ".join(sorted({f"{o.status}: {o.why[:70]}" for o in row if o.status != "verified"}))
        lines.append(f"{combination.label:<24}{combination.dynamics:<16}{verified:>7}/{len(row)}"
                     f"{median_solve_time(row):>11.3f}{setup:>11.2f}{iterations:>6.0f}{deviation:>10.3f}"
                     f"{worst:>12.3g}  {why}")
    return "\n".join(lines)


def _tf_deviation(row: list[Outcome], reference: list[Outcome] | None) -> float:
    """Largest |t_f − t_f_ref| / t_f_ref in % over the cases both verified; nan if none."""
    if reference is None:
        return math.nan
    pairs = [(o.measured.plan.trajectory.tf, r.measured.plan.trajectory.tf) for o, r in zip(row, reference)
             if o.status == "verified" and r.status == "verified"]
    return max((100 * abs(tf - ref) / ref for tf, ref in pairs), default=math.nan)


def recommendation(outcomes: dict[Combination, list[Outcome]]) -> str:
    """The fastest combination that verifies every case: the one to keep as the default."""
    everywhere = [(median_solve_time(row), c) for c, row in outcomes.items()
                  if all(o.status == "verified" for o in row)]
    if not everywhere:
        return "no combination verified every case"
    time, best = min(everywhere, key=lambda item: item[0])
    return (f"fastest combination verified on every case: solver {best.label}, dynamics {best.dynamics} "
            f"(median {time:.3f} s); {len(everywhere)} of {len(outcomes)} combinations verified every case")
