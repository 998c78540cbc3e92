"""The teaching notebooks (docs/notebooks/*.py, jupytext percent format) run top to bottom as scripts and write
every figure their markdown shows; the pictures they show are committed in docs/figures/notebooks/ (the docs
site renders the notebooks without executing them)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO / "docs" / "notebooks").glob("[a-z]_*.py"))
FIGURE = re.compile(r"\.\./figures/notebooks/([\w.-]+\.png)")
"""A figure a notebook's markdown shows: ![caption](../figures/notebooks/<file>.png)."""
PNG = b"\x89PNG\r\n\x1a\n"


def figures(notebook: Path) -> list[str]:
    """The PNG files `notebook` shows, in order, each once."""
    return list(dict.fromkeys(FIGURE.findall(notebook.read_text(encoding="utf-8"))))


def test_the_five_notebooks_are_there() -> None:
    assert set("abcde") <= {n.stem[0] for n in NOTEBOOKS}, NOTEBOOKS


@pytest.mark.slow
@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda n: n.stem)
def test_notebook_runs_and_writes_its_figures(notebook: Path, tmp_path: Path) -> None:
    env = {**os.environ, "OCPKIT_FIGURES": str(tmp_path), "MPLBACKEND": "Agg"}
    result = subprocess.run([sys.executable, str(notebook)], cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=600, check=False)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    shown = figures(notebook)
    assert shown, f"{notebook.name} shows no figure"
    for name in shown:
        path = tmp_path / name
        assert path.is_file(), f"{notebook.name} did not write {name}; it wrote {sorted(os.listdir(tmp_path))}"
        assert path.read_bytes()[:8] == PNG, f"{name} is not a PNG"
        assert name.startswith(f"{notebook.stem[0]}-"), f"{name}: prefix it with the notebook's letter"


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda n: n.stem)
def test_the_figures_a_notebook_shows_are_committed(notebook: Path) -> None:
    missing = [name for name in figures(notebook) if not (REPO / "docs" / "figures" / "notebooks" / name).is_file()]
    assert not missing, f"run `python {notebook.relative_to(REPO)}` to write {missing} into docs/figures/notebooks/"
