"""`ocpkit bench perf`: where the time of a plan goes, and how it grows.

Per plan of the paper cases at the paper's settings (chebyshev, 12 and 8 knots, single shot), the computation time
split into: the solver's NLP evaluations by kind (CasADi's t_wall_nlp_f, _g, _grad_f, _jac_g, _hess_l), the
solver's own work (IPOPT's call minus those callbacks), split into linear solves (MUMPS) and the rest of IPOPT
by the shares IPOPT's own timing statistics give on one extra plan per case (`ipopt_shares`), the iteration
callback (Python), the solver call's wrapper,
verification, the guess and the rest of Python; and by solve (the first, each refinement round). The one-time
set-up split into graph construction (the transcription's build), solver creation (nlpsol: CasADi generates and
sparsity-analyses its derivative functions there) and compilation (the dynamics rows' point derivatives, compiled
to C once per robot and machine and kept on disk: ocpkit.solvers.compiled; the fresh builds of a run find them
there after the first, so a cold compile is measured once on its own, in an empty directory). Medians and
95th percentiles over the repeats of all cases, ratios to the paper's figures; growth of computation and set-up
with knots, obstacle spheres and robot joints, as growth.png with a fitted power law.
"""

from __future__ import annotations

import csv
import dataclasses
import os
import re
import statistics
import tempfile
from dataclasses import dataclass
from pathlib import Path
from unittest import mock

import numpy as np
from tqdm import tqdm

from ocpkit.bench.common import load_all, machine
from ocpkit.bench.paper import PAPER_SETUP
from ocpkit.geometry.clearances import clearances, sphere_centers
from ocpkit.geometry.scene import Scene
from ocpkit.planner import plan
from ocpkit.planner.build_cache import clear_builds
from ocpkit.planner.ladder import SINGLE_SHOT
from ocpkit.planner.refinement import CALLBACKS
from ocpkit.problem import Problem, TimeBounds
from ocpkit.result import Plan
from ocpkit.robots import load_robot

PAPER_COMPUTATION = {12: 2.47, 8: 1.30}
"""The paper's median computation time (s) at 12 and 8 knots."""
KNOTS = (12, 8)
EVALUATIONS = CALLBACKS[:5]
PARTS = (*EVALUATIONS, "linear solves", "ipopt overhead", "iteration callback", "solver wrapper", "verification",
         "guess", "python")
"""The parts of a plan's computation time, in the order printed (module docstring)."""
GROWTH_KNOTS = (8, 12, 16, 24, 32)
GROWTH_OBSTACLES = (1, 2, 4, 8, 16, 32)
GROWTH_CASE = "case2"
CLUTTER_SEED = 0
CLUTTER_RADIUS = 0.05  # m, each extra obstacle sphere
CLUTTER_CLEARANCE = 0.1  # m, from the robot along the straight-line path


@dataclass(frozen=True)
class Sample:
    """One plan's figures (s): computation, its parts (PARTS), each solve's time (solve + verification), set-up
    and its parts (graph, solver; only on a plan that built), iterations, status."""

    computation: float
    parts: dict
    solves: list
    setup: float
    setup_parts: dict
    iterations: int
    status: str


def sample(result: Plan, linear_share: float = 0.0) -> Sample:
    """The figures of one simultaneous plan from its stats (stats.timing, ocpkit.planner.simultaneous);
    `linear_share`: the fraction of IPOPT's own work (its call less the callbacks) in linear solves."""
    timing = result.stats.timing
    rounds = timing.rounds
    parts = {kind: sum(r.callbacks.get(kind, 0.0) for r in rounds) for kind in EVALUATIONS}
    total = sum(r.callbacks.get("total", r.solve) for r in rounds)
    parts["iteration callback"] = sum(r.callbacks.get("callback_fun", 0.0) for r in rounds)
    internal = total - sum(parts[k] for k in EVALUATIONS) - parts["iteration callback"]
    parts["linear solves"], parts["ipopt overhead"] = linear_share * internal, (1 - linear_share) * internal
    parts["solver wrapper"] = timing.solve - total
    parts["verification"] = timing.verify
    parts["guess"] = timing.guess or 0.0
    parts["python"] = result.stats.solve_time - sum(parts.values())
    return Sample(result.stats.solve_time, parts, [r.solve + r.verify for r in rounds],
                  result.stats.setup_time, dict(timing.setup), result.stats.iterations, result.status)


