"""`ocpkit report DIR`: one self-contained HTML page (figures embedded as base64 PNG) and a Markdown summary of a
`bench run` output folder, plus its OMPL benchmark logs for Planner Arena (ocpkit.bench.arena).

Tables: the metrics (ocpkit.bench.metrics) per method and per method on each scene, where the time goes per method
on each scene (`time_split`), success per method × scene.
Figures: the success grid, the computation-time distribution per method, t_f against computation time, and for
one plan (`plan`: a trajectory file; default the first verified row's) joint position, velocity, torque and
torque rate against their limits. The figures show every plan that found a trajectory (the tables: verified
ones only). matplotlib with the headless Agg backend.
"""

from __future__ import annotations

import base64
import csv
import html
import io
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ocpkit.bench.arena import write_arena_logs  # noqa: E402
from ocpkit.bench.metrics import formatted, success_grid, summarize, time_split  # noqa: E402
from ocpkit.errors import OptionError  # noqa: E402
from ocpkit.formats.scenario import load_scenario  # noqa: E402
from ocpkit.robots import Robot  # noqa: E402

DPI = 100


def read_results(folder: Path) -> list[dict]:
    """The rows of folder/results.csv; OptionError if there is none."""
    path = folder / "results.csv"
    if not path.is_file():
        raise OptionError(f"{path} does not exist: give the --out folder of `ocpkit bench run`")
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    if not rows or "method" not in rows[0]:
        raise OptionError(f"{path} has no rows of `ocpkit bench run` (columns method, scene, ...)")
    return rows


def write_report(folder: Path, plan: Path | None = None) -> tuple[Path, Path]:
    """report.html and report.md in `folder` (and planner-arena/*.log); returns the two paths."""
    rows = read_results(folder)
    chosen = _chosen(folder, rows, plan)
    tables = {"Per method": summarize(rows, ("method",)), "Per method and scene": summarize(rows, ("method", "scene")),
              "Where the time goes, per method and scene (medians over every plan)": time_split(
                  rows, ("method", "scene"))}
    methods, scenes, rates = success_grid(rows)
    figures = {"Success per method and scene (%)": _success_figure(methods, scenes, rates),
               "Computation time per method": _time_figure(rows, methods),
               "Motion time against computation time (hollow: not verified)": _tf_figure(rows, methods)}
    if chosen is not None:
        figures[f"Plan {chosen.relative_to(folder) if chosen.is_relative_to(folder) else chosen}"] = \
            _plan_figure(folder, rows, chosen)
    suite = rows[0]["suite"]
    write_arena_logs(rows, folder / "planner-arena", suite)
    html_path, md_path = folder / "report.html", folder / "report.md"
    html_path.write_text(_html(suite, tables, figures, len(rows)))
    md_path.write_text(_markdown(suite, tables, methods, scenes, rates, len(rows)))
    return html_path, md_path


def _chosen(folder: Path, rows: list[dict], plan: Path | None) -> Path | None:
    if plan is not None:
        path = plan if plan.is_absolute() or plan.exists() else folder / plan
        if not path.is_file():
            raise OptionError(f"--plan {plan}: no such trajectory file (in {folder} or the current folder)")
        return path
    verified = [r for r in rows if r["status"] == "verified"]
    return folder / verified[0]["trajectory"] if verified else None


def _png(figure: plt.Figure) -> str:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=DPI, bbox_inches="tight")
    plt.close(figure)
    return base64.b64encode(buffer.getvalue()).decode("ascii")


def _success_figure(methods: list, scenes: list, rates: np.ndarray) -> str:
    figure, axes = plt.subplots(figsize=(1.6 + 1.2 * len(scenes), 0.8 + 0.5 * len(methods)))
    axes.imshow(np.nan_to_num(rates, nan=-1), cmap="RdYlGn", vmin=0, vmax=100, aspect="auto")
    axes.set_xticks(range(len(scenes)), scenes, rotation=30, ha="right")
    axes.set_yticks(range(len(methods)), methods)
    for (i, j), rate in np.ndenumerate(rates):
        axes.text(j, i, formatted(float(rate)), ha="center", va="center")
    return _png(figure)


def _found(rows: list[dict], method: str) -> list[dict]:
    """The rows of `method` whose planner found a trajectory (verified or not)."""
    return [r for r in rows if r["method"] == method and r["path_length_rad"] != ""]


def _time_figure(rows: list[dict], methods: list) -> str:
    figure, axes = plt.subplots(figsize=(7, 0.8 + 0.5 * len(methods)))
    data = [[float(r["solve_time_s"]) for r in _found(rows, m)] or [np.nan] for m in methods]
    axes.boxplot(data, orientation="horizontal", tick_labels=methods)
    axes.set_xscale("log")
    axes.set_xlabel("computation time [s] of the plans that found a trajectory")
    return _png(figure)


