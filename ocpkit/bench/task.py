"""One task of `ocpkit bench run`: plan one scenario with one method once, in whatever process runs it.

A task is plain data (a dict: the scenario mapping, case, scene, method, repeat, suite), so a local worker
process or a Dask worker on another machine can run it; each process keeps its own build cache
(ocpkit.planner.build_cache) while it plans one scenario, so its later methods and repeats of a shape it has built skip
the set-up, and drops the builds screened for that scenario's motions when the scenario changes: no other problem
has their rows, and builds held from earlier problems (several per plan with the ladder's rungs and screening
rebuilds) fill the memory and slow later plans (figures: docs/design-notes.md). What later problems can share
stays, within the cache's memory budget, as in any process that plans many problems of one robot: unscreened
builds (the safety nets' timing NLPs) and the small parts every build of a robot shares (layouts, the dynamics
rows' derivatives and compiled code). The outcome is plain data too:
the results row and the trajectory JSON text, written by the process that collects the outcomes.
"""

from __future__ import annotations

import re
import tempfile
import time
from pathlib import Path

from ocpkit.bench.metrics import PLAN_METRICS, plan_metrics
from ocpkit.bench.suite import Method, Scenario
from ocpkit.formats.record import RESULT_COLUMNS, result_row, trajectory_header
from ocpkit.formats.scenario import problem_from_dict
from ocpkit.formats.trajectory import write_json
from ocpkit.planner import plan
from ocpkit.planner.build_cache import drop_screened
from ocpkit.planner.ladder import DEFAULT_LADDER
from ocpkit.problem import Problem
from ocpkit.result import Plan, finish

RUN_KEY_COLUMNS = ("suite", "scene", "case", "method", "repeat")
"""What names a row of a `bench run` results.csv: one per (scenario, method, repeat)."""
RUN_COLUMNS = (*RESULT_COLUMNS, "robot", "scene", "method", "repeat", "guess", "seed", "wall_time_s",
               *PLAN_METRICS, "trajectory")
"""The columns of a `bench run` results.csv: those of ocpkit.formats.record, the robot, scene, method label, repeat
(0-based), the initial guess and OMPL seed of the reported plan (the verified fallback rung's; empty where the
plan used none), the task's wall time (s, set-up
included) and the per-plan metrics (ocpkit.bench.metrics), and the trajectory file relative to the output."""


def make_task(suite: str, scenario: Scenario, method: Method, repeat: int) -> dict:
    """The plain-data task of `scenario` × `method` × `repeat`."""
    return {"suite": suite, "case": scenario.case, "scene": scenario.scene, "scenario": scenario.data,
            "method": {"label": method.label, "planner": method.planner, "options": method.options},
            "repeat": repeat}


def task_key(task: dict) -> tuple[str, ...]:
    """The RUN_KEY_COLUMNS of a task's row, as strings."""
    return (task["suite"], task["scene"], task["case"], task["method"]["label"], str(task["repeat"]))


def trajectory_file(task: dict) -> str:
    """Where the task's trajectory goes, relative to the output folder: trajectories/SCENE/CASE--METHOD--rR.json."""
    slug = re.sub(r"[^A-Za-z0-9_.=-]+", "_", task["method"]["label"])
    return f"trajectories/{task['scene']}/{task['case']}--{slug}--r{task['repeat']}.json"


def _guess_and_seed(planner: str, options: dict, seed: int | None, rung_name: str | None) -> tuple[str, int | None]:
    """The initial guess and OMPL seed of the plan a row reports: for the simultaneous planner, those of the
    fallback-ladder rung that gave it (ocpkit.planner.ladder) where the rung overrides the method's; no guess
    otherwise."""
    if planner != "simultaneous":
        return "", seed
    rung = next((r for r in options.get("fallbacks", DEFAULT_LADDER) if r.name == rung_name), None)
    guess = (rung.guess if rung else None) or options.get("guess", "paper")
    if rung is not None and rung.guess is not None:
        seed = rung.seed if guess == "ompl" else None
    return guess, seed


def _plan_or_failed(problem: Problem, method: Method, options: dict) -> Plan:
    """The method's plan; if the planner raises, a `failed` plan holding the start whose message names the
    exception (also in the row's `extra`), so one task's crash ends its own row, not the whole run."""
    started = time.perf_counter()
    try:
        return plan(problem, planner=method.planner, **options)
    except Exception as exc:  # noqa: BLE001 - any planner bug becomes this row's status
        from ocpkit.planner.ompl_seed import hold

        error = f"{method.planner} raised {type(exc).__name__}: {exc}"
        return finish(problem, hold(problem), "failed", {"planner": method.planner}, started, message=error,
                      extra={"error": error}, found=False)


_planning: tuple[str, str] | None = None  # the (suite, case) this process planned last (`run_task`)


def run_task(task: dict) -> dict:
    """Plan the task; return {"row": the results row (RUN_COLUMNS), "trajectory": the trajectory JSON text}.
    The process's screened builds are dropped first if its last task was another scenario (module docstring)."""
    global _planning
    scenario = (task["suite"], task["case"])
    if _planning != scenario:
        drop_screened()
        _planning = scenario
    started = time.perf_counter()
    problem = problem_from_dict(task["scenario"], name=task["case"])
    method = Method(**task["method"])
    options, seed = method.plan_options(task["repeat"])
    result = _plan_or_failed(problem, method, options)
    wall = time.perf_counter() - started
    row = result_row(task["suite"], task["case"], result, result.stats.solve_time, result.stats.setup_time)
    metrics = plan_metrics(problem.robot, result.trajectory.sample()) if result.found else dict.fromkeys(
        PLAN_METRICS, "")
    guess, seed = _guess_and_seed(method.planner, options, seed, result.method.get("rung"))
    row.update(robot=problem.robot.name, scene=task["scene"], method=method.label, repeat=task["repeat"],
               guess=guess, seed="" if seed is None else seed, wall_time_s=wall, trajectory=trajectory_file(task),
               **metrics)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "trajectory.json"
        write_json(path, result.trajectory, trajectory_header(problem, result),
                   time_bounds=(problem.time.min, problem.time.max))
        text = path.read_text()
    return {"row": row, "trajectory": text}
