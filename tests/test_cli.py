"""The command line: `list`, and `plan`'s one-line errors (exit 2) for user mistakes."""

from __future__ import annotations

import json

import pytest
from helpers import REPO

from ocpkit.cli import main
from ocpkit.solvers import SOLVERS

CASE2 = REPO / "scenarios/paper/case2.yaml"
GROUPS = ("transcriptions", "dynamics", "constraints", "solvers", "planners", "guesses")


def one_error_line(capsys) -> str:
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), captured.err
    assert "Traceback" not in captured.err
    return lines[0]


def test_list_prints_every_registry_group_with_its_components(capsys):
    assert main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    headings = [line for line in lines if not line.startswith(" ")]
    assert headings == list(GROUPS)
    names = {line.split()[0] for line in lines if line.startswith("  ")}
    assert {"chebyshev", "casadi-rnea", "collision", "torque-rate", "ipopt", "simultaneous", "ompl-toppra",
            "line"} <= names


def test_list_gives_each_constraint_its_docstring_line(capsys):
    main(["list"])
    out = capsys.readouterr().out
    constraints = out.split("constraints\n")[1].split("solvers\n")[0].splitlines()
    assert [line.split()[0] for line in constraints] == ["collision", "state-limits", "torque", "torque-rate"]
    assert all(len(line.split()) > 1 for line in constraints)  # a description follows every name


def test_plan_of_a_missing_scenario_is_a_one_line_error(tmp_path, capsys):
    missing = tmp_path / "nowhere.yaml"
    assert main(["plan", str(missing)]) == 2
    line = one_error_line(capsys)
    assert str(missing) in line


def test_an_option_the_baseline_does_not_take_is_named(capsys):
    assert main(["plan", str(CASE2), "--planner", "ompl-toppra", "--knots", "3"]) == 2
    line = one_error_line(capsys)
    assert "'knots'" in line and "ompl-toppra" in line


def test_an_unknown_solver_lists_the_known_solvers(capsys):
    assert main(["plan", str(CASE2), "--knots", "3", "--solver", "nope"]) == 2
    line = one_error_line(capsys)
    assert "'nope'" in line
    assert all(name in line for name in SOLVERS.names())


def test_an_unknown_planner_is_a_one_line_error(capsys):
    assert main(["plan", str(CASE2), "--planner", "nope"]) == 2
    assert "simultaneous" in one_error_line(capsys)


def test_a_missing_subcommand_is_an_argparse_usage_error(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main([])
    assert exit_info.value.code == 2
    assert "usage: ocpkit" in capsys.readouterr().err


@pytest.mark.slow
def test_plan_of_case2_writes_json_and_exits_zero(tmp_path, capsys):
    out = tmp_path / "out.json"
    assert main(["plan", str(CASE2), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "case2: status verified" in printed and f"wrote {out}" in printed
    document = json.loads(out.read_text())
    assert document["status"] == "verified" and document["robot"] == "industrial6"
    assert document["samples"]["t"][-1] == document["tf"]
