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
# # A. Transcription by hand: the minimum-energy double integrator
#
# A *direct transcription* turns an optimal control problem, whose unknowns are functions of time, into a
# nonlinear program (NLP), whose unknowns are finitely many numbers. This notebook does it once by hand, with
# raw CasADi, and then lets `ocpkit.ocp` do the same in a few lines.
#
# **The problem.** A unit mass moves on a line: position x (m), velocity v = ẋ (m/s), control u = ẍ (m/s²).
# It starts at rest at x = 0 and must arrive at rest at x = 1 m after T = 1 s, spending as little "energy"
# as possible:
#
#     minimize    J = ½ ∫₀¹ u(t)² dt                 (m²/s³)
#     subject to  ẋ = v,  v̇ = u
#                 x(0) = 0, v(0) = 0,  x(1) = 1, v(1) = 0
#
# **The exact answer.** The Hamiltonian H = ½u² + λₓ v + λᵥ u gives u = −λᵥ, λ̇ₓ = 0, λ̇ᵥ = −λₓ, so u is
# linear in t. The four boundary conditions fix it: u(t) = 6 − 12t, v(t) = 6t − 6t², x(t) = 3t² − 2t³ and
# J* = ½ ∫₀¹ (6 − 12t)² dt = 6 m²/s³.

# %%
import os
from pathlib import Path

import casadi as ca
import matplotlib.pyplot as plt
import numpy as np

from ocpkit.ocp import Ocp, solve

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # run inside Jupyter: the working directory is docs/notebooks
    ROOT = Path.cwd().resolve().parents[1]
FIGURES = Path(os.environ.get("OCPKIT_FIGURES", ROOT / "docs" / "figures" / "notebooks"))
FIGURES.mkdir(parents=True, exist_ok=True)

T = 1.0  # s


def exact(t):
    """The analytic optimum: x (m), v (m/s), u (m/s²) at times t (s)."""
    return 3 * t**2 - 2 * t**3, 6 * t - 6 * t**2, 6 - 12 * t


J_EXACT = 6.0  # m²/s³

# %% [markdown]
# ## 1. Trapezoidal collocation, written out
#
# **Grid.** Split [0, T] into N intervals of length h = T/N; the knots are t_k = k h, k = 0 … N.
#
# **Decision variables.** The state and the control at every knot, stacked knot by knot:
#
#     w = [x₀, v₀, u₀,  x₁, v₁, u₁,  …,  x_N, v_N, u_N]      (3(N + 1) numbers)
#
# Between knots the control is the straight line from u_k to u_{k+1}.
#
# **Defects.** The differential equation ẏ = f(y, u), y = (x, v), is replaced on each interval by the
# trapezoidal rule applied to its integral form y_{k+1} = y_k + ∫ f dt:
#
#     x_{k+1} − x_k − (h/2)(v_k + v_{k+1}) = 0
#     v_{k+1} − v_k − (h/2)(u_k + u_{k+1}) = 0        k = 0 … N − 1
#
# These 2N equality rows are the *defects*; at a solution of the NLP they vanish.
#
# **Boundary conditions** are simply bounds on w: x₀ = v₀ = 0, x_N = 1, v_N = 0.
#
# **Cost.** The integral must become a finite sum too (a *quadrature*). ocpkit's trapezoidal transcription
# applies the trapezoidal rule to the running cost L = ½u² as well (Kelly 2017):
#
#     ∫_{t_k}^{t_{k+1}} ½u² dt  ≈  (h/2) (½u_k² + ½u_{k+1}²)
#
# We use the same rule, so that both NLPs are the same and must have the same optimum.

# %%
N = 20  # intervals


