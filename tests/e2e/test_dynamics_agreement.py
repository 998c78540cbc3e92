"""Every dynamics backend plans every paper case at 8 knots to the same motion time as the default
(`casadi-rnea`), within 1 %: swapping the backend changes how the defect is computed, not the answer. (8 knots,
not 12: the pinocchio callbacks take half the time, and the agreement is the same.)"""

from __future__ import annotations

import functools

import pytest
from helpers import REPO

import ocpkit
from ocpkit.dynamics import DYNAMICS

CASES = sorted((REPO / "scenarios/paper").glob("*.yaml"))
REFERENCE = "casadi-rnea"


@functools.cache
def _plan(case: str, dynamics: str) -> ocpkit.Plan:
    return ocpkit.plan(ocpkit.load_scenario(REPO / "scenarios/paper" / case), knots=8, dynamics=dynamics)


@pytest.mark.slow
@pytest.mark.parametrize("dynamics", [name for name in DYNAMICS.names() if name != REFERENCE])
@pytest.mark.parametrize("case", [path.name for path in CASES])
def test_backend_plans_the_same_motion_time(case, dynamics):
    reference, plan = _plan(case, REFERENCE), _plan(case, dynamics)
    assert reference.ok and plan.ok, (reference.status, plan.status, plan.stats.solver_message)
    assert abs(plan.trajectory.tf - reference.trajectory.tf) <= 0.01 * reference.trajectory.tf
