"""Where a simultaneous plan's time goes: IPOPT's function evaluations (CasADi's SX virtual machine) against
everything else in IPOPT (mostly MUMPS factorizing the KKT system), per knot count and dynamics form.

Run from the repository root:  .venv/bin/python scripts/profile_solve.py [--repeats 3]
Prints medians over the four paper cases and `repeats` solves each, measured in this one run.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

import ocpkit

EVALUATIONS = ("nlp_f", "nlp_g", "nlp_grad_f", "nlp_jac_g", "nlp_hess_l")


def profile(problems, knots: int, dynamics: str, repeats: int) -> dict[str, float]:
    """Medians over problems × repeats of: solve wall time, iterations, ms per iteration, evaluation share."""
    walls, iterations, evaluation = [], [], []
    for problem in problems:
        made = ocpkit.build(problem, "chebyshev", knots, dynamics)
        d = made.discretization
        for _ in range(repeats):
            result = made.solver.solve(d.initial_guess(problem), d.parameters(problem), d.bounds(problem))
            walls.append(result.wall_time)
            iterations.append(result.iterations)
            evaluation.append(sum(result.stats.get(f"t_wall_{name}", 0.0) for name in EVALUATIONS))
    return {"solve_s": statistics.median(walls), "iterations": statistics.median(iterations),
            "ms_per_iteration": 1e3 * statistics.median(w / i for w, i in zip(walls, iterations)),
            "evaluation_share": statistics.median(e / w for e, w in zip(evaluation, walls)),
            "variables": d.nlp.x.numel(), "constraints": d.nlp.g.numel()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    problems = [ocpkit.load_scenario(f) for f in sorted(Path("scenarios/paper").glob("case*.yaml"))]
    print(f"{'dynamics':<13}{'knots':>6}{'variables':>10}{'constraints':>12}{'solve [s]':>11}{'iterations':>11}"
          f"{'ms/iter':>9}{'evaluations':>13}{'rest (MUMPS, IPOPT)':>21}")
    for dynamics in ("casadi-rnea", "casadi"):
        for knots in (8, 12, 16):
            r = profile(problems, knots, dynamics, args.repeats)
            print(f"{dynamics:<13}{knots:>6}{r['variables']:>10}{r['constraints']:>12}{r['solve_s']:>11.3f}"
                  f"{r['iterations']:>11.0f}{r['ms_per_iteration']:>9.1f}{r['evaluation_share']:>12.0%}"
                  f"{1 - r['evaluation_share']:>21.0%}")


if __name__ == "__main__":
    main()
