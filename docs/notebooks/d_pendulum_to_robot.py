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
# # D. From a pendulum to a six-joint robot
#
# A robot arm is a chain of pendulums. This notebook solves a single pendulum's swing-up with `ocpkit.ocp`,
# then the paper's robot problem, where the same ideas (states, torque limits, a cost, one NLP) come with
# rigid-body dynamics, collision avoidance and torque-rate limits.
#
# ## 1. Pendulum swing-up
#
# A point mass m = 1 kg on a massless rod of length ℓ = 1 m, angle θ (rad) from the downward vertical,
# driven by a torque u (N·m) at the pivot:
#
#     θ̈ = −(g/ℓ) sin θ + u / (m ℓ²),      g = 9.81 m/s²,   |u| ≤ u_max = 6 N·m
#
# From rest hanging down (θ = 0) to rest upright (θ = π) in T = 3 s, minimizing ∫₀ᵀ u² dt (N²·m²·s).
# Holding the mass horizontal takes m g ℓ = 9.81 N·m, more than u_max: the pendulum cannot be lifted
# directly and has to be swung up.
#
# Why a fixed T and an energy cost rather than minimum time? Minimum time makes u bang-bang, whose corners a
# global polynomial cannot follow (notebook B); the energy-optimal torque is smooth, so a pseudospectral
# transcription solves it quickly and robustly from the default straight-line guess.

# %%
import os
from pathlib import Path

import casadi as ca
import matplotlib.pyplot as plt
import numpy as np

import ocpkit
from ocpkit.ocp import Ocp, solve
from ocpkit.ocp.certify import certify

try:
    ROOT = Path(__file__).resolve().parents[2]
except NameError:  # run inside Jupyter: the working directory is docs/notebooks
    ROOT = Path.cwd().resolve().parents[1]
FIGURES = Path(os.environ.get("OCPKIT_FIGURES", ROOT / "docs" / "figures" / "notebooks"))
FIGURES.mkdir(parents=True, exist_ok=True)

M, L, G = 1.0, 1.0, 9.81  # kg, m, m/s²
U_MAX, T = 6.0, 3.0  # N·m, s

ocp = Ocp(T=T, name="pendulum")
theta = ocp.state("theta", start=0.0, end=np.pi)  # rad
omega = ocp.state("omega", start=0.0, end=0.0)  # rad/s
u = ocp.control("u", lower=-U_MAX, upper=U_MAX)  # N·m
ocp.set_der(theta, omega)
ocp.set_der(omega, -(G / L) * ca.sin(theta) + u / (M * L**2))
ocp.minimize_integral(u**2)

pendulum = solve(ocp, "chebyshev", 30)
print(f"{pendulum.status} in {pendulum.iterations} iterations, ∫u² dt = {pendulum.objective:.4f} N²·m²·s")

# %% [markdown]
# The solver's answer is only as good as the discretization. `certify` re-integrates θ̈ with an adaptive ODE
# solver, driven by the solution's own torque u(t), and checks the bounds on a dense time grid:

# %%
certificate = certify(pendulum)
print(f"re-integration error {certificate.state_error:.1e} (relative), largest bound excess "
      f"{certificate.excess:.1e}: {'passed' if certificate.passed else 'FAILED'}")

t = np.linspace(0.0, T, 601)
fig, axes = plt.subplots(1, 3, figsize=(12, 3.3))
for ax, values, label in zip(axes, (pendulum.x("theta", t), pendulum.x("omega", t), pendulum.u("u", t)),
                             ("θ (rad)", "ω (rad/s)", "u (N·m)")):
    ax.plot(t, values)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(label)
axes[0].axhline(np.pi, color="gray", ls=":", lw=1)
for limit in (-U_MAX, U_MAX):
    axes[2].axhline(limit, color="k", ls="--", lw=1)
axes[2].plot(pendulum.knot_times, pendulum.u("u", pendulum.knot_times), ".", color="C0", ms=4)
fig.suptitle("Pendulum swing-up, minimum ∫u² dt, Chebyshev N = 30 (dots: knots; dashed: torque limits)")
fig.tight_layout()
fig.savefig(FIGURES / "d-pendulum.png", dpi=120)

