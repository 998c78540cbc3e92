"""The classic optimal control test problems, each a module with `build() -> Ocp` and its `CLASSIC` record (published
optimum, source), collected in `CLASSICS` by name; `classic(name)` looks one up."""

from __future__ import annotations

from ocpkit.errors import OptionError
from ocpkit.problems import (brachistochrone, bryson_denham, cart_pole, double_integrator, free_flying_robot, goddard,
                             hang_glider)
from ocpkit.problems.classic import Classic

CLASSICS: dict[str, Classic] = {module.CLASSIC.name: module.CLASSIC for module in (
    double_integrator, bryson_denham, brachistochrone, goddard, cart_pole, hang_glider, free_flying_robot)}


def classic(name: str) -> Classic:
    """The classic problem called `name`; OptionError listing the known names otherwise."""
    if name not in CLASSICS:
        raise OptionError(f"unknown classic problem {name!r}; known: {', '.join(CLASSICS)}")
    return CLASSICS[name]


__all__ = ["CLASSICS", "Classic", "classic"]
