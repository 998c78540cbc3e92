"""How general the simultaneous planner is: seeded random industrial6 problems it was never tuned on
(`ocpkit bench random`).

Each problem has a random start and goal inside most of the joint range and obstacle spheres in the way, in
the paper cases' workspace. With `obstacles=(1, 1)` (the original suite) that is one sphere near the wrist's
position halfway along the straight joint-space path. With another range (lo, hi) it is lo..hi spheres of
radius RADII, each near a different robot sphere of PATH_SPHERES at a random point of that path. Problems
whose start or goal is invalid are redrawn, and so are problems whose obstacles leave no room to pass: a problem
counts only once RRTConnect (seed PATH_SEED, at most PATH_CHECKS configurations checked, the planners' 0.01 m
margin, OMPL's own step: the one the published problem sets were drawn with) has connected its start and goal.
That certificate is a budget in collision checks, not seconds, so the same seed gives the same problems on any
machine; the planners under test never see its path.

Prints one line per problem (with the hint of a plan that did not verify), then the status counts and the
median and 90th-percentile computation time of the verified plans; with `out`, also results.csv, the trajectory
JSONs and each problem's scenario YAML (for tests/outside_check.py).
"""

from __future__ import annotations

import csv
from collections import Counter
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np
import yaml

from ocpkit.baselines.ompl_toppra import joint_path
from ocpkit.bench.common import machine
from ocpkit.errors import ScenarioError
from ocpkit.formats.record import RESULT_COLUMNS, result_row, trajectory_header
from ocpkit.formats.trajectory import write_json
from ocpkit.geometry.clearances import sphere_centers
from ocpkit.geometry.scene import Scene, Workspace
from ocpkit.planner import plan
from ocpkit.planner.ladder import DEFAULT_LADDER, OMPL_CHECKS, Rung
from ocpkit.problem import Problem, TimeBounds
from ocpkit.result import Plan
from ocpkit.robots import Robot, load_robot
from ocpkit.validation import validate

LOWER_DEG = [-150, -60, -60, -170, -110, -170]
UPPER_DEG = [150, 80, 120, 170, 90, 170]
WORKSPACE = Workspace(np.array([-1.0, -1.6, -0.3]), np.array([1.8, 1.6, 2.0]))
WRIST_SPHERE = 12
SINGLE_RADII = (0.1, 0.25)  # m, the original suite's one sphere
RADII = (0.08, 0.22)  # m, each sphere of the other suites
PATH_SPHERES = np.arange(4, 15)  # robot spheres that obstacles are placed near: upper arm to flange
PATH_FRACTIONS = (0.2, 0.8)  # where along the straight path
OFFSET = 0.1  # m, standard deviation of an obstacle's offset from its robot sphere
PATH_SEED = 1000  # OMPL seed of the room-to-pass certificate (unlike the planners' seeds 0, 1, 2, ...)
PATH_CHECKS = OMPL_CHECKS  # configurations the certificate may check: the budget of a ladder's OMPL rung


def random_problems(seed: int, count: int, obstacles: tuple[int, int] = (1, 1),
                    room_to_pass: bool | None = True) -> Iterator[Problem]:
    """`count` valid random problems for industrial6 with obstacles[0]..obstacles[1] obstacle spheres,
    deterministic in `seed`: each with a certified collision-free path (`room_to_pass` True), each without one
    (False: the draws the suite redraws, where the certificate's search found no path; most are blocked), or every
    valid draw (None) (module docstring)."""
    rng = np.random.default_rng(seed)
    robot = load_robot("industrial6")
    lower, upper = np.radians(LOWER_DEG), np.radians(UPPER_DEG)
    while count:
        start, goal = rng.uniform(lower, upper), rng.uniform(lower, upper)
        centers, radii = _obstacles(rng, robot, start, goal, obstacles)
        scene = Scene(centers, radii, WORKSPACE)
        problem = Problem(robot, start, goal, scene, TimeBounds(0.1, 10.0, 10.0), 0.3, f"random{count}")
        try:
            validate(problem)
        except ScenarioError:
            continue
        if room_to_pass is not None and room_to_pass != _passable(problem):
            continue
        count -= 1
        yield problem


def _passable(problem: Problem) -> bool:
    """Whether the room-to-pass certificate's search connects `problem`'s start and goal (module docstring)."""
    return joint_path(problem, planner_name="rrtconnect", planning_time=np.inf, seed=PATH_SEED, max_checks=PATH_CHECKS,
                      max_step=None) is not None


