# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # E. Swapping components: NLP solvers and dynamics backends
#
# ocpkit builds its NLP from interchangeable parts, each chosen by name (`ocpkit list` shows them all):
#
# - the **transcription** (notebooks A–C): how the trajectory becomes finitely many numbers;
# - the **dynamics backend**: how the rigid-body dynamics enter the rows;
#   - `casadi`: forward dynamics (the paper's form), q̈ − ABA(q, q̇, τ) = 0 in rad/s², as a CasADi
#     expression with exact derivatives;
#   - `casadi-rnea` (the default): inverse dynamics, (RNEA(q, q̇, q̈) − τ)/τ_max = 0, dimensionless; no
#     inverse of the mass matrix appears, and the feasible set is the same;
#   - `pinocchio`: forward dynamics computed numerically by the Pinocchio library in a callback; it gives
#     first derivatives only, so the solver must approximate the Hessian (L-BFGS);
# - the **NLP solver**:
#   - `ipopt`: interior point, sparse linear algebra (MUMPS);
#   - `sqpmethod`: CasADi's sequential quadratic programming, one QP per iteration; we give it the sparse QP
#     solver OSQP (`solver_options={"qpsol": "osqp"}`): its default, the dense active-set qpOASES, needs
#     seconds per QP on this NLP;
#   - `fatrop`: an interior point method that exploits the stage structure of an optimal control problem
#     (x_{k+1} depends on stage k only). A mesh transcription has that structure, a pseudospectral one does
#     not (D couples every node with every other), so fatrop needs `transcription="hermite-simpson"` (or
#     `"trapezoidal"`); `ocpkit.plan` then builds the staged form of the NLP by itself. It also needs exact
#     second derivatives, so not the `pinocchio` backend.
#
# We plan the paper's case 2 (notebook D) with several combinations. Each plan is a single shot
# (`fallbacks=SINGLE_SHOT`: no fallback strategies, the paper's setting) with a wall-time budget, and is
# verified densely. A combination that ocpkit refuses is skipped with its reason.
#
# **A timing from a notebook is a demonstration, not a benchmark.** It is one run, on whatever machine runs
# the notebook, sharing it with whatever else runs there. For measurements use the benchmark commands
# (`ocpkit bench ...`, see the Benchmarks page), which repeat runs and report spreads.

# %%
import os
from pathlib import Path

import matplotlib.pyplot as plt

import ocpkit
from ocpkit.planner.ladder import SINGLE_SHOT

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # run inside Jupyter: the working directory is docs/notebooks
    ROOT = Path.cwd().resolve().parents[1]
FIGURES = Path(os.environ.get("OCPKIT_FIGURES", ROOT / "docs" / "figures" / "notebooks"))
FIGURES.mkdir(parents=True, exist_ok=True)

problem = ocpkit.load_scenario(ROOT / "scenarios" / "paper" / "case2.yaml")
MAX_WALL_TIME = 6.0  # s per plan: keeps the notebook short; a plan that needs more ends as time_limit
SOLVER_OPTIONS = {"sqpmethod": {"qpsol": "osqp"}}

RUNS = [  # (solver, dynamics, transcription)
    ("ipopt", "casadi", "chebyshev"),
    ("ipopt", "casadi-rnea", "chebyshev"),
    ("ipopt", "pinocchio", "chebyshev"),
    ("sqpmethod", "casadi", "chebyshev"),
    ("sqpmethod", "casadi-rnea", "chebyshev"),
    ("sqpmethod", "pinocchio", "chebyshev"),
    ("fatrop", "casadi-rnea", "chebyshev"),  # refused: no stage structure
    ("ipopt", "casadi", "hermite-simpson"),
    ("ipopt", "casadi-rnea", "hermite-simpson"),
    ("fatrop", "casadi", "hermite-simpson"),
    ("fatrop", "casadi-rnea", "hermite-simpson"),
    ("fatrop", "pinocchio", "hermite-simpson"),  # refused: no exact Hessian
]

# %%
rows = []
for solver, dynamics, transcription in RUNS:
    label = f"{solver} · {dynamics} · {transcription}"
    try:
        plan = ocpkit.plan(problem, solver=solver, dynamics=dynamics, transcription=transcription, knots=12,
                           solver_options=SOLVER_OPTIONS.get(solver), fallbacks=SINGLE_SHOT,
                           max_wall_time=MAX_WALL_TIME)
    except Exception as error:  # noqa: BLE001  a combination ocpkit refuses: say why and go on
        print(f"skipped {label}: {type(error).__name__}: {error}")
        continue
    rows.append((label, plan.status, plan.trajectory.tf, plan.stats.iterations, plan.stats.solve_time,
                 plan.stats.setup_time))

print()
print(f"{'solver · dynamics · transcription':44s} {'status':11s} {'t_f (s)':>8s} {'iter':>5s} {'time (s)':>9s} "
      f"{'setup (s)':>9s}")
for label, status, tf, iterations, seconds, setup in rows:
    print(f"{label:44s} {status:11s} {tf:8.4f} {iterations:5d} {seconds:9.3f} {setup:9.3f}")

# %% [markdown]
# *time* is the plan's computation time (initial guess, solve, dense verification); *setup* is the one-time
# construction of the NLP and the solver, which ocpkit caches and reuses for every later problem of the same
# shape. Plans that reach `verified` should agree on t_f to a few digits for the same transcription; the two
# transcriptions solve slightly different NLPs, so their t_f differ a little.

# %%
fig, ax = plt.subplots(figsize=(9, 0.4 * len(rows) + 1.4))
labels = [row[0] for row in rows]
colors = ["C2" if row[1] == "verified" else "C3" for row in rows]
ax.barh(range(len(rows)), [row[4] for row in rows], color=colors)
ax.set_yticks(range(len(rows)), labels, fontsize=8)
ax.invert_yaxis()
ax.set_xlim(0, 1.25 * max(row[4] for row in rows))
ax.set_xlabel("computation time of one plan (s)")
for y, row in enumerate(rows):
    ax.text(row[4], y, f" {row[1]}", va="center", fontsize=7)
ax.set_title("case2, one plan per combination (green: verified)\na demonstration on this machine, not a benchmark",
             fontsize=10)
fig.tight_layout()
fig.savefig(FIGURES / "e-solve-times.png", dpi=120)

# %% [markdown]
# ![Computation time of one case2 plan per combination](../figures/notebooks/e-solve-times.png)
#
# **What to look for** (the numbers are in the printed table, not here, because they depend on the machine):
#
# - the symbolic backends give the solver exact second derivatives; the numeric `pinocchio` backend gives
#   first derivatives only, and a quasi-Newton Hessian typically needs many more iterations;
# - for the same transcription and backend, the solvers reach the same optimum by different routes, with
#   different iteration counts and costs per iteration;
# - a structure-exploiting solver (fatrop) can only be used with a transcription that has the structure.
#
# To turn such impressions into evidence, run the benchmark suites (`ocpkit bench ...`) on an otherwise idle
# machine.
