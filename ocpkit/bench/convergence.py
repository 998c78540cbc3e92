"""Convergence study (`ocpkit bench convergence`): how fast each transcription approaches the continuous optimum.

One paper case, two variants of it:

  paper    the case as it is (μ = 0.3): the time-optimal motion rides velocity/torque-rate limits and the
           obstacle, so the optimum has constraint-switch kinks that no single polynomial resolves; spectral
           convergence is spoilt and every method converges algebraically.
  smooth   μ = 30 and no obstacle (the workspace box stays): no bound is active, the optimum is smooth.

For each registered transcription among chebyshev / lgr / hermite-simpson / trapezoidal and each knot count of the
sweep we plan once (`refinements=0`, so every point solves the same continuous problem: a refinement round
would change the margin and limits depending on what it found) and record status, t_f, |t_f − t_f_ref|, the
dense dynamics residual (the `dynamics` check of `verify`: max |τ − rnea(q, q̇, q̈) − friction| over a 1 ms grid,
relative to the torque range 2 τ_max), solve time and iterations. IPOPT runs with tol = 1e-9 so the solver's
own tolerance sits below the discretization errors we measure.

References (the t_f_ref against which t_f errors are measured):
  paper    hermite-simpson at 80 intervals: a local method converges at its algebraic rate even through the
           constraint switches (which a global polynomial cannot), and imposes the path constraints at 161
           points. Paper-case errors as small as its own discretization error (estimated by the finest
           trapezoidal point's distance from it; figures: docs/design/moved-from-code.md) lie within the
           reference's uncertainty.
  smooth   chebyshev at 32: with no active bound the Euler–Lagrange equation of t_f + μ∫q⃛ᵀQq⃛ dt is q⁽⁶⁾ = 0,
           so the optimal q(t) is a quintic, which a degree-N Chebyshev polynomial (N ≥ 5) represents
           exactly.
"""

from __future__ import annotations

import csv
import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ocpkit.bench.common import measure, write_csv
from ocpkit.formats.scenario import load_scenario
from ocpkit.geometry.scene import Scene
from ocpkit.problem import Problem
from ocpkit.transcription.base import TRANSCRIPTIONS

DEFAULT_CASE = Path("scenarios/paper/case2.yaml")
SWEEP = {"chebyshev": (6, 8, 10, 12, 16, 20, 24),
         "chebyshev×3": (4, 6, 8),  # three equal segments (h–p): 3N + 1 points
         "lgr": (6, 8, 10, 12, 16, 20, 24),
         "hermite-simpson": (4, 6, 8, 12, 16, 24, 32),
         "trapezoidal": (8, 12, 16, 24, 32, 48, 64)}
REFERENCES = {"paper": ("hermite-simpson", 80), "smooth": ("chebyshev", 32)}
SMOOTH_MU = 30.0
STUDY_OPTIONS = {"refinements": 0, "solver_options": {"tol": 1e-9}}
COLUMNS = ("variant", "transcription", "knots", "points", "status", "tf", "tf_ref", "tf_error",
           "dynamics_residual", "solve_time_s", "setup_time_s", "iterations")
ERROR_FLOOR = 1e-12  # plotted in place of an error of exactly 0
STYLE = {"chebyshev": ("tab:blue", "o"), "chebyshev×3": ("tab:purple", "D"), "lgr": ("tab:orange", "v"),
         "hermite-simpson": ("tab:green", "s"), "trapezoidal": ("tab:red", "^")}


@dataclass(frozen=True)
class Variant:
    """A named problem and the (transcription, knots) whose t_f serves as its reference."""

    name: str
    problem: Problem
    reference: tuple[str, int]


def variants(case: Path, smooth_mu: float = SMOOTH_MU, references: dict = REFERENCES) -> list[Variant]:
    """The case as it is ("paper") and its smooth variant (μ = smooth_mu, obstacles removed)."""
    problem = load_scenario(case)
    smooth = dataclasses.replace(problem, mu=smooth_mu, scene=Scene(workspace=problem.scene.workspace),
                                 name=f"{problem.name}-smooth")
    return [Variant(name, p, references[name]) for name, p in (("paper", problem), ("smooth", smooth))
            if name in references]