def planned(problem: Problem, knots: int, fresh: bool = False, linear_share: float = 0.0, **options) -> Sample:
    """One single-shot plan of `problem` at `knots` (options as for `ocpkit.plan`); `fresh`: with an empty build
    cache and none of the parts builds share, so that it includes the whole set-up; `linear_share` as for
    `sample`."""
    if fresh:
        clear_builds(parts=True)
    return sample(plan(problem, knots=knots, fallbacks=SINGLE_SHOT, **options), linear_share)


def ipopt_timing(problem: Problem, knots: int) -> dict[str, float]:
    """IPOPT's own timing statistics (wall s) of one plan: `total` (OverallAlgorithm), `linear`
    (StdAugSystemSolverMultiSolve: factorizations and back-solves of the KKT system) and `evaluations`
    (Function Evaluations), read from its output file (print_timing_statistics)."""
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "ipopt.out"
        plan(problem, knots=knots, fallbacks=SINGLE_SHOT, solver_options={
            "output_file": str(log), "file_print_level": 3, "print_timing_statistics": "yes"})
        text = log.read_text()
    found = {key: re.findall(rf"^\s*{label}\.*:.*wall:\s*([0-9.]+)\)", text, re.MULTILINE)
             for key, label in (("total", "OverallAlgorithm"), ("linear", "StdAugSystemSolverMultiSolve"),
                                ("evaluations", "Function Evaluations"))}
    return {key: float(values[-1]) if values else 0.0 for key, values in found.items()}


def linear_share(timings: list[dict[str, float]]) -> float:
    """Median over `timings` (ipopt_timing) of the linear solves' share of IPOPT's own work (total less
    evaluations)."""
    return statistics.median(min(t["linear"] / max(t["total"] - t["evaluations"], 1e-9), 1.0) for t in timings)


def progress(items: list, label: str) -> tqdm:
    """`items` with a progress bar on stderr (gone when done)."""
    return tqdm(items, desc=label, unit="plan", leave=False)


def p95(values: list[float]) -> float:
    """The 95th percentile (linear interpolation)."""
    return float(np.percentile(values, 95))


def paper_split(problems: list[Problem], repeats: int, knots: tuple[int, ...] = KNOTS,
                guess: str = "line") -> dict[int, list[Sample]]:
    """Per knot count, `repeats` plans of each problem from `guess` after one that builds (its set-up kept as the
    first sample's), in one list."""
    out = {}
    for n in knots:
        samples = []
        share = linear_share([ipopt_timing(p, n) for p in problems])
        for p in progress(problems, f"{guess} guess, {n} knots"):
            first = planned(p, n, fresh=True, linear_share=share, guess=guess)
            repeated = [planned(p, n, linear_share=share, guess=guess) for _ in range(repeats)]
            samples += [dataclasses.replace(repeated[0], setup=first.setup, setup_parts=first.setup_parts),
                        *repeated[1:]]
        out[n] = samples
    return out


