"""The documentation site (mkdocs.yml, docs/) builds in strict mode with every page, and a broken link or an API
block naming a module that does not exist fails the build; README.md stays a short front door without history."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from helpers import REPO

PAGES = [
    "index", "getting-started", "cli", "formats", "robots-and-data", "benchmarks", "results", "design-notes",
    "design/moved-from-code", "architecture", "contributing", "transcription",
    "concepts/index", "concepts/problem", "concepts/transcription", "concepts/dynamics", "concepts/constraints",
    "concepts/solvers", "concepts/verify", "concepts/planner", "concepts/ladder", "concepts/baselines",
    "api/index", "api/ocpkit", "api/planner", "api/simultaneous", "api/ladder", "api/result", "api/verify",
    "api/problem", "api/transcription", "api/dynamics", "api/constraints", "api/solvers", "api/nlp",
    "api/scenario", "api/trajectory", "api/baselines", "api/ocp", "api/problems", "concepts/ocp", "classics",
    "notebooks/a_transcription_by_hand", "notebooks/b_nodes_and_convergence", "notebooks/c_costates",
    "notebooks/d_pendulum_to_robot", "notebooks/e_swapping_components",
]
"""Every page the site must have (docs/PAGE.md → PAGE.html: the site uses file URLs)."""

API_MODULES = {
    "api/ocpkit": "ocpkit", "api/planner": "ocpkit.planner", "api/simultaneous": "ocpkit.planner.simultaneous",
    "api/ladder": "ocpkit.planner.ladder", "api/result": "ocpkit.result", "api/verify": "ocpkit.verify",
    "api/problem": "ocpkit.problem", "api/transcription": "ocpkit.transcription", "api/dynamics": "ocpkit.dynamics",
    "api/constraints": "ocpkit.constraints", "api/solvers": "ocpkit.solvers", "api/nlp": "ocpkit.nlp",
    "api/scenario": "ocpkit.formats.scenario", "api/trajectory": "ocpkit.formats.trajectory",
    "api/baselines": "ocpkit.baselines", "api/ocp": "ocpkit.ocp", "api/problems": "ocpkit.problems",
}
"""The public API each reference page documents (its `::: module` block)."""


def mkdocs_build(config: Path, site: Path) -> subprocess.CompletedProcess:
    """`mkdocs build --strict` of `config` into `site`: the completed process, its output captured."""
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}  # Material's notice about MkDocs 2.0 is not the site's
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file", str(config),
                           "--site-dir", str(site)], check=False, capture_output=True, text=True, env=env,
                          timeout=300)


def test_the_site_builds_strictly_with_every_page(tmp_path: Path) -> None:
    result = mkdocs_build(REPO / "mkdocs.yml", tmp_path / "site")
    assert result.returncode == 0, result.stdout + result.stderr
    missing = [page for page in PAGES if not (tmp_path / "site" / f"{page}.html").is_file()]
    assert not missing, f"pages not built: {missing}"
    for page, module in API_MODULES.items():
        html = (tmp_path / "site" / f"{page}.html").read_text()
        assert f'id="{module}.' in html, f"{page}.html documents no member of {module}"


def broken_copy(tmp_path: Path, break_it: str) -> Path:
    """A copy of mkdocs.yml and docs/ in `tmp_path` with one page broken (`break_it`: "link" or "api"); the
    copied config reads the package from the repository. Returns the config's path."""
    shutil.copytree(REPO / "docs", tmp_path / "docs")
    config = yaml.safe_load((REPO / "mkdocs.yml").read_text())
    config["plugins"][1]["mkdocstrings"]["handlers"]["python"]["paths"] = [str(REPO)]
    (tmp_path / "mkdocs.yml").write_text(yaml.safe_dump(config, allow_unicode=True, sort_keys=False))
    if break_it == "link":
        page = tmp_path / "docs" / "getting-started.md"
        page.write_text(page.read_text() + "\nSee [the missing page](no-such-page.md).\n")
    else:
        page = tmp_path / "docs" / "api" / "nlp.md"
        page.write_text(page.read_text().replace("::: ocpkit.nlp", "::: ocpkit.no_such_module"))
    return tmp_path / "mkdocs.yml"


@pytest.mark.parametrize(("break_it", "message"), [("link", "no-such-page.md"),
                                                   ("api", "ocpkit.no_such_module")])
def test_a_broken_link_or_api_block_fails_the_build(tmp_path: Path, break_it: str, message: str) -> None:
    result = mkdocs_build(broken_copy(tmp_path, break_it), tmp_path / "site")
    assert result.returncode != 0
    assert message in result.stdout + result.stderr


def test_the_readme_is_a_front_door_without_history() -> None:
    text = (REPO / "README.md").read_text()
    lines = text.splitlines()
    assert len(lines) <= 150
    assert lines[2] == "```sh" and lines[5] == "```", "README starts with the two set-up commands"
    assert lines[3].startswith("make demo ") and lines[4].startswith("make test ")
    assert not re.search(r"\bstop \d+", text, re.IGNORECASE), "progress notes belong in docs/design-notes.md"
    assert not re.search(r"\b20\d\d-\d\d-\d\d\b", text), "dated figures belong in docs/results.md"
    for target in re.findall(r"\]\((docs/[^)#]+)", text):
        assert (REPO / target).exists(), f"README links to {target}, which does not exist"
