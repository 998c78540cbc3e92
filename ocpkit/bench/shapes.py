"""`ocpkit bench shapes`: what the smooth box and cylinder rows cost. One scenario with boxes and cylinders is
planned as it is and with its boxes and cylinders removed (spheres and workspace kept); the table gives the
collision rows per point (of them, those for boxes and cylinders), the NLP's rows, and the median computation
time and iterations of the single-shot paper settings."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from ocpkit.bench.common import machine, measure
from ocpkit.constraints.collision import SphereCollision
from ocpkit.formats.scenario import load_scenario
from ocpkit.geometry.scene import Boxes, Cylinders
from ocpkit.planner.build_cache import build
from ocpkit.planner.ladder import SINGLE_SHOT
from ocpkit.problem import Problem

DEFAULT_SCENARIO = Path("scenarios/shapes/boxes.yaml")


def run_shapes_benchmark(scenario: Path = DEFAULT_SCENARIO, knots: int = 12, repeats: int = 5) -> list[dict]:
    """Print and return one row per variant (with / without boxes and cylinders) of `scenario`."""
    problem = load_scenario(scenario)
    bare = dataclasses.replace(problem, scene=dataclasses.replace(problem.scene, boxes=Boxes(), cylinders=Cylinders(),
                                                                  names=()))
    rows = [_row("with boxes and cylinders", problem, knots, repeats),
            _row("without them", bare, knots, repeats)]
    print(f"{problem.name}: {len(problem.scene.boxes)} boxes, {len(problem.scene.cylinders)} cylinders, "
          f"{len(problem.scene.obstacle_radii)} spheres; chebyshev N={knots}, ipopt, single shot")
    print(f"{'scene':<26}{'collision rows/point':>22}{'of them primitives':>20}{'NLP rows':>10}{'status':>10}"
          f"{'t_f s':>8}{'iterations':>12}{'median s':>10}")
    for r in rows:
        print(f"{r['scene']:<26}{r['collision_rows']:>22}{r['primitive_rows']:>20}{r['nlp_rows']:>10}"
              f"{r['status']:>10}{r['tf']:>8.3f}{r['iterations']:>12}{r['solve_time']:>10.3f}")
    print(f"{machine()}; computation times are medians of {repeats} runs")
    return rows


def _row(label: str, problem: Problem, knots: int, repeats: int) -> dict:
    collision = SphereCollision(problem)
    spheres = len(problem.scene.obstacle_radii)
    primitive_rows = int(collision.obstacle_mask[:, spheres:].sum())
    nlp_rows = build(problem, knots=knots).discretization.nlp.g.numel()
    measured = measure(problem, repeats, knots=knots, fallbacks=SINGLE_SHOT)
    return {"scene": label, "collision_rows": collision.term_count,
            "primitive_rows": primitive_rows, "nlp_rows": nlp_rows, "status": measured.plan.status,
            "tf": measured.plan.trajectory.tf, "iterations": measured.plan.stats.iterations,
            "solve_time": measured.solve_time}
