"""The package's layers (docs/architecture.md): no module imports from a layer above its own."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from helpers import REPO

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("values", ("ocpkit.errors", "ocpkit.registry", "ocpkit.interrupt", "ocpkit.kept", "ocpkit.nlp",
                "ocpkit.tolerances", "ocpkit.formats", "ocpkit.formats.schema", "ocpkit.formats.trajectory")),
    ("robots and geometry", ("ocpkit.robots", "ocpkit.geometry")),
    ("problem", ("ocpkit.problem", "ocpkit.validation", "ocpkit.formats.scenario", "ocpkit.formats.moveit",
                 "ocpkit.formats.mbm")),
    ("symbolic pieces", ("ocpkit.dynamics", "ocpkit.constraints", "ocpkit.path_spline", "ocpkit.ocp.model",
                         "ocpkit.problems")),
    ("transcription and solvers", ("ocpkit.transcription", "ocpkit.solvers", "ocpkit.ocp.instance",
                                   "ocpkit.ocp.solve", "ocpkit.ocp.rockit_peer")),
    ("certification", ("ocpkit.verify", "ocpkit.result", "ocpkit.formats.record", "ocpkit.ocp")),
    ("planner", ("ocpkit.planner",)),
    ("baselines", ("ocpkit.baselines",)),
    ("commands", ("ocpkit.bench", "ocpkit.viewer", "ocpkit.cli")),
)
"""Layers from the bottom up, each a tuple of module prefixes. `ocpkit` itself (the public API) is above all."""


def layer(module: str) -> int:
    """The index in LAYERS of `module` (dotted name), by its longest prefix there (`ocpkit.formats` is a layer
    apart from `ocpkit.formats.scenario`); len(LAYERS) for the package's own `ocpkit`."""
    if module == "ocpkit":
        return len(LAYERS)
    matches = [(len(p), index) for index, (_, prefixes) in enumerate(LAYERS) for p in prefixes
               if module == p or module.startswith(p + ".")]
    assert matches, f"{module} is in no layer of LAYERS: add it"
    return max(matches)[1]


def modules() -> dict[str, Path]:
    """Every module of the package (dotted name → file), its __init__ files as the package's name."""
    package = REPO / "ocpkit"
    found = {}
    for path in sorted(package.rglob("*.py")):
        parts = path.relative_to(REPO).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found[name] = path
    return found


def imported(module: str, path: Path) -> set[str]:
    """The ocpkit modules `module` imports, at the top or inside a function (`from ocpkit import x` as ocpkit.x
    when x is a module, else as ocpkit)."""
    names = set()
    known = modules()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names if a.name.startswith("ocpkit"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("ocpkit"):
            for alias in node.names:
                sub = f"{node.module}.{alias.name}"
                names.add(sub if sub in known else node.module)
    return names


ALL = modules()


def test_every_module_has_a_layer() -> None:
    for module in ALL:
        if module != "ocpkit" and not module.endswith("__main__"):
            layer(module)


@pytest.mark.parametrize("module", [m for m in ALL if m != "ocpkit"])
def test_no_import_from_a_higher_layer(module: str) -> None:
    own = layer(module)
    upward = sorted(m for m in imported(module, ALL[module]) if layer(m) > own)
    assert not upward, f"{module} ({LAYERS[own][0]}) imports from higher layers: {upward}"


def test_the_layer_test_sees_an_upward_import(tmp_path: Path) -> None:
    bad = tmp_path / "bad.py"
    bad.write_text("def f():\n    from ocpkit.planner.ladder import climb\n")
    assert "ocpkit.planner.ladder" in imported("ocpkit.verify", bad)
    assert layer("ocpkit.planner.ladder") > layer("ocpkit.verify")


def test_at_most_twelve_modules_at_the_root() -> None:
    assert len(list((REPO / "ocpkit").glob("*.py"))) <= 12