def _tf_figure(rows: list[dict], methods: list) -> str:
    figure, axes = plt.subplots(figsize=(7, 4.5))
    for method, color in zip(methods, plt.rcParams["axes.prop_cycle"].by_key()["color"] * len(methods)):
        for ok, fill in ((True, color), (False, "none")):
            mine = [r for r in _found(rows, method) if (r["status"] == "verified") == ok]
            if not mine:
                continue
            axes.scatter([float(r["solve_time_s"]) for r in mine], [float(r["tf"]) for r in mine], s=22,
                         facecolors=fill, edgecolors=color, label=f"{method} ({'verified' if ok else 'not verified'})")
    axes.set_xscale("log")
    axes.set_xlabel("computation time [s]")
    axes.set_ylabel("motion time $t_f$ [s]")
    axes.legend(fontsize="small")
    return _png(figure)


def _plan_figure(folder: Path, rows: list[dict], path: Path) -> str:
    """Joint position, velocity, torque and torque rate of the trajectory at `path` against the robot's limits."""
    document = json.loads(path.read_text())
    if not document.get("samples"):
        raise OptionError(f"{path} holds no samples ({document.get('samples_omitted', 'no trajectory found')})")
    robot = _robot_of(folder, rows, path)
    samples = {k: np.asarray(v) for k, v in document["samples"].items()}
    t = samples["t"]
    taud = np.gradient(samples["tau"], t, axis=0)
    panels = (("position [rad]", samples["q"], robot.q_lower, robot.q_upper),
              ("velocity [rad/s]", samples["qd"], -robot.qd_max, robot.qd_max),
              ("torque [N m]", samples["tau"], -robot.tau_max, robot.tau_max),
              ("torque rate [N m/s]", taud, -robot.taud_max, robot.taud_max))
    figure, grid = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    for axes, (label, values, lower, upper) in zip(grid.flat, panels):
        for j in range(values.shape[1]):
            line, = axes.plot(t, values[:, j], lw=1.2, label=robot.joint_names[j])
            axes.axhline(upper[j], color=line.get_color(), ls="--", lw=0.7)
            axes.axhline(lower[j], color=line.get_color(), ls="--", lw=0.7)
        axes.set_ylabel(label)
    for axes in grid[1]:
        axes.set_xlabel("t [s]")
    grid[0, 0].legend(fontsize="x-small", ncol=2)
    figure.suptitle(f"{document.get('robot')}: {json.dumps(document.get('method'))}, status {document['status']} "
                    "(dashed: limits)", fontsize="small")
    return _png(figure)


def _robot_of(folder: Path, rows: list[dict], path: Path) -> Robot:
    """The robot of the row whose trajectory is `path` (from its scenario file under folder/scenarios)."""
    row = next((r for r in rows if (folder / r["trajectory"]).resolve() == path.resolve()), None)
    if row is None:
        raise OptionError(f"--plan {path}: not a trajectory of {folder / 'results.csv'}")
    return load_scenario(folder / "scenarios" / row["scene"] / f"{row['case']}.yaml").robot


def _html(suite: str, tables: dict, figures: dict, count: int) -> str:
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>ocpkit report: {html.escape(suite)}</title>"
             "<style>body{font-family:sans-serif;margin:2em;max-width:1200px}table{border-collapse:collapse;"
             "margin-bottom:1.5em;font-size:0.9em}td,th{border:1px solid #ccc;padding:3px 8px;text-align:right}"
             "th{background:#eee}td:first-child,td:nth-child(2){text-align:left}img{max-width:100%}</style></head>"
             f"<body><h1>Benchmark {html.escape(suite)}</h1><p>{count} plans. Success = verified by the dense "
             "re-check. Times (s) over the verified plans; t_f, path lengths and peak uses are their medians.</p>"]
    for title, rows in tables.items():
        head = list(rows[0])
        parts.append(f"<h2>{title}</h2><table><tr>{''.join(f'<th>{html.escape(h)}</th>' for h in head)}</tr>")
        parts += ["<tr>" + "".join(f"<td>{html.escape(formatted(r[h]))}</td>" for h in head) + "</tr>" for r in rows]
        parts.append("</table>")
    for title, png in figures.items():
        parts.append(f"<h2>{html.escape(title)}</h2><img alt='{html.escape(title)}' src='data:image/png;base64,{png}'>")
    return "\n".join(parts) + "\n</body></html>\n"


def _markdown(suite: str, tables: dict, methods: list, scenes: list, rates: np.ndarray, count: int) -> str:
    lines = [f"# Benchmark {suite}", "", f"{count} plans; success = verified; times (s) over the verified plans, "
             "t_f, path lengths and peak uses their medians. Figures: report.html.", ""]
    for title, rows in tables.items():
        head = list(rows[0])
        lines += [f"## {title}", "", "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(formatted(r[h]) for h in head) + " |" for r in rows]
        lines.append("")
    lines += ["## Success per method and scene (%)", "", "| method | " + " | ".join(scenes) + " |",
              "|" + "---|" * (len(scenes) + 1)]
    lines += [f"| {m} | " + " | ".join(formatted(float(v)) for v in rates[i]) + " |" for i, m in enumerate(methods)]
    return "\n".join(lines) + "\n"