def method(label: str) -> tuple[str, dict]:
    """(transcription name, options) of a sweep label: "NAME" or "NAME×K" for K pseudospectral segments."""
    name, _, segments = label.partition("×")
    return name, ({"segments": int(segments)} if segments else {})


def collocation_points(label: str, knots: int) -> int:
    """Points where the dynamics residual is imposed: N + 1 knots (K N + 1 with K segments; LGR collocates
    D X = h F at all but t_f of them), plus N midpoints for Hermite–Simpson."""
    name, options = method(label)
    return 2 * knots + 1 if name == "hermite-simpson" else options.get("segments", 1) * knots + 1


def solve_point(variant: Variant, transcription: str, knots: int, tf_ref: float = math.nan) -> dict:
    """Plan `variant` once with the sweep label `transcription` at `knots` and return its CSV row."""
    name, options = method(transcription)
    m = measure(variant.problem, 1, transcription=name, knots=knots, transcription_options=options, **STUDY_OPTIONS)
    tf = m.plan.trajectory.tf
    dynamics = next(c.worst for c in m.plan.verification.checks if c.name == "dynamics")
    return {"variant": variant.name, "transcription": transcription, "knots": knots,
            "points": collocation_points(transcription, knots), "status": m.plan.status, "tf": tf,
            "tf_ref": tf_ref, "tf_error": abs(tf - tf_ref), "dynamics_residual": dynamics,
            "solve_time_s": m.solve_time, "setup_time_s": m.setup_time, "iterations": m.plan.stats.iterations}


def run_convergence(out: Path, case: Path = DEFAULT_CASE, sweep: dict = SWEEP, references: dict = REFERENCES,
                    smooth_mu: float = SMOOTH_MU) -> list[dict]:
    """Sweep every registered transcription of `sweep` over its knot counts on both variants of `case`
    (those named in `references`); write out/convergence.csv and out/convergence.png, print the table."""
    out = Path(out)
    available = set(TRANSCRIPTIONS.names())
    rows = []
    for variant in variants(Path(case), smooth_mu, references):
        reference = solve_point(variant, *variant.reference)
        tf_ref = reference["tf"]
        print(f"{variant.name}: reference {variant.reference[0]} at {variant.reference[1]} knots, "
              f"t_f_ref = {tf_ref:.9f} s ({reference['status']})", flush=True)
        for transcription, counts in sweep.items():
            if method(transcription)[0] in available:
                rows += [solve_point(variant, transcription, n, tf_ref) for n in counts]
    write_csv(out / "convergence.csv", rows, COLUMNS)
    plot_convergence(rows, out / "convergence.png")
    print(table(rows))
    return rows


def read_rows(path: Path) -> list[dict]:
    """Rows written by `run_convergence` (convergence.csv), numbers parsed back."""
    with Path(path).open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        for key in ("knots", "points", "iterations"):
            row[key] = int(row[key])
        for key in ("tf", "tf_ref", "tf_error", "dynamics_residual", "solve_time_s", "setup_time_s"):
            row[key] = float(row[key])
    return rows


def algebraic_order(rows: list[dict], key: str) -> float:
    """p in error ≈ C · points^(−p): minus the least-squares slope of log error vs log points."""
    pts = [(math.log(r["points"]), math.log(max(r[key], ERROR_FLOOR))) for r in rows]
    x, y = np.array(pts).T
    return float(-np.polyfit(x, y, 1)[0])


def decades_per_ten_points(rows: list[dict], key: str) -> float:
    """Exponential rate: decades of error lost per 10 more points (least-squares slope of log10 error vs
    points); a straight line on a semi-log plot is spectral convergence."""
    x = np.array([r["points"] for r in rows], dtype=float)
    y = np.log10(np.maximum([r[key] for r in rows], ERROR_FLOOR))
    return float(-10.0 * np.polyfit(x, y, 1)[0])


