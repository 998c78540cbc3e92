"""The figures the motion-planning benchmarks report (robometrics, cuRobo), per plan and per group of rows.

Per plan, from the dense samples: joint-space path length (rad, Σ‖Δq‖₂), end-effector path length (m, of the
tool frame: `end_effector_frame`), peak torque and torque-rate use (max over time and joints of |τ|/τ_max and
|τ̇|/τ̇_max; 1 is the limit). Per group (a method, or a method on a scene): runs, success (= verified) rate, and
over the verified runs the computation time's mean, median, 75th and 98th percentile, motion time t_f, the path
lengths and the peak uses (medians); and where the time goes (`time_split`, from each row's `extra` timing).
"""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin

from ocpkit.formats.trajectory import Samples
from ocpkit.robots import Robot

PLAN_METRICS = ("path_length_rad", "ee_path_length_m", "peak_torque_use", "peak_torque_rate_use")
"""The per-plan columns of a `bench run` results.csv (empty when the planner found no trajectory)."""


TOOL_FRAME_SUFFIXES = ("_tcp", "tool0", "flange", "ee_link")
"""Names of tool frames, by preference (panda_hand_tcp, UR's tool0, industrial6's flange, ee_link)."""


def end_effector_frame(robot: Robot) -> int:
    """The pinocchio frame id of the end effector: the first body frame rigidly attached to the last joint whose
    name ends in one of TOOL_FRAME_SUFFIXES (in that order), else the last joint's own frame."""
    model = robot.model
    last = model.njoints - 1
    bodies = [k for k, f in enumerate(model.frames) if f.parentJoint == last and f.type == pin.FrameType.BODY]
    for suffix in TOOL_FRAME_SUFFIXES:
        match = next((k for k in bodies if model.frames[k].name.endswith(suffix)), None)
        if match is not None:
            return match
    return model.getFrameId(model.names[last])


def end_effector_positions(robot: Robot, q: np.ndarray) -> np.ndarray:
    """World position (m) of the end-effector frame (`end_effector_frame`) at configurations q (K, n): (K, 3)."""
    data, frame = robot.model.createData(), end_effector_frame(robot)
    out = np.empty((len(q), 3))
    for k, qk in enumerate(q):
        pin.framesForwardKinematics(robot.model, data, qk)
        out[k] = data.oMf[frame].translation
    return out


def plan_metrics(robot: Robot, samples: Samples) -> dict[str, float]:
    """The PLAN_METRICS of a motion's dense `samples` on `robot` (module docstring)."""
    steps = lambda x: np.linalg.norm(np.diff(x, axis=0), axis=1).sum()  # noqa: E731
    return {"path_length_rad": float(steps(samples.q)),
            "ee_path_length_m": float(steps(end_effector_positions(robot, samples.q))),
            "peak_torque_use": float(np.max(np.abs(samples.tau) / robot.tau_max)),
            "peak_torque_rate_use": float(np.max(np.abs(samples.taud) / robot.taud_max))}


SUMMARY_COLUMNS = ("runs", "success_%", "time_mean_s", "time_median_s", "time_p75_s", "time_p98_s", "setup_median_s",
                   "all_median_s", "all_p90_s", "tf_s", "path_length_rad", "ee_path_length_m", "peak_torque_use",
                   "peak_torque_rate_use")
"""The columns of a summary row (after the group's names): computation times and the set-up's median over the
verified runs; `all_*`: computation plus set-up over every run, failures included (what a user waits); the rest
medians over the verified runs."""


SPLIT_COLUMNS = ("runs", "setup_s", "guess_s", "solves_s", "verify_s", "rest_s", "iterations", "ms_per_iteration",
                 "rounds", "rebuilds")
"""Where the time goes, medians over every run of a group, failures included (s unless named): the set-up (every
rung's builds); of the rung that gave the plan: its guess (an OMPL path's search, shortening, smoothing and timing),
its solves and its dense verifications over every refinement round; `rest_s`, the rest of the computation (the
other rungs tried, rebuilds, bookkeeping); the IPOPT iterations of every rung; the plan's rung's time per
iteration (its solves over its iterations), its refinement rounds and screening rebuilds."""


def summarize(rows: list[dict], by: tuple[str, ...]) -> list[dict]:
    """One summary row per distinct value of the `by` columns of results `rows`, sorted by those values (the rows'
    order, the order plans finished in, changes nothing): the group's names, then SUMMARY_COLUMNS (NaN where no run
    verified)."""
    return [{**names, **_figures(group)} for names, group in _grouped(rows, by)]


def time_split(rows: list[dict], by: tuple[str, ...]) -> list[dict]:
    """One row per distinct value of the `by` columns, sorted as in `summarize`: the group's names, then
    SPLIT_COLUMNS (NaN where no run records its timing in `extra`)."""
    return [{**names, "runs": len(group), **_split(group)} for names, group in _grouped(rows, by)]


