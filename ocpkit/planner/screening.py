"""Active-set screening of the collision rows: the NLP carries only the terms that can matter near the motion.

An arm of many spheres among many obstacles has many collision terms per point (its own sphere pairs and the
sphere-obstacle terms within reach), most of them far from contact on any motion the solver will consider;
IPOPT's linear solves grow with every row. So the planner builds the NLP with the terms whose clearance is below
SCREEN_DISTANCE somewhere along the straight line and along the initial guess (`Constraint.screened`), solves,
and — verification always checks every term densely — keeps a verified plan as it is. A crowded NLP (more than
CROWDED_ROWS rows per point kept that way: an arm of many spheres among shelves and boxes) is screened at the
tighter CROWDED_DISTANCE instead, since each IPOPT iteration's factorization grows with its rows, while a sparse
one (the paper's cases) keeps the wider screen and the rebuilds it spares. An unverified plan whose motion comes
within MISSING_FRACTION of the screening distance of a term left out is solved again, warm-started, with the
terms near it added (a rebuild, part of the computation time), at most MAX_REBUILDS times; such a motion also ends the
refinement rounds at once (ocpkit.planner.refinement), since rounds on an NLP without those rows cannot fix it:
they would spend the rung's iterations and end `violated`, the rows still missing.
Every robot and scene with collision terms screens, the paper's robot too: its paper cases keep few of them, and
IPOPT's linear solves shrink with the rows.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ocpkit.constraints import Constraint, make_constraints
from ocpkit.formats.trajectory import Trajectory
from ocpkit.problem import Problem

SCREEN_DISTANCE = 0.2  # m: a term is kept when its clearance is below this somewhere near the motion
CROWDED_ROWS = 64  # rows per point above which an NLP is crowded: screened at CROWDED_DISTANCE instead
CROWDED_DISTANCE = 0.05  # m
MISSING_FRACTION = 0.5  # a left-out term within this fraction of the screening distance triggers a rebuild
MAX_REBUILDS = 3
SAMPLES = 64  # configurations sampled along a motion (evenly in time)


def screenable_rows(constraints: Sequence[Constraint]) -> int:
    """The rows per point of `constraints` that screening may leave out (`Constraint.term_count`)."""
    return sum(c.term_count for c in constraints)


def worth_screening(constraints: Sequence[Constraint]) -> bool:
    """Whether the constraints have any screenable terms (collision terms) at all."""
    return screenable_rows(constraints) > 0


def line_samples(problem: Problem) -> np.ndarray:
    """SAMPLES configurations (SAMPLES, n) evenly along the straight joint-space line from start to goal."""
    return problem.start + np.outer(np.linspace(0.0, 1.0, SAMPLES), problem.goal - problem.start)


def motion_samples(trajectory: Trajectory) -> np.ndarray:
    """SAMPLES configurations (SAMPLES, n) of the motion, evenly in time."""
    return trajectory.interpolant(np.linspace(0.0, trajectory.tf, SAMPLES)).q


def screened(problem: Problem, kinds: Sequence, near: np.ndarray) -> list[Constraint]:
    """The constraints `kinds` for `problem` screened by the configurations `near` (K, n): at SCREEN_DISTANCE, or
    at CROWDED_DISTANCE when that keeps more than CROWDED_ROWS rows per point."""
    made = make_constraints(problem, kinds, (near, SCREEN_DISTANCE))
    if screenable_rows(made) > CROWDED_ROWS:
        made = make_constraints(problem, kinds, (near, CROWDED_DISTANCE))
    return made


def missing(problem: Problem, constraints: Sequence[Constraint], near: np.ndarray) -> int:
    """Terms left out of `constraints` that come within MISSING_FRACTION of their screening distance of contact
    in `problem` at the configurations `near` (K, n)."""
    return sum(c.missing(problem, near, MISSING_FRACTION * c.screened_at) for c in constraints if c.screened_at)
