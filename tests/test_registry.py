"""Registries: built-ins come from pyproject's entry points, a third party adds a component through its own
entry-point metadata, unknown names list the known ones, and `ocpkit list` shows everything."""

from __future__ import annotations

import pytest
from helpers import REPO

import ocpkit
from ocpkit.cli.main import main
from ocpkit.errors import RegistryError
from ocpkit.transcription import TRANSCRIPTIONS

BUILTINS = ["chebyshev", "trapezoidal", "hermite-simpson", "casadi", "casadi-rnea", "ipopt", "simultaneous",
            "ompl-toppra"]


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(RegistryError, match="unknown transcription 'nope'; known: chebyshev, hermite-simpson"):
        ocpkit.plan(ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml"), transcription="nope")


def test_list_shows_every_builtin_with_its_description(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    for name in BUILTINS:
        assert f"\n  {name} " in out
    assert "transcriptions\n  chebyshev         Chebyshev pseudospectral transcription" in out


@pytest.mark.slow
def test_third_party_transcription_from_an_entry_point_plans_by_name(monkeypatch):
    """The toy plugin (tests/plugin_fixture: a module and its dist-info, never installed) appears on sys.path
    after the registry has been used, as if pip-installed mid-session, and plans by name."""
    monkeypatch.setattr(TRANSCRIPTIONS, "_items", {})  # forget loaded components, the toy included, afterwards
    with pytest.raises(RegistryError):
        TRANSCRIPTIONS.get("toy")
    monkeypatch.syspath_prepend(str(REPO / "tests/plugin_fixture"))
    assert "toy" in TRANSCRIPTIONS.names()
    result = ocpkit.plan(ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml"), transcription="toy", knots=8)
    assert TRANSCRIPTIONS.get("toy").__module__ == "ocpkit_toy"
    assert result.status == "verified", result.verification.summary()
