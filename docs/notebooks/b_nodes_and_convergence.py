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
# # B. Nodes, differentiation matrices and convergence
#
# A *pseudospectral* transcription represents each state on [0, t_f] by one polynomial of degree N, stored
# through its values at N + 1 points (the *nodes*). Three things make it work:
#
# 1. **the nodes**: clustered towards the ends of the interval, which keeps polynomial interpolation stable;
# 2. **a differentiation matrix D**: the derivative of the interpolating polynomial at the nodes is a
#    matrix–vector product, so the dynamics ẋ = f(x, u) become the algebraic rows D X = h F;
# 3. **quadrature weights w**: an integral ∫ L dt becomes the weighted sum Σ w_i L_i.
#
# The normalized time is s ∈ [−1, 1], with t = t_f (s + 1)/2, so dt/ds = h = t_f/2. In ocpkit the nodes run
# from s = 1 (t = t_f) down to s = −1 (t = 0).

# %%
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from numpy.polynomial import Polynomial
from scipy.optimize import brentq

from ocpkit.ocp import solve
from ocpkit.problems import CLASSICS
from ocpkit.transcription.chebyshev import CHEBYSHEV
from ocpkit.transcription.lgl import LGL
from ocpkit.transcription.lgr import LGR

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # run inside Jupyter: the working directory is docs/notebooks
    ROOT = Path.cwd().resolve().parents[1]
FIGURES = Path(os.environ.get("OCPKIT_FIGURES", ROOT / "docs" / "figures" / "notebooks"))
FIGURES.mkdir(parents=True, exist_ok=True)

FAMILIES = {"Chebyshev–Gauss–Lobatto": CHEBYSHEV, "Legendre–Gauss–Lobatto": LGL, "Legendre–Gauss–Radau": LGR}

# %% [markdown]
# ## 1. Three node families, N = 8
#
# - **Chebyshev–Gauss–Lobatto** (CGL): s_i = cos(iπ/N), the projections of equally spaced points on a
#   half circle. Both ends are nodes.
# - **Legendre–Gauss–Lobatto** (LGL): ±1 and the roots of P′_N (P_N the Legendre polynomial).
# - **Legendre–Gauss–Radau** (LGR): +1 and the roots of (P_{N−1} − P_N)/(1 − s); ocpkit adds s = −1 as a
#   node where the dynamics are *not* collocated (open marker below). GPOPS-II and dymos use the mirror image
#   (collocate −1, add +1; `collocate="start"`), whose discrete dynamics can grow where the true ones decay
#   fast (docs, "Transcription equations").

# %%
n = 8
fig, ax = plt.subplots(figsize=(7, 2.4))
for row, (name, family) in enumerate(FAMILIES.items()):
    s, collocated = family.points(n), family.collocation_mask(n)
    ax.plot(s[collocated], np.full(collocated.sum(), -row), "o", color=f"C{row}")
    ax.plot(s[~collocated], np.full((~collocated).sum(), -row), "o", mfc="none", color=f"C{row}")
ax.set_yticks([0, -1, -2], list(FAMILIES))
ax.set_ylim(-2.6, 0.6)
ax.set_xlabel("s (normalized time)")
ax.set_title(f"Nodes for N = {n} (open: not collocated)")
ax.grid(axis="x", alpha=0.3)
fig.tight_layout()
fig.savefig(FIGURES / "b-nodes.png", dpi=120)

# %% [markdown]
# ![CGL, LGL and LGR nodes for N = 8](../figures/notebooks/b-nodes.png)
#
# ## 2. D and w are exact for polynomials
#
# D is built so that (D f)_i = p′(s_i), p the polynomial of degree ≤ N through the values f_i. So D
# differentiates every polynomial of degree ≤ N exactly (to rounding). A quadrature with N + 1 nodes is
# exact up to a degree that depends on where the nodes are: N for Clenshaw–Curtis on the CGL nodes (N + 1
# when N is even: the nodes are symmetric, so the odd power N + 1 integrates to 0 exactly), 2N − 1 for LGL
# and 2N − 2 for LGR (its node at s = +1 has weight 0). One degree more, and the error is no longer rounding.

