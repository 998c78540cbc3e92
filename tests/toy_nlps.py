"""Small NLPs with known optima, built by hand on `ocpkit.nlp`, for the solver tests."""

from __future__ import annotations

import casadi as ca
import numpy as np

from ocpkit.nlp import NLP, Layout

DISK = 1.532
"""The Rosenbrock disk's bound on w0² + w1²: active at the optimum."""
GUESS, PARAMS = np.array([-1.0, 2.0, 3.0]), np.array([1.0, 1.75])
BOUNDS = (np.array([-5.0, -5.0, 3.0]), np.array([5.0, 5.0, 3.0]))
"""The Rosenbrock disk's variable bounds: w2 fixed to 3."""


def decision_vector(n_w: int) -> tuple[Layout, ca.SX]:
    """A Layout holding one part `w` (n_w,), and its symbol."""
    variables = Layout("w")
    return variables, variables.add("w", n_w)


def toy_nlp(variables: Layout, f: ca.SX, g: ca.SX, lbg: list, ubg: list, parameters: Layout | None = None,
            exact_hessian: bool = True) -> NLP:
    """The NLP min f s.t. lbg ≤ g ≤ ubg over `variables`, with `parameters` (none by default)."""
    parameters = parameters or Layout("p")
    return NLP(variables.symbol(), parameters.symbol(), f, g, np.array(lbg, dtype=float),
               np.array(ubg, dtype=float), variables, parameters, ("toy", str(f), str(g)), exact_hessian)


def rosenbrock_disk(exact_hessian: bool = True, disk: float = DISK) -> NLP:
    """min (p0 - w0)² + 100 (w1 - w0²)² + (w2 - 1)² s.t. w0² + w1² ≤ disk and w0 + w1 = p1; solved with
    GUESS, PARAMS = (1, 1.75) and BOUNDS (w2 fixed to 3)."""
    variables, w = decision_vector(3)
    parameters = Layout("p")
    p = parameters.add("p", 2)
    f = (p[0] - w[0]) ** 2 + 100 * (w[1] - w[0] ** 2) ** 2 + (w[2] - 1) ** 2
    g = ca.vertcat(w[0] ** 2 + w[1] ** 2, w[0] + w[1] - p[1])
    return toy_nlp(variables, f, g, [-np.inf, 0.0], [disk, 0.0], parameters, exact_hessian)


def optimum(disk: float = DISK) -> np.ndarray:
    """On the line w1 = 1.75 - w0 the disk leaves |w0 - 0.875| ≤ √((disk - 1.53125) / 2); the cost falls
    towards the unconstrained line optimum w0 ≈ 0.914, so w0 sits on the disk's upper end when that is
    below 0.914 (as for DISK)."""
    w0 = np.linspace(0.875, 0.875 + np.sqrt((disk - 1.53125) / 2), 1_000_001)
    cost = (1 - w0) ** 2 + 100 * (1.75 - w0 - w0 ** 2) ** 2
    best = w0[np.argmin(cost)]
    return np.array([best, 1.75 - best, 3.0])
