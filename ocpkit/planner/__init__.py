"""`plan`: the one call that validates a Problem and solves it with a chosen planner.

Planners (registry `PLANNERS`, entry-point group `ocpkit.planners`) are functions `planner(problem, **options)
-> Plan`: `simultaneous` (ocpkit.planner.simultaneous, the paper's method) and the baselines (ocpkit.baselines).
Initial-guess rules for the simultaneous planner (registry `GUESSES`, group `ocpkit.guesses`) are functions
`guess(problem, discretization) -> w`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

import numpy as np

from ocpkit import interrupt
from ocpkit.errors import OptionError
from ocpkit.problem import Problem
from ocpkit.registry import Registry
from ocpkit.result import Plan
from ocpkit.transcription import Discretization
from ocpkit.validation import validate

PLANNERS: Registry[Callable[..., Plan]] = Registry("planner", "ocpkit.planners")
GUESSES: Registry[Callable[[Problem, Discretization], np.ndarray]] = Registry("initial guess", "ocpkit.guesses")


def plan(problem: Problem, planner: str = "simultaneous", **options: Any) -> Plan:
    """Validate `problem` (ocpkit.validation) and plan it with the named planner; `options` go to that planner
    (e.g. `ocpkit.planner.simultaneous.plan_simultaneous`); one it does not take is
    an OptionError. Ctrl-C during the plan raises KeyboardInterrupt even if the solver caught it
    (ocpkit.interrupt): an interrupted plan never returns."""
    validate(problem)
    function = PLANNERS.get(planner)
    _check_options(planner, function, problem, options)
    with interrupt.watching():
        result = function(problem, **options)
        interrupt.check()
    return result


def _check_options(planner: str, function: Callable[..., Plan], problem: Problem, options: dict) -> None:
    """OptionError if `function` does not take `options`."""
    signature = inspect.signature(function)
    try:
        signature.bind(problem, **options)
    except TypeError as exc:
        raise OptionError(f"planner {planner!r}: {exc}; its options: "
                          f"{', '.join(list(signature.parameters)[1:])}") from exc
