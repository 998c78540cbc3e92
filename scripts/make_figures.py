"""Generate the figures of docs/transcription.md into docs/figures/.

    PYTHONPATH=. python scripts/make_figures.py            # all figures; re-plots convergence.csv if present
    PYTHONPATH=. python scripts/make_figures.py --rerun    # also re-run the convergence study (slow)

knots.png          Chebyshev–Lobatto knots vs uniform knots on [0, t_f]
dmatrix.png        the Chebyshev differentiation matrix D (N = 12) as a heat map
between_knots.png  case1 at 8 knots, no clearance margin, no refinement: the obstacle clearance of the
                   interpolant between knots, with knots and check times marked
convergence.png    the convergence study (ocpkit.bench.convergence), with its convergence.csv
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ocpkit import load_scenario, plan  # noqa: E402
from ocpkit.bench.convergence import plot_convergence, read_rows, run_convergence  # noqa: E402
from ocpkit.planner.build_cache import build  # noqa: E402
from ocpkit.geometry.clearances import clearances, sphere_centers  # noqa: E402
from ocpkit.transcription.polynomials import differentiation_matrix, lobatto_points  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
FIGURES = ROOT / "docs" / "figures"


def knot_placement(path: Path, knots: int = 12) -> None:
    """Chebyshev–Lobatto knots T_i = (t_f/2)(cos(iπ/N) + 1) against uniform knots, t_f = 1."""
    fig, ax = plt.subplots(figsize=(8, 2.2))
    cheb = (lobatto_points(knots) + 1.0) / 2.0
    ax.plot(cheb, np.ones_like(cheb), "o", color="tab:blue", label=f"Chebyshev–Lobatto, N = {knots}")
    ax.plot(np.linspace(0, 1, knots + 1), np.zeros(knots + 1), "^", color="tab:red", label=f"uniform, N = {knots}")
    theta = np.linspace(0, np.pi, 200)
    ax.plot((np.cos(theta) + 1) / 2, 1 + 0.45 * np.sin(theta), color="tab:blue", alpha=0.3)
    for c in cheb:
        ax.plot([c, c], [1, 1 + 0.45 * np.sqrt(max(0.0, 1 - (2 * c - 1) ** 2))], color="tab:blue", alpha=0.3, lw=0.8)
    ax.set_yticks([0, 1], ["uniform", "Chebyshev"])
    ax.set_ylim(-0.4, 1.6)
    ax.set_xlabel("t / t_f")
    ax.set_title("knots: equal angles on a half circle, projected (clustered at the ends) vs equal spacing", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def differentiation_heatmap(path: Path, knots: int = 12) -> None:
    """D (N = 12) on a symmetric log colour scale: dense, largest in the corners."""
    d = differentiation_matrix(knots)
    fig, ax = plt.subplots(figsize=(5, 4.3))
    limit = np.abs(d).max()
    image = ax.imshow(d, cmap="RdBu_r", norm=matplotlib.colors.SymLogNorm(linthresh=1.0, vmin=-limit, vmax=limit))
    fig.colorbar(image, ax=ax, shrink=0.85)
    ax.set_title(f"Chebyshev differentiation matrix D, N = {knots}\n"
                 f"D₀₀ = (2N² + 1)/6 = {d[0, 0]:.1f}; every row sums to 0", fontsize=9)
    ax.set_xlabel("j (knot value f_j)")
    ax.set_ylabel("i (derivative at s_i)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def between_knots(path: Path, knots: int = 8) -> dict:
    """case1 at `knots` with margin 0 and no refinement: obstacle clearance of the interpolant vs time, whole
    motion (left) and around its minimum (right), with the knots and the check times between them marked."""
    problem = load_scenario(ROOT / "scenarios" / "paper" / "case1.yaml")
    result = plan(problem, knots=knots, refinements=0, transcription_options={"margin": 0.0})
    traj, robot = result.trajectory, problem.robot
    d = build(problem, knots=knots, transcription_options={"margin": 0.0}).discretization
    s_checks = np.concatenate([d.check_sigma, d.adaptive_default])  # σ ∈ [-1, 1] of the fixed and adaptive checks
    clear = lambda q: clearances(robot, problem.scene, sphere_centers(robot, q)).obstacles  # noqa: E731
    smallest = lambda q: 100 * clear(q).reshape(len(q), -1).min(axis=1)  # noqa: E731  cm
    dense = traj.sample(1e-3)
    t_checks = traj.tf * (s_checks + 1.0) / 2.0
    curves = (dense.t, smallest(dense.q)), (traj.knots.t, smallest(traj.knots.q)), \
        (t_checks, smallest(traj.interpolant(t_checks).q))
    worst = int(np.argmin(curves[0][1]))
    t_worst, c_worst = dense.t[worst], curves[0][1][worst]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.4), gridspec_kw={"width_ratios": [1.4, 1]})
    for ax, window in zip(axes, (None, 0.06)):
        (t, c), (tk, ck), (tc, cc) = curves
        ax.plot(t, c, color="tab:blue", label="interpolant (1 ms grid)")
        ax.plot(tk, ck, "o", color="black", label=f"knots (N = {knots})")
        ax.plot(tc, cc, "D", color="tab:orange", ms=5, label="check times between knots")
        ax.axhline(0.0, color="tab:red", lw=1)
        ax.plot(t_worst, c_worst, "x", color="tab:red", ms=10, mew=2,
                label=f"{c_worst:+.2f} cm at t = {t_worst:.3f} s")
        ax.grid(alpha=0.3)
        ax.set_xlabel("t [s]")
        if window:
            ax.set_xlim(t_worst - window, t_worst + window)
            ax.set_ylim(c_worst - 0.3, 1.0)
            ax.set_title("zoom: the constraint holds at knots and checks, not between", fontsize=9)
    axes[0].set_ylabel("smallest obstacle clearance [cm]")
    axes[0].set_title(f"case1, chebyshev N = {knots}, margin 0, no refinement: {result.status}", fontsize=9)
    axes[0].legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return {"status": result.status, "worst_cm": round(float(c_worst), 3), "t": round(float(t_worst), 3),
            "knots_min_cm": round(float(curves[1][1].min()), 4), "checks_min_cm": round(float(curves[2][1].min()), 4)}


def convergence(out: Path, rerun: bool) -> None:
    """Re-run the study into `out` (CSV + PNG), or re-plot its existing CSV."""
    csv_path = out / "convergence.csv"
    if rerun or not csv_path.exists():
        run_convergence(out, case=ROOT / "scenarios" / "paper" / "case2.yaml")
    else:
        plot_convergence(read_rows(csv_path), out / "convergence.png")


def main(argv: list[str] | None = None) -> int:
    args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    args.add_argument("--out", type=Path, default=FIGURES)
    args.add_argument("--rerun", action="store_true", help="re-run the convergence study (~3 min)")
    options = args.parse_args(argv)
    options.out.mkdir(parents=True, exist_ok=True)
    knot_placement(options.out / "knots.png")
    differentiation_heatmap(options.out / "dmatrix.png")
    print("between knots:", between_knots(options.out / "between_knots.png"))
    convergence(options.out, options.rerun)
    return 0


if __name__ == "__main__":
    sys.exit(main())