def groups(rows: list[dict]) -> dict[tuple[str, str], list[dict]]:
    """Rows grouped by (variant, transcription), each sorted by points."""
    grouped: dict[tuple[str, str], list[dict]] = {}
    for row in rows:
        grouped.setdefault((row["variant"], row["transcription"]), []).append(row)
    return {k: sorted(v, key=lambda r: r["points"]) for k, v in grouped.items()}


def plot_convergence(rows: list[dict], path: Path) -> None:
    """Log–log grid: rows are the variants, columns |t_f − t_f_ref| and the dynamics residual vs points."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(dict.fromkeys(r["variant"] for r in rows))
    fig, axes = plt.subplots(len(names), 2, figsize=(10, 3.6 * len(names)), squeeze=False, sharex=True)
    titles = {"tf_error": "|t_f − t_f,ref|  [s]", "dynamics_residual": "dynamics residual (rel. to torque range)"}
    for (variant, transcription), group in groups(rows).items():
        color, marker = STYLE.get(transcription, ("k", "x"))
        for ax, key in zip(axes[names.index(variant)], titles):
            label = f"{transcription} ({rate_label(transcription, group, key)})"
            ax.loglog([r["points"] for r in group], [max(r[key], ERROR_FLOOR) for r in group],
                      marker=marker, color=color, label=label)
    for i, variant in enumerate(names):
        for ax, (key, title) in zip(axes[i], titles.items()):
            ax.set_title(f"{variant}: {title}", fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
            if key == "dynamics_residual":
                ax.axhline(0.01, color="gray", linestyle=":", linewidth=1)
    for ax in axes[-1]:
        ax.set_xlabel("collocation points (N + 1; Hermite–Simpson 2N + 1)")
        ax.set_xticks([5, 10, 20, 40, 80], ["5", "10", "20", "40", "80"])
        ax.minorticks_off()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def rate_label(transcription: str, group: list[dict], key: str) -> str:
    """Legend text: the exponential rate for Chebyshev, the algebraic order otherwise; errors all below
    1e-8 are the solver's tolerance, not a rate."""
    if max(r[key] for r in group) < 1e-8:
        return "at solver tolerance"
    if transcription.startswith("chebyshev"):
        return f"{decades_per_ten_points(group, key):.1f} decades / 10 points"
    return f"order {algebraic_order(group, key):.1f}"


def table(rows: list[dict]) -> str:
    """The compact printed table: one line per solve, then the fitted rates per (variant, method)."""
    head = (f"{'variant':<8}{'method':<17}{'N':>5}{'points':>7}{'status':>10}{'t_f [s]':>13}{'|Δt_f| [s]':>12}"
            f"{'dyn. resid.':>12}{'solve [s]':>10}{'iter':>6}")
    lines = [head, "-" * len(head)]
    for row in rows:
        lines.append(f"{row['variant']:<8}{row['transcription']:<17}{row['knots']:>5}{row['points']:>7}"
                     f"{row['status']:>10}{row['tf']:>13.7f}{row['tf_error']:>12.2e}{row['dynamics_residual']:>12.2e}"
                     f"{row['solve_time_s']:>10.2f}{row['iterations']:>6}")
    lines += ["", "fitted rates: algebraic order p (error ~ points^-p) | decades per 10 points"]
    for (variant, transcription), group in groups(rows).items():
        lines.append(f"{variant:<8}{transcription:<17} t_f: p = {algebraic_order(group, 'tf_error'):4.1f} | "
                     f"{decades_per_ten_points(group, 'tf_error'):4.2f}   dynamics: p = "
                     f"{algebraic_order(group, 'dynamics_residual'):4.1f} | "
                     f"{decades_per_ten_points(group, 'dynamics_residual'):4.2f}")
    return "\n".join(lines)
