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
# # C. Costates from the NLP's multipliers: Bryson–Denham
#
# A direct method never writes down the adjoint equations, yet the NLP's Lagrange multipliers carry the same
# information. For the pseudospectral transcriptions the link is known exactly (the *covector mapping
# theorem*, Fahroo & Ross; Garg et al. for LGR): the multiplier Λ_j of the collocation row at node j, divided
# by that node's quadrature weight w_j, estimates the costate λ(t_j), up to sign. `Solution.costates()`
# applies this map, with the sign that makes H = L + λᵀ f.
#
# **The problem** (Bryson & Ho 1975, §3.11; dimensionless): x′ = v, v′ = u, x ≤ ℓ = 1/9,
# (x, v)(0) = (0, 1), (x, v)(1) = (0, −1), t_f = 1, minimize ½ ∫ u² dt. The optimum J* = 4/(9ℓ) = 4 has three
# arcs: free on [0, 3ℓ], riding the state constraint x = ℓ on [3ℓ, 1 − 3ℓ] (u = 0), free again on
# [1 − 3ℓ, 1]. The costates are known in closed form (`ocpkit.problems.bryson_denham.costates`): λᵥ = −u is
# continuous with kinks at the junctions, λₓ is piecewise constant and *jumps* at the junctions t = 1/3 and
# t = 2/3.
#
# A single polynomial cannot jump. Three segments whose boundaries sit exactly at the junctions can: each
# segment has its own polynomial, and the costate estimate may change between them.

# %%
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from ocpkit.ocp import solve
from ocpkit.problems import CLASSICS
from ocpkit.problems.bryson_denham import ELL, JUNCTIONS, costates

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # run inside Jupyter: the working directory is docs/notebooks
    ROOT = Path.cwd().resolve().parents[1]
FIGURES = Path(os.environ.get("OCPKIT_FIGURES", ROOT / "docs" / "figures" / "notebooks"))
FIGURES.mkdir(parents=True, exist_ok=True)

print(f"ℓ = {ELL:.6f}, junctions at t = {JUNCTIONS[0]:.6f} and {JUNCTIONS[1]:.6f}, "
      f"J* = {CLASSICS['bryson-denham'].optimum}")

# %% [markdown]
# ## Two LGR transcriptions with the same number of nodes
#
# - one segment, N = 30 (31 nodes on [0, 1]);
# - three segments of N = 10 each (`transcription_options={"segments": 3}`): with t_f = 1 the segment
#   boundaries are at 1/3 and 2/3, exactly the junctions 3ℓ and 1 − 3ℓ.

# %%
RUNS = {"1 segment, N = 30": (1, 30), "3 segments at the junctions, N = 10 each": (3, 10)}
solutions = {label: solve(CLASSICS["bryson-denham"].build(), "lgr", N, transcription_options={"segments": K})
             for label, (K, N) in RUNS.items()}
for label, solution in solutions.items():
    print(f"{label}: {solution.status}, J − J* = {solution.objective - 4.0:+.2e}")

# %% [markdown]
# The aligned transcription reaches J* = 4 to the solver's tolerance. One solver setting matters here: IPOPT
# relaxes every variable bound by a relative 10⁻⁸ by default (its option `bound_relax_factor`), so x may
# exceed ℓ by about 10⁻⁸, and the optimum's sensitivity to the bound, dJ*/dℓ = −4/(9ℓ²) = −36, turns that into
# a gain of about 3.6·10⁻⁷. `solve` turns the relaxation off for an `Ocp` (`ocpkit.ocp.solve.SOLVER_DEFAULTS`);
# with IPOPT's default:

# %%
relaxed = solve(CLASSICS["bryson-denham"].build(), "lgr", 10, transcription_options={"segments": 3},
                solver_options={"bound_relax_factor": 1e-8})
print(f"3 segments, bound_relax_factor = 1e-8: {relaxed.status}, J − J* = {relaxed.objective - 4.0:+.2e}")

# %% [markdown]
# ## Costate error away from the junctions
#
# At a junction the exact λₓ has two values (left and right limits), so we measure the error at the nodes
# more than 0.05 away from either junction. Inside the constrained arc the exact costates are 0, so a
# pointwise relative error means nothing there; we divide by each costate's largest magnitude instead
# (18 for λₓ, 6 for λᵥ).

# %%
AWAY = 0.05
for label, solution in solutions.items():
    t, lam = solution.costates()
    exact = np.column_stack(costates(t))
    away = np.min(np.abs(t[:, None] - np.array(JUNCTIONS)[None, :]), axis=1) > AWAY
    relative = np.max(np.abs(lam - exact)[away], axis=0) / np.max(np.abs(exact), axis=0)
    print(f"{label}: max relative error λx {relative[0]:.1e}, λv {relative[1]:.1e} ({away.sum()} of {len(t)} nodes)")

# %%
t_dense = np.linspace(0.0, 1.0, 1001)
exact_dense = costates(t_dense)
fig, axes = plt.subplots(1, 2, figsize=(11, 4))
for column, (ax, name) in enumerate(zip(axes, ("λx", "λv"))):
    ax.plot(t_dense, exact_dense[column], "k-", lw=2.5, alpha=0.3, label="analytic")
    for (label, solution), marker in zip(solutions.items(), ("o", "s")):
        t, lam = solution.costates()
        ax.plot(t, lam[:, column], marker, ms=4, mfc="none" if marker == "o" else None, label=label)
    for junction in JUNCTIONS:
        ax.axvline(junction, color="gray", ls=":", lw=1)
    ax.set_xlabel("t")
    ax.set_ylabel(name)
axes[0].set_ylim(-30, 30)
axes[0].legend(fontsize=8, loc="lower left")
fig.suptitle("Bryson–Denham: LGR costate estimates (dotted: the arc junctions)")
fig.tight_layout()
fig.savefig(FIGURES / "c-costates.png", dpi=120)

# %% [markdown]
# ![LGR costates: one segment, and three meeting at the junctions](../figures/notebooks/c-costates.png)
#
# **Reading the plot.** With one segment the λₓ estimate oscillates around the jumps (a Gibbs-like
# phenomenon of trying to follow a discontinuity with one polynomial), and the error spreads over the whole
# interval, because D couples every node with every other. With the segment boundaries at the junctions each
# arc is one smooth piece on its own segment, and both costates follow the analytic ones closely (the
# printed errors above).
#
# At a segment boundary the LGR estimate belongs to the segment that *ends* there (ocpkit's LGR collocates the
# end of each segment, not its start), so the node at t = 1/3 shows the first arc's λₓ = 18, and the node at
# t = 2/3 the middle arc's 0.
#
# Here the junctions were known in advance. In general they are not, which is why practical
# pseudospectral solvers (GPOPS-II, for example) move or add segment boundaries adaptively, guided by
# error estimates such as the one this notebook computed from the analytic solution.