def split_table(split: dict[int, list[Sample]]) -> str:
    """The computation split (median, 95th percentile, share of the median total) and set-up split per knots."""
    lines = ["Computation time of one plan, split (chebyshev + ipopt, single shot; medians and 95th percentiles "
             "over all plans of all cases)",
             f"{'part':<22}" + "".join(f"{f'{n} knots: median':>18}{'p95':>9}{'share':>7}" for n in split)]
    medians = {n: statistics.median(s.computation for s in samples) for n, samples in split.items()}
    for part in PARTS:
        cells = ""
        for n, samples in split.items():
            values = [s.parts[part] for s in samples]
            cells += f"{statistics.median(values) * 1e3:>16.1f}ms{p95(values) * 1e3:>7.1f}ms" \
                     f"{100 * statistics.median(values) / medians[n]:>6.0f}%"
        lines.append(f"{part:<22}{cells}")
    rows = {"computation (wall)": lambda s: s.computation}
    for k in range(max(len(s.solves) for samples in split.values() for s in samples)):
        rows["solve 1 (first)" if k == 0 else f"round {k}"] = lambda s, k=k: s.solves[k] if k < len(s.solves) else 0
    for label, value in rows.items():
        cells = ""
        for n, samples in split.items():
            values = [value(s) for s in samples]
            cells += f"{statistics.median(values) * 1e3:>16.1f}ms{p95(values) * 1e3:>7.1f}ms{'':>7}"
        lines.append(f"{label:<22}{cells}")
    lines.append("linear solves / ipopt overhead: IPOPT's call less the callbacks, split by the share of "
                 "StdAugSystemSolverMultiSolve in IPOPT's timing statistics (median of one extra plan per case)")
    return "\n".join(lines)


def summary_table(splits: dict[str, dict[int, list[Sample]]]) -> str:
    """Per guess and knot count: median and p95 computation, the paper's figure and the ratio, iterations (median
    per plan), verified plans, set-up and its split (medians over the fresh builds), the paper's set-up."""
    lines = ["", f"{'guess':<7}{'knots':>6}{'computation':>13}{'p95':>8}{'paper':>8}{'speed-up':>10}{'iterations':>12}"
             f"{'verified':>10}{'set-up':>9}{'graph':>8}{'solver':>8}{'compile':>9}{'paper':>7}"]
    for guess, split in splits.items():
        lines += [f"{guess:<7}" + _summary_row(n, samples) for n, samples in split.items()]
    lines.append("line: the timed line guess (ocpkit.planner.guesses); paper: the paper's (straight line over "
                 "t_f = 10 s); compile: C compiled in the set-up, 0 when the disk cache had it")
    return "\n".join(lines)


def cold_compile(problem: Problem, knots: int) -> dict:
    """The set-up parts (s) of a fresh build of `problem` at `knots` with an empty disk cache of compiled C."""
    with tempfile.TemporaryDirectory() as folder, mock.patch.dict(os.environ, {"OCPKIT_COMPILED_DIR": folder}):
        return planned(problem, knots, fresh=True).setup_parts


def _summary_row(n: int, samples: list[Sample]) -> str:
    setups = [s for s in samples if s.setup > 0]
    median = statistics.median(s.computation for s in samples)
    paper = PAPER_COMPUTATION.get(n)
    return (f"{n:>6}{median:>12.3f}s{p95([s.computation for s in samples]):>7.3f}s"
            f"{(f'{paper:.2f}s' if paper else '-'):>8}{(f'{paper / median:.1f}x' if paper else '-'):>10}"
            f"{statistics.median(s.iterations for s in samples):>12.0f}"
            f"{sum(s.status == 'verified' for s in samples):>6}/{len(samples):<3}"
            f"{statistics.median(s.setup for s in setups):>8.2f}s"
            f"{statistics.median(s.setup_parts.get('graph', 0) for s in setups):>7.2f}s"
            f"{statistics.median(s.setup_parts.get('solver', 0) for s in setups):>7.2f}s"
            f"{statistics.median(s.setup_parts.get('compile', 0) for s in setups):>8.2f}s"
            f"{PAPER_SETUP:>6.1f}s")