# %%
rng = np.random.default_rng(0)
exactness = {"Chebyshev–Gauss–Lobatto": n + 1 if n % 2 == 0 else n,  # highest degree integrated exactly
             "Legendre–Gauss–Lobatto": 2 * n - 1, "Legendre–Gauss–Radau": 2 * n - 2}
for name, family in FAMILIES.items():
    s, D, w = family.points(n), family.differentiation(n), family.quadrature_weights(n)
    p = Polynomial(rng.standard_normal(n + 1))  # a random polynomial of degree N
    d_error = np.max(np.abs(D @ p(s) - p.deriv()(s)))
    print(f"{name}: max |D p(s_i) − p′(s_i)| = {d_error:.1e} (degree {n})")
    for degree in (exactness[name], exactness[name] + 1):
        q = Polynomial(rng.standard_normal(degree + 1))
        integral = q.integ()(1.0) - q.integ()(-1.0)
        print(f"    |Σ w_i q(s_i) − ∫ q ds| = {abs(w @ q(s) - integral):.1e} (degree {degree})")

# %% [markdown]
# ## 3. Convergence: smooth against non-smooth
#
# For a problem whose solution is smooth (analytic), the polynomial error of a pseudospectral method falls
# faster than any power of N (*spectral* convergence: a straight line on a semi-log plot). The local mesh
# methods converge algebraically: the error of trapezoidal collocation falls like N⁻², that of
# Hermite–Simpson like N⁻⁴. When the solution has a corner, one global polynomial cannot follow it and every
# method falls back to algebraic convergence.
#
# **Smooth: the brachistochrone** (`CLASSICS["brachistochrone"]`). A bead slides without friction from
# (0, 10) m to (10, 5) m in minimum time, g = 9.80665 m/s². The optimal wire is a cycloid
# x = r(φ − sin φ), depth r(1 − cos φ), whose end angle φ_f solves (φ − sin φ)/(1 − cos φ) = Δx/Δy = 2; then
# r = Δy/(1 − cos φ_f) and t_f* = φ_f √(r/g). We compute that reference to machine precision rather than use
# the published 5-digit value.

# %%
G = 9.80665  # m/s²
phi_f = brentq(lambda phi: (phi - np.sin(phi)) / (1 - np.cos(phi)) - 10.0 / 5.0, 1e-3, 2 * np.pi - 1e-3)
r = 5.0 / (1 - np.cos(phi_f))
tf_brachistochrone = phi_f * np.sqrt(r / G)
print(f"brachistochrone: t_f* = {tf_brachistochrone:.12f} s (published: {CLASSICS['brachistochrone'].optimum} s)")

# %% [markdown]
# **Non-smooth: the minimum-time double integrator** (`CLASSICS["double-integrator"]`): ẍ = u, |u| ≤ 1 m/s²,
# rest at x = 0 to rest at x = 1 m. The optimal control is bang-bang, u = +1 then −1 with one switch at
# t = 1 s, so t_f* = 2 s. We use odd N only: with an even N, CGL and the uniform meshes put a node exactly on
# the switch, a lucky alignment (checked at the end).
#
# Each point below is one solve from the problem's default guess (IPOPT, tol = 1e-10).

# %%
TRANSCRIPTIONS = ["chebyshev", "lgr", "trapezoidal", "hermite-simpson"]
CASES = {
    "brachistochrone": (tf_brachistochrone, [6, 8, 10, 12, 16, 24, 32, 40]),
    "double-integrator": (2.0, [7, 9, 11, 15, 21, 31, 41]),
}
errors = {}
for problem, (reference, knots) in CASES.items():
    for transcription in TRANSCRIPTIONS:
        row = []
        for N in knots:
            solution = solve(CLASSICS[problem].build(), transcription, N)
            row.append(abs(solution.objective - reference) if solution.converged else np.nan)
        errors[problem, transcription] = row
        print(f"{problem:18s} {transcription:16s} " + " ".join(f"{e:8.1e}" for e in row))