def trapezoidal_nlp(N, rule="trapezoid"):
    """The double integrator's NLP on N intervals: (w, J, g, lower bound of w, upper bound of w).

    rule: how the cost integral is approximated on each interval, "trapezoid" (the mean of L at its two knots,
    as ocpkit does) or "midpoint" (L at the interval's midpoint, on the linear control)."""
    h = T / N
    W = ca.SX.sym("w", 3, N + 1)  # column k = (x_k, v_k, u_k)
    x, v, u = W[0, :], W[1, :], W[2, :]
    defects = []
    for k in range(N):
        defects.append(x[k + 1] - x[k] - h / 2 * (v[k] + v[k + 1]))
        defects.append(v[k + 1] - v[k] - h / 2 * (u[k] + u[k + 1]))
    if rule == "midpoint":
        J = sum(h * 0.5 * ((u[k] + u[k + 1]) / 2) ** 2 for k in range(N))
    else:
        J = sum(h / 2 * (0.5 * u[k] ** 2 + 0.5 * u[k + 1] ** 2) for k in range(N))
    lower, upper = np.full((3, N + 1), -np.inf), np.full((3, N + 1), np.inf)
    lower[:2, 0] = upper[:2, 0] = [0.0, 0.0]  # x(0) = 0 m, v(0) = 0 m/s
    lower[:2, N] = upper[:2, N] = [1.0, 0.0]  # x(T) = 1 m, v(T) = 0 m/s
    # ca.vec stacks column by column, i.e. knot by knot; NumPy's ravel(order="F") does the same for the bounds
    return ca.vec(W), J, ca.vertcat(*defects), lower.ravel(order="F"), upper.ravel(order="F")


def solve_by_hand(N, rule="trapezoid"):
    """Solve the hand-made NLP with IPOPT from w = 0: (J, knot values (3, N + 1), IPOPT's return status)."""
    w, J, g, lbw, ubw = trapezoidal_nlp(N, rule)
    solver = ca.nlpsol("s", "ipopt", {"x": w, "f": J, "g": g},
                       {"ipopt.print_level": 0, "ipopt.tol": 1e-10, "print_time": False})
    result = solver(x0=np.zeros(w.numel()), lbx=lbw, ubx=ubw, lbg=0.0, ubg=0.0)  # defects = 0
    return float(result["f"]), np.asarray(result["x"]).reshape(N + 1, 3).T, solver.stats()["return_status"]


w, J, g, lbw, ubw = trapezoidal_nlp(N)
print(f"N = {N}: {w.numel()} decision variables, {g.numel()} defect rows")
J_hand, knots_hand, status = solve_by_hand(N)
print(f"IPOPT: {status}, J = {J_hand:.10f} m²/s³ (exact optimum {J_EXACT})")

# %% [markdown]
# The NLP's optimum is a little above J* = 6: the discretization's error, O(h²). Another common quadrature, the
# midpoint rule (L once per interval, at its midpoint, on the linear control: h · ½((u_k + u_{k+1})/2)²), is a
# different NLP with its own optimum, and a property worth knowing: its cost and both defects read the control
# only through the interval means m_k = (u_k + u_{k+1})/2, and for a constant acceleration m_k the trapezoidal
# update of x is exact (x_{k+1} = x_k + h v_k + h² m_k / 2). So that NLP is the *exact* problem restricted to
# piecewise-constant controls, and its optimum can only be higher than J*.
#
# The side effect: adding c·(−1)^k to every u_k leaves every m_k, hence the cost and every defect, unchanged.
# The knot values u_k are not unique, only the interval means are; an interior-point solver may return any
# member of that family, so the knot values can zig-zag while m_k stays smooth. The trapezoidal rule counts every
# u_k² on its own, so its knot values are unique (one reason ocpkit uses it). The size of the alternating part
# of the midpoint rule's u_k:

# %%
J_midpoint, knots_midpoint, _ = solve_by_hand(N, rule="midpoint")
u_mid = knots_midpoint[2]
means = (u_mid[:-1] + u_mid[1:]) / 2
t_knots = np.linspace(0.0, T, N + 1)
basis = np.column_stack([np.ones(N + 1), t_knots, (-1.0) ** np.arange(N + 1)])  # u_k ≈ a + b t_k + c (−1)^k
alternating = np.linalg.lstsq(basis, u_mid, rcond=None)[0][2]
print(f"alternating part c of the midpoint rule's u_k: {alternating:+.3g} m/s²")
midpoints = (np.arange(N) + 0.5) * T / N
print(f"max |m_k − u*(t_k + h/2)| = {np.max(np.abs(means - exact(midpoints)[2])):.3g} m/s²")
print(f"N = {N}: J(trapezoid rule) − J* = {J_hand - J_EXACT:+.3e},  J(midpoint rule) − J* = "
      f"{J_midpoint - J_EXACT:+.3e}  (m²/s³)")

# %% [markdown]
# Both differ from J* by O(h²) and approach it as N grows:

# %%
Ns = [5, 10, 20, 40, 80]
errors = {rule: [abs(solve_by_hand(n, rule)[0] - J_EXACT) for n in Ns] for rule in ("midpoint", "trapezoid")}