def _obstacles(rng: np.random.Generator, robot: Robot, start: np.ndarray, goal: np.ndarray,
               obstacles: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Obstacle centres (k, 3) and radii (k,), m, on the way from start to goal (module docstring)."""
    if tuple(obstacles) == (1, 1):  # the original suite, draw for draw
        return _near(rng, robot, start, goal, np.array([WRIST_SPHERE]), np.array([0.5]), SINGLE_RADII)
    k = int(rng.integers(obstacles[0], obstacles[1] + 1))
    spheres = rng.choice(PATH_SPHERES, k, replace=False)
    return _near(rng, robot, start, goal, spheres, rng.uniform(*PATH_FRACTIONS, k), RADII)


def _near(rng: np.random.Generator, robot: Robot, start: np.ndarray, goal: np.ndarray, spheres: np.ndarray,
          fractions: np.ndarray, radii: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """One obstacle per robot sphere index of `spheres` (k,), near that sphere's centre at the point `fractions`
    (k,) along the straight path, with a radius (m) drawn from `radii`: centres (k, 3), radii (k,)."""
    centers, sizes = np.zeros((len(spheres), 3)), np.zeros(len(spheres))
    for i, (sphere, fraction) in enumerate(zip(spheres, fractions)):
        centers[i] = sphere_centers(robot, (1 - fraction) * start + fraction * goal)[sphere] + rng.normal(0, OFFSET, 3)
        sizes[i] = rng.uniform(*radii)
    return centers, sizes


def run_random(seed: int = 1, count: int = 30, knots: int = 12, obstacles: tuple[int, int] = (1, 1),
               out: Path | None = None, fallbacks: Sequence[Rung] = DEFAULT_LADDER,
               planner: str = "simultaneous", blocked: bool = False) -> Counter:
    """Plan `count` random problems of `seed` (with `obstacles` spheres) with the simultaneous planner's defaults
    at `knots` and the ladder `fallbacks` (SINGLE_SHOT: the paper's one solve); print a line per problem, the
    summary and which rung verified how many; with `out`, write results.csv, the trajectories and the scenarios
    there. Returns the status counts. Another `planner` (e.g. "ompl-topp3") plans them with its defaults instead
    (`knots` and `fallbacks` are the simultaneous planner's). `blocked`: the draws without room to pass instead
    (`random_problems`), where a plan should end `no_path` with the checks it spent, within its budget."""
    statuses, rungs, verified_times, rows = Counter(), Counter(), [], []
    for problem in random_problems(seed, count, obstacles, room_to_pass=not blocked):
        own = {"knots": knots, "fallbacks": fallbacks} if planner == "simultaneous" else {}
        result = plan(problem, planner, **own)
        statuses[result.status] += 1
        if result.ok:
            verified_times.append(result.stats.solve_time)
            rungs[result.method.get("rung", "single shot")] += 1
        print(_line(problem, result), flush=True)
        if out is not None:
            rows.append(result_row("random", problem.name, result, result.stats.solve_time, result.stats.setup_time))
            _write_problem(Path(out), problem, result)
    if out is not None:
        _write_csv(Path(out) / "results.csv", rows)
    print(f"{dict(statuses)}; {_times(verified_times)} at {knots} knots; {machine()}")
    print(f"verified by rung: {dict(rungs)}")
    return statuses


def _line(problem: Problem, result: Plan) -> str:
    """The printed line of one problem: status, t_f, time, rounds, the ladder's rung (and every rung tried, when
    there were several), and when it did not verify, what failed, the plan's message (a failed search's checks)
    and the hint."""
    tried = result.stats.rungs
    trail = "" if len(tried) < 2 else " (tried " + ", ".join(f"{r.rung} {r.status} {r.time_s:.1f} s"
                                                            for r in tried) + ")"
    return (f"{problem.name:<10}{result.status:>16}  t_f {result.trajectory.tf:5.2f} s (bound "
            f"{problem.velocity_lower_bound():4.2f})  {result.stats.solve_time:5.2f} s  {result.stats.rounds} rounds"
            f"  rung {result.method.get('rung', '-')}{trail}"
            + ("" if result.ok else f"  {result.verification.summary()}; {result.stats.solver_message}; "
                                      f"hint: {result.hint}"))


def _times(seconds: list[float]) -> str:
    """Median and 90th percentile of the computation times (s) of the verified plans."""
    if not seconds:
        return "no verified plan"
    return (f"computation time of the {len(seconds)} verified plans: median {np.median(seconds):.2f} s, "
            f"90th percentile {np.percentile(seconds, 90):.2f} s")


def _write_problem(out: Path, problem: Problem, result: Plan) -> None:
    """The plan's trajectory JSON and the problem's scenario YAML under `out`."""
    write_json(out / "trajectories" / f"{problem.name}.json", result.trajectory, trajectory_header(problem, result),
               time_bounds=(problem.time.min, problem.time.max))
    (out / "scenarios").mkdir(parents=True, exist_ok=True)
    (out / "scenarios" / f"{problem.name}.yaml").write_text(yaml.safe_dump(_scenario(problem)))


def _scenario(problem: Problem) -> dict:
    """The scenario file's content (radians) of a random problem."""
    scene = problem.scene
    return {"name": problem.name, "robot": problem.robot.name, "unit": "rad", "start": problem.start.tolist(),
            "goal": problem.goal.tolist(),
            "scene": {"obstacles": [{"sphere": {"center": c.tolist(), "radius": float(r)}}
                                    for c, r in zip(scene.obstacle_centers, scene.obstacle_radii)],
                      "workspace": {"min": WORKSPACE.lower.tolist(), "max": WORKSPACE.upper.tolist()}},
            "time": {"min": problem.time.min, "max": problem.time.max, "guess": problem.time.guess},
            "cost": {"mu": problem.mu}}


def _write_csv(path: Path, rows: list[dict]) -> None:
    """results.csv with RESULT_COLUMNS."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as file:
        writer = csv.DictWriter(file, fieldnames=RESULT_COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
