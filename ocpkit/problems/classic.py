"""`Classic`: one classic optimal control test problem with its published optimum, the record the registry in
`ocpkit.problems` holds."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ocpkit.ocp.model import Ocp


@dataclass(frozen=True)
class Classic:
    """A test problem: `build()` makes a fresh `Ocp`; `optimum` is the published objective value as the problem's
    `minimize_*` terms compute it (maximizations are written as minimizations of the negative); `source` says where
    the number comes from; `smooth` says whether the optimal solution is smooth (no bang-bang, singular or
    constrained arcs), i.e. whether a pseudospectral method should reach it to ~1e-6; `note` any caveat."""

    name: str
    build: Callable[[], Ocp]
    optimum: float
    source: str
    smooth: bool
    note: str = ""