# %% [markdown]
# ![Pendulum swing-up: angle, angular velocity and torque](../figures/notebooks/d-pendulum.png)
#
# The pendulum first swings back (θ < 0) to gain energy, then over the top. With a tighter limit the torque
# would saturate on some arcs and more swings would be needed; at this u_max the limit is not active.
#
# ## 2. The paper's robot problem
#
# `scenarios/paper/case2.yaml`: a six-joint industrial arm sweeps joint 1 from −40° to +50°, past a sphere
# of radius 0.25 m hanging across the straight joint-space path, inside walls. The state is (q, q̇) ∈ ℝ¹²
# (rad, rad/s); the torque τ (N·m) follows from the rigid-body dynamics M(q) q̈ + h(q, q̇) plus friction. The
# limits are on q, q̇, τ and the torque rate τ̇ (N·m/s); the cost is t_f + μ ∫ q⃛ᵀ Q q⃛ dt, time plus a little
# jerk.
#
# Two ways to solve it:
#
# - **simultaneous** (`ocpkit.plan`, the default planner): path and timing are the unknowns of one optimal
#   control problem, transcribed (Chebyshev, 12 intervals) and solved by IPOPT, then verified densely.
# - **decomposition** (`planner="ompl-toppra"`): first a collision-free geometric path (OMPL's RRT-Connect,
#   then smoothing), then the fastest timing along that fixed path under the velocity and torque limits
#   (TOPP-RA). TOPP-RA has no model of torque rate, so that limit is left unchecked until verification.

# %%
problem = ocpkit.load_scenario(ROOT / "scenarios" / "paper" / "case2.yaml")
robot = problem.robot
plans = {"simultaneous": ocpkit.plan(problem), "ompl-toppra": ocpkit.plan(problem, planner="ompl-toppra")}
for name, plan in plans.items():
    print(f"{name:13s} status {plan.status:9s} t_f = {plan.trajectory.tf:.3f} s")
    print(f"              {plan.verification.summary()}")

# %% [markdown]
# A *verified* plan passed every dense check (limits every millisecond, collisions, dynamics, rest at both
# ends); *violated* means the planner finished but some check failed, named in the summary. A shorter t_f is
# only a better answer if the plan is verified.
#
# Below: joint 1, the joint that sweeps, for both plans. Dashed lines are its limits. The τ̇ panel has a
# symmetric-log axis (linear within the limits, logarithmic beyond), because one plan exceeds its limit by
# a large factor.

# %%
JOINT = 0  # joint 1
fig, axes = plt.subplots(1, 4, figsize=(15, 3.5))
for (name, plan), color in zip(plans.items(), ("C0", "C1")):
    samples = plan.trajectory.sample(0.002)
    for ax, values in zip(axes, (samples.q, samples.qd, samples.tau, samples.taud)):
        ax.plot(samples.t, values[:, JOINT], color=color, label=f"{name} ({plan.status})")
limits = ((robot.q_lower[JOINT], robot.q_upper[JOINT]), (-robot.qd_max[JOINT], robot.qd_max[JOINT]),
          (-robot.tau_max[JOINT], robot.tau_max[JOINT]), (-robot.taud_max[JOINT], robot.taud_max[JOINT]))
for ax, (lower, upper), label in zip(axes, limits, ("q (rad)", "q̇ (rad/s)", "τ (N·m)", "τ̇ (N·m/s)")):
    ax.axhline(lower, color="k", ls="--", lw=1)
    ax.axhline(upper, color="k", ls="--", lw=1)
    ax.set_xlabel("t (s)")
    ax.set_ylabel(label)
axes[3].set_yscale("symlog", linthresh=robot.taud_max[JOINT])
axes[0].legend(fontsize=8, loc="lower right")
fig.suptitle(f"case2, joint 1 ({robot.joint_names[JOINT]}): simultaneous planning against path-then-timing")
fig.tight_layout()
fig.savefig(FIGURES / "d-case2-joint1.png", dpi=120)

# %% [markdown]
# ![case2, joint 1: q, q̇, τ and τ̇ of both plans](../figures/notebooks/d-case2-joint1.png)
#
# **Reading the plot.** TOPP-RA times its path as fast as the velocity and torque limits allow, so the
# torque jumps wherever the active limit changes (when joint 1 reaches its velocity limit, and when it
# brakes). At those instants the torque rate far exceeds its limit, and the plan fails verification despite
# its shorter t_f. The simultaneous plan treats the
# torque-rate limit as one more path constraint; it ends up limited by joint 1's velocity instead, and it is
# free to change the path itself, not only the timing along a given one.