fig, ax = plt.subplots(figsize=(5, 3.5))
for rule, marker in (("midpoint", "o"), ("trapezoid", "s")):
    ax.loglog(Ns, errors[rule], marker=marker, label=f"{rule} rule for the cost")
ax.loglog(Ns, errors["trapezoid"][0] * (Ns[0] / np.array(Ns)) ** 2, "k--", lw=0.8, label="slope N⁻²")
ax.set_xticks(Ns, [str(n) for n in Ns], minor=False)
ax.set_xticks([], minor=True)
ax.set_xlabel("intervals N")
ax.set_ylabel("|J_N − J*|  (m²/s³)")
ax.set_title("Trapezoidal collocation: objective error")
ax.legend()
fig.tight_layout()
fig.savefig(FIGURES / "a-energy-error-vs-knots.png", dpi=120)

# %% [markdown]
# ![Objective error against N, two cost quadratures](../figures/notebooks/a-energy-error-vs-knots.png)
#
# ## 2. The same problem with `ocpkit.ocp`
#
# `Ocp` describes the continuous problem (states with their fixed ends, a control, the derivatives, the
# running cost); `solve` picks the transcription and the number of intervals, builds the NLP above and calls
# IPOPT.

# %%
ocp = Ocp(T=T, name="double-integrator-energy")
x = ocp.state("x", start=0.0, end=1.0)  # m
v = ocp.state("v", start=0.0, end=0.0)  # m/s
u = ocp.control("u")  # m/s²
ocp.set_der(x, v)
ocp.set_der(v, u)
ocp.minimize_integral(0.5 * u**2)

solution = solve(ocp, "trapezoidal", N)
print(f"ocpkit: {solution.status}, J = {solution.objective:.10f} m²/s³, {solution.iterations} iterations")
print(f"its NLP: {solution.discretization.nlp.x.numel()} variables (ours: {w.numel()}; ocpkit adds t_f, "
      "here fixed by its bounds)")
assert abs(solution.objective - J_hand) < 1e-7, (solution.objective, J_hand)
print(f"same optimum as by hand: |ΔJ| = {abs(solution.objective - J_hand):.1e}")

# %%
t = np.linspace(0.0, T, 201)
fig, axes = plt.subplots(1, 3, figsize=(12, 3.5))
for ax, name, row, unit in zip(axes, ("x", "v"), (0, 1), ("m", "m/s")):
    ax.plot(t, exact(t)[row], "k-", lw=2.5, alpha=0.3, label="analytic")
    ax.plot(t, solution.x(name, t), "C0-", lw=1, label="ocpkit (its interpolant)")
    ax.plot(t_knots, knots_hand[row], "C1o", ms=4, label="by hand (knots)")
    ax.set_ylabel(f"{name} ({unit})")
ax = axes[2]
ax.plot(t, exact(t)[2], "k-", lw=2.5, alpha=0.3, label="analytic")
ax.plot(t, solution.u("u", t), "C0-", lw=1, label="ocpkit (its interpolant)")
ax.plot(t_knots, knots_hand[2], "C1o", ms=4, label="by hand: knot values u_k")
ax.stairs(means, t_knots, baseline=None, color="C2", lw=1.5, label="midpoint rule: interval means m_k")
ax.set_ylim(-10, 10)
ax.set_ylabel("u (m/s²)")
for ax in axes:
    ax.set_xlabel("t (s)")
axes[0].legend(fontsize=8)
axes[2].legend(fontsize=8)
fig.suptitle(f"Minimum-energy double integrator, trapezoidal collocation, N = {N}")
fig.tight_layout()
fig.savefig(FIGURES / "a-double-integrator-trajectories.png", dpi=120)

# %% [markdown]
# ![x, v and u: by hand, ocpkit, analytic](../figures/notebooks/a-double-integrator-trajectories.png)
#
# Both NLPs reach the same objective. The states and the control agree with the analytic solution to O(h²);
# with the midpoint rule only the interval means of the control are determined, and they follow the analytic
# line.
#
# **What to take away.** A transcription is three choices: where the unknowns live (knots, here), how the
# differential equation becomes algebraic rows (defects, here the trapezoidal rule), and how the cost
# integral becomes a sum (a quadrature). Each choice changes the NLP and therefore its optimum, by an amount
# that shrinks as the grid is refined. Notebook B compares several transcriptions on that score.