def cluttered(problem: Problem, count: int, seed: int = CLUTTER_SEED) -> Problem:
    """`problem` with `count` obstacle spheres: its first, then spheres of CLUTTER_RADIUS drawn (seeded) in its
    workspace at least CLUTTER_CLEARANCE from the robot along the straight start-goal line (rows, not detours)."""
    scene = problem.scene
    lower, upper = ((scene.workspace.lower, scene.workspace.upper) if scene.workspace is not None
                    else (np.full(3, -1.5), np.full(3, 1.5)))
    line = problem.start + np.linspace(0, 1, 41)[:, None] * (problem.goal - problem.start)
    robot_centers = sphere_centers(problem.robot, line)
    rng = np.random.default_rng(seed)
    centers, radii = list(scene.obstacle_centers[:1]), list(scene.obstacle_radii[:1])
    while len(radii) < count:
        c = rng.uniform(lower + CLUTTER_RADIUS, upper - CLUTTER_RADIUS)
        trial = Scene(c[None], np.array([CLUTTER_RADIUS]))
        if clearances(problem.robot, trial, robot_centers).obstacles.min() >= CLUTTER_CLEARANCE:
            centers.append(c)
            radii.append(CLUTTER_RADIUS)
    return dataclasses.replace(problem, scene=Scene(np.array(centers), np.array(radii), scene.workspace),
                               name=f"{problem.name}-{count}-obstacles")


def panda_problem() -> Problem:
    """A 7-joint problem: the built-in Panda from the middle of its joint ranges by a third of each range (alternating
    sign) to rest, one obstacle sphere away from its path, no workspace box."""
    robot = load_robot("panda")
    middle, span = (robot.q_lower + robot.q_upper) / 2, robot.q_upper - robot.q_lower
    sign = np.where(np.arange(robot.n) % 2, -1.0, 1.0)
    start, goal = middle - sign * span / 6, middle + sign * span / 6
    base = Problem(robot, start, goal, Scene(np.zeros((0, 3)), np.zeros(0)), TimeBounds(), name="panda")
    return cluttered(dataclasses.replace(base, scene=Scene(np.array([[0.0, 0.0, 2.0]]), np.array([0.1]))), 1)


def growth_point(problem: Problem, knots: int, repeats: int) -> dict:
    """Set-up (s, a fresh build), median computation (s) over `repeats` and whether the last plan verified."""
    first = planned(problem, knots, fresh=True)
    samples = [planned(problem, knots) for _ in range(repeats)]
    return {"setup": first.setup, "computation": statistics.median(s.computation for s in samples),
            "iterations": samples[-1].iterations, "status": samples[-1].status}