# %%
fig, axes = plt.subplots(1, 2, figsize=(11, 4))
for ax, (problem, (reference, knots)) in zip(axes, CASES.items()):
    for transcription, marker in zip(TRANSCRIPTIONS, "osv^"):
        ax.plot(knots, errors[problem, transcription], marker=marker, label=transcription)
    ax.set_yscale("log")
    ax.set_xlabel("N (intervals per segment or mesh intervals)")
    ax.set_ylabel("|t_f − t_f*|  (s)")
    ax.grid(alpha=0.3)
axes[0].set_title("brachistochrone (smooth): semi-log axes")
axes[0].axhline(1e-10, color="gray", ls=":", lw=1)
axes[0].text(25, 2e-10, "solver tolerance", color="gray", fontsize=8)
knots = np.array(CASES["double-integrator"][1])
axes[1].set_xscale("log")
guide = 2 * errors["double-integrator", "trapezoidal"][0] * (knots / knots[0]) ** -2.0
axes[1].plot(knots, guide, "k--", lw=0.8, label="slope N⁻²")
axes[1].set_xticks(knots, [str(k) for k in knots], minor=False)
axes[1].set_xticks([], minor=True)
axes[1].set_title("double integrator, bang-bang: log-log axes")
axes[0].legend()
axes[1].legend(loc="lower left")
fig.tight_layout()
fig.savefig(FIGURES / "b-convergence.png", dpi=120)

# %% [markdown]
# ![Objective error against N, smooth and bang-bang problems](../figures/notebooks/b-convergence.png)
#
# **Reading the plot.** On the brachistochrone the two pseudospectral transcriptions reach the solver's
# tolerance within a handful of nodes; below that level the error is set by the NLP tolerance and rounding,
# not by N. The mesh methods converge algebraically (curves that flatten on semi-log axes): Hermite–Simpson
# about like N⁻⁴, trapezoidal like N⁻².
#
# On the bang-bang double integrator every method converges algebraically, here about like N⁻², and the
# pseudospectral ones lose their advantage: one polynomial over [0, t_f] cannot have a corner, so their error
# depends mostly on how close a node falls to the switch, which makes their curves erratic.
#
# **Alignment.** Put a node on the switch and a mesh method only has to represent two smooth arcs:

# %%
for N in (8, 9):
    solution = solve(CLASSICS["double-integrator"].build(), "hermite-simpson", N)
    on_switch = np.any(np.isclose(solution.knot_times, 1.0))
    print(f"hermite-simpson, N = {N}: |t_f − 2| = {abs(solution.objective - 2.0):.1e} s "
          f"({'a knot at' if on_switch else 'no knot at'} t = 1 s)")

# %% [markdown]
# In practice one does not know where the switches are; that is what mesh refinement and segmented
# pseudospectral methods (notebook C) are for. `ocpkit.ocp.mesh.refine` reads the switches from a first
# solution's knots (where u reaches, leaves or jumps between its bounds) and solves again on segments that end
# there, warm-started; with a Lobatto family the control may jump at a segment end.

# %%
from ocpkit.ocp.mesh import refine, switch_times  # noqa: E402

first = solve(CLASSICS["double-integrator"].build(), "chebyshev", 41)
refined = refine(first, knots=10)
print(f"one polynomial, N = 41:     |t_f − 2| = {abs(first.objective - 2.0):.1e} s")
print(f"switches found at τ = {', '.join(f'{b:.3f}' for b in switch_times(first))}")
print(f"{refined.segments} segments of 10 knots: |t_f − 2| = {abs(refined.objective - 2.0):.1e} s")