def _grouped(rows: list[dict], by: tuple[str, ...]) -> list[tuple[dict, list[dict]]]:
    """(the `by` columns' values, the rows with them) per distinct value, sorted by those values' text."""
    groups: dict[tuple, list[dict]] = {}
    for row in rows:
        groups.setdefault(tuple(row[c] for c in by), []).append(row)
    ordered = sorted(groups, key=lambda names: tuple(map(str, names)))
    return [(dict(zip(by, names)), groups[names]) for names in ordered]


def _split(rows: list[dict]) -> dict:
    """SPLIT_COLUMNS after runs: each the median over the rows that have it (`_parts`), NaN where none has."""
    parts = [_parts(row) for row in rows]
    return {name: _median_known([p[name] for p in parts]) for name in SPLIT_COLUMNS[1:]}


def _median_known(values: list[float]) -> float:
    """The median of `values` without their NaNs; NaN if all are."""
    known = [v for v in values if not np.isnan(v)]
    return float(np.median(known)) if known else float("nan")


GUESS_PARTS = ("guess", "path_search", "simplify", "smooth", "path_timing")
"""The `timing` entries of a plan's `extra` that make its guess (the simultaneous planner's) or its path (a
baseline's)."""


def _parts(row: dict) -> dict:
    """SPLIT_COLUMNS of one results row (after runs); without a timing in its `extra` (a plan that ended before
    any solve, `no_path`) its whole computation is `rest_s` and the plan's rung's parts are NaN."""
    extra, nan = json.loads(row.get("extra") or "{}"), float("nan")
    known = {"setup_s": float(row.get("setup_time_s") or 0.0), "iterations": float(row.get("iterations") or 0),
             "rebuilds": float((extra.get("screening") or {}).get("rebuilds", nan))}
    timing, computation = extra.get("timing"), float(row["solve_time_s"])
    if not timing:
        return {**known, "guess_s": nan, "solves_s": nan, "verify_s": nan, "rest_s": computation, "rounds": nan,
                "ms_per_iteration": nan}
    rounds = timing.get("rounds") or []
    guess = sum(timing.get(name) or 0.0 for name in GUESS_PARTS)
    solves, verify = sum(r["solve"] for r in rounds), sum(r["verify"] for r in rounds)
    iterations = sum(r["iterations"] for r in rounds)
    return {**known, "guess_s": guess, "solves_s": solves, "verify_s": verify,
            "rest_s": max(computation - guess - solves - verify, 0.0), "rounds": float(len(rounds)),
            "ms_per_iteration": 1e3 * solves / iterations if iterations else nan}


def _figures(rows: list[dict]) -> dict:
    verified = [r for r in rows if r["status"] == "verified"]
    column = lambda name: np.array([float(r[name]) for r in verified])  # noqa: E731
    stat = lambda f, name: float(f(column(name))) if verified else float("nan")  # noqa: E731
    times = lambda q: (lambda x: np.percentile(x, q))  # noqa: E731
    setup = lambda r: float(r.get("setup_time_s") or 0.0)  # noqa: E731  (older results have no set-up column)
    waited = [float(r["solve_time_s"]) + setup(r) for r in rows]
    figures = {"runs": len(rows), "success_%": 100.0 * len(verified) / len(rows),
               "time_mean_s": stat(np.mean, "solve_time_s"), "time_median_s": stat(np.median, "solve_time_s"),
               "time_p75_s": stat(times(75), "solve_time_s"), "time_p98_s": stat(times(98), "solve_time_s"),
               "setup_median_s": float(np.median([setup(r) for r in verified])) if verified else float("nan"),
               "all_median_s": float(np.median(waited)), "all_p90_s": float(np.percentile(waited, 90)),
               "tf_s": stat(np.median, "tf")}
    figures.update({name: stat(np.median, name) for name in PLAN_METRICS})
    return figures


def success_grid(rows: list[dict], across: str = "scene", down: str = "method") -> tuple[list, list, np.ndarray]:
    """Success rate (%) per `down` × `across` value: (down values, across values, rates (D, A), NaN where no
    run)."""
    downs, acrosses = _distinct(rows, down), _distinct(rows, across)
    rates = np.full((len(downs), len(acrosses)), np.nan)
    for i, d in enumerate(downs):
        for j, a in enumerate(acrosses):
            cell = [r["status"] == "verified" for r in rows if r[down] == d and r[across] == a]
            if cell:
                rates[i, j] = 100.0 * np.mean(cell)
    return downs, acrosses, rates


def _distinct(rows: list[dict], column: str) -> list:
    """The values of `column` in `rows`, each once, sorted by their text."""
    return sorted({r[column] for r in rows}, key=str)


def formatted(value: object, digits: int = 3) -> str:
    """A table cell: floats to `digits` significant figures, NaN as '-'."""
    if isinstance(value, float):
        return "-" if np.isnan(value) else f"{value:.{digits}g}"
    return str(value)