def fitted_exponent(x: list[float], y: list[float]) -> float:
    """b of the least-squares fit y = a x^b in log-log."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


def growth(case: Problem, repeats: int, knots: tuple[int, ...], obstacles: tuple[int, ...]) -> list[dict]:
    """Rows (series, x, setup, computation, iterations, status): against knots, against obstacle spheres (12 knots),
    and the 6-joint case beside the 7-joint Panda (12 knots)."""
    points = [("knots", n, case, n) for n in knots] + [("obstacles", k, cluttered(case, k), 12) for k in obstacles]
    points += [("joints", p.robot.n, p, 12) for p in (case, panda_problem())]
    return [{"series": series, "x": x, **growth_point(problem, n, repeats)}
            for series, x, problem, n in progress(points, "growth")]


def growth_table(rows: list[dict]) -> str:
    """The growth rows and the fitted exponents of computation and set-up per series."""
    lines = ["", f"Growth on {GROWTH_CASE} (computation: median; set-up: a fresh build)",
             f"{'series':<11}{'x':>5}{'computation':>13}{'set-up':>9}{'iterations':>12}{'status':>10}"]
    lines += [f"{r['series']:<11}{r['x']:>5}{r['computation']:>12.3f}s{r['setup']:>8.2f}s{r['iterations']:>12}"
              f"{r['status']:>10}" for r in rows]
    for series, exponents in exponents_by_series(rows).items():
        lines.append(f"fitted exponent against {series}: computation ~ x^{exponents['computation']:.2f}, "
                     f"set-up ~ x^{exponents['setup']:.2f}")
    robots = [r for r in rows if r["series"] == "joints"]
    if len(robots) == 2:
        six, seven = robots
        lines.append(f"{seven['x']} joints (panda) vs {six['x']} ({GROWTH_CASE}): computation "
                     f"x{seven['computation'] / six['computation']:.1f}, set-up x{seven['setup'] / six['setup']:.1f}")
    return "\n".join(lines)


def exponents_by_series(rows: list[dict]) -> dict[str, dict[str, float]]:
    """The fitted power-law exponent of computation and set-up against knots and obstacles (with at least two x
    values each); two robots are compared by ratio instead."""
    out = {}
    for series in ("knots", "obstacles"):
        chosen = [r for r in rows if r["series"] == series]
        if len({r["x"] for r in chosen}) > 1:
            x = [r["x"] for r in chosen]
            out[series] = {k: fitted_exponent(x, [r[k] for r in chosen]) for k in ("computation", "setup")}
    return out


def plot_growth(rows: list[dict], path: Path) -> None:
    """growth.png: computation and set-up against knots and obstacle spheres (log-log), and per robot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fits = exponents_by_series(rows)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for ax, series, label in zip(axes, ("knots", "obstacles", "joints"), ("knots N", "obstacle spheres",
                                                                          "robot joints")):
        chosen = [r for r in rows if r["series"] == series]
        x = [r["x"] for r in chosen]
        for key, marker in (("computation", "o-"), ("setup", "s--")):
            fit = f" (~x^{fits[series][key]:.2f})" if series in fits else ""
            ax.plot(x, [r[key] for r in chosen], marker, label=f"{key}{fit}")
        if series != "joints":
            ax.set_xscale("log")
            ax.set_yscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("seconds")
        ax.legend()
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"ocpkit cost growth ({GROWTH_CASE}, chebyshev + ipopt, single shot)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


def write_split_csv(path: Path, split: dict[int, list[Sample]]) -> None:
    """One row per plan: knots, status, iterations, computation, its parts, set-up and its parts (s)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["knots", "status", "iterations", "computation", *PARTS, "solves", "setup", "graph",
                         "solver", "compile"])
        for n, samples in split.items():
            for s in samples:
                writer.writerow([n, s.status, s.iterations, s.computation, *(s.parts[p] for p in PARTS),
                                 " ".join(f"{t:.6f}" for t in s.solves), s.setup, s.setup_parts.get("graph", ""),
                                 s.setup_parts.get("solver", ""), s.setup_parts.get("compile", "")])


def run_perf(scenarios: Path, out: Path, repeats: int = 5, quick: bool = False) -> dict[int, list[Sample]]:
    """Print the split and the growth; write split.csv, growth.csv and growth.png under `out`. `quick`: 2 repeats,
    growth at 8 and 12 knots, 1 and 2 obstacles."""
    problems = load_all(Path(scenarios))
    repeats = 2 if quick else repeats
    split = paper_split(problems, repeats)
    print(split_table(split), flush=True)
    print(summary_table({"line": split, "paper": paper_split(problems, repeats, guess="paper")}), flush=True)
    cold = cold_compile(problems[0], KNOTS[0])
    print(f"a cold compile ({problems[0].name}, {KNOTS[0]} knots, empty disk cache): set-up "
          f"{sum(cold.values()):.2f} s, of which compile {cold.get('compile', 0):.2f} s", flush=True)
    write_split_csv(out / "split.csv", split)
    case = next((p for p in problems if p.name == GROWTH_CASE), problems[0])
    rows = growth(case, 1 if quick else 3, GROWTH_KNOTS[:2] if quick else GROWTH_KNOTS,
                  GROWTH_OBSTACLES[:2] if quick else GROWTH_OBSTACLES)
    print(growth_table(rows))
    with (out / "growth.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    plot_growth(rows, out / "growth.png")
    print(machine())
    print(f"results: {(out / 'split.csv').resolve()}, growth.csv and growth.png")
    return split
