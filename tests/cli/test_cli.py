"""The command line: `list`, help texts from the registries, and one-line errors (exit 2) for user mistakes,
found before any solve; the knot bounds of `plan` for Python callers."""

from __future__ import annotations

import json
import time
from itertools import count

import numpy as np
import pytest
from helpers import REPO

import ocpkit
from ocpkit.cli.main import _planner_options, main, parser
from ocpkit.dynamics import DYNAMICS
from ocpkit.errors import OptionError
from ocpkit.planner import GUESSES, PLANNERS
from ocpkit.planner.build_cache import clear_builds
from ocpkit.solvers import SOLVERS
from ocpkit.transcription import TRANSCRIPTIONS

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
    components = [line for line in lines if line.startswith("  ")]
    names = {line.split()[0] for line in components}
    assert {"chebyshev", "casadi-rnea", "collision", "torque-rate", "ipopt", "simultaneous", "ompl-toppra",
            "line"} <= names
    # one line each: the docstring's first sentence, cut with "…" to fit the line
    assert all(len(line) <= 120 for line in components), max(components, key=len)
    assert all(line.endswith((".", "…")) for line in components)
    ipopt = "  ipopt             IPOPT (interior point) with the exact Hessian and the MUMPS linear solver."
    assert ipopt in components


def test_list_gives_each_constraint_its_docstring_line(capsys):
    main(["list"])
    out = capsys.readouterr().out
    constraints = out.split("constraints\n")[1].split("solvers\n")[0].splitlines()
    names = [line.split()[0] for line in constraints]
    assert names == ["collision", "dynamics-consistency", "state-limits", "torque", "torque-rate"]
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
    assert main(["plan", str(CASE2), "--knots", "6", "--solver", "nope"]) == 2
    line = one_error_line(capsys)
    assert "'nope'" in line
    assert all(name in line for name in SOLVERS.names())


def test_an_unknown_constraint_lists_the_known_constraints(capsys):
    assert main(["plan", str(CASE2), "--knots", "6", "--constraints", "torque, nope"]) == 2
    line = one_error_line(capsys)
    assert "'nope'" in line and "dynamics-consistency" in line


def test_constraints_reach_the_planner_as_a_tuple_of_names():
    args = parser().parse_args(["plan", str(CASE2), "--constraints", "torque, collision,dynamics-consistency"])
    assert _planner_options(args)["constraints"] == ("torque", "collision", "dynamics-consistency")


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


def plan_help() -> str:
    commands = next(a for a in parser()._actions if a.dest == "command")
    return commands.choices["plan"].format_help()


def test_plan_help_lists_the_registered_components_and_the_exit_codes(monkeypatch):
    monkeypatch.setenv("COLUMNS", "1000")  # no line breaks inside names such as scipy-slsqp
    text = " ".join(plan_help().split())
    for registry in (PLANNERS, TRANSCRIPTIONS, DYNAMICS, SOLVERS, GUESSES):
        assert all(name in text for name in registry.names())
    assert "Exit codes: 0 planned and verified" in text and "130 interrupted" in text
    for option in ("--guess", "--refinements", "--seed", "--max-wall-time"):
        assert option in text


@pytest.mark.parametrize("argv, named", [
    (["plan", str(CASE2), "--mu", "-1"], "--mu"),
    (["plan", str(CASE2), "--mu", "nan"], "--mu"),
    (["plan", str(CASE2), "--segments", "0"], "--segments"),
    (["bench", "paper", "--segments", "0"], "--segments"),
    (["plan", str(CASE2), "--knots", "2"], "knots ≥ 6"),
    (["plan", str(CASE2), "--transcription", "trapezoidal", "--knots", "3"], "knots ≥ 4"),
    (["plan", str(CASE2), "--knots", "1000"], f"at most {TRANSCRIPTIONS.get('chebyshev').max_knots}"),
    (["bench", "paper", "--knots", "12", "1000"], f"at most {TRANSCRIPTIONS.get('chebyshev').max_knots}"),
    (["bench", "random", "--knots", "3"], "knots ≥ 6"),
    (["bench", "random", "--obstacles", "2", "1"], "--obstacles"),
    (["bench", "paper", "--repeats", "0"], "--repeats"),
    (["plan", str(CASE2), "--max-wall-time", "-5"], "--max-wall-time"),
])
def test_an_out_of_range_value_is_a_one_line_error_before_any_work(argv, named, capsys):
    began = time.perf_counter()
    assert main(argv) == 2
    assert named in one_error_line(capsys)
    assert time.perf_counter() - began < 5.0  # no build, no solve


def test_output_under_a_plain_file_is_refused_before_planning(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    began = time.perf_counter()
    assert main(["plan", str(CASE2), "-o", str(blocker / "out.json")]) == 2
    assert f"{blocker} is a file" in one_error_line(capsys)
    assert main(["bench", "paper", "--out", str(blocker / "results")]) == 2
    assert f"{blocker} is a file" in one_error_line(capsys)
    assert main(["bench", "paper", "--out", str(blocker)]) == 2
    assert f"{blocker} is a file" in one_error_line(capsys)
    assert main(["plan", str(CASE2), "-o", str(tmp_path)]) == 2
    assert f"{tmp_path} is a folder" in one_error_line(capsys)
    assert time.perf_counter() - began < 5.0


def test_output_in_a_read_only_filesystem_is_refused(capsys):
    assert main(["plan", str(CASE2), "-o", "/proc/out.json"]) == 2
    assert "/proc is not writable" in one_error_line(capsys)


def test_the_wall_time_limit_is_the_baselines_planning_time(capsys):
    assert main(["plan", str(CASE2), "--planner", "ompl-toppra", "--max-wall-time", "2", "--refinements", "1"]) == 2
    line = one_error_line(capsys)
    assert "'refinements'" in line and "planning_time" in line  # max-wall-time was taken: refinements is named


def free_path_values(transcription: str, knots: int, segments: int) -> float:
    """(variables − equality rows − fixed variables − 1) / joints of the NLP actually built: free path values per
    joint besides t_f."""
    problem = ocpkit.load_scenario(CASE2)
    made = ocpkit.build(problem, transcription=transcription, knots=knots,
                        transcription_options={"segments": segments} if segments > 1 else None).discretization
    lbx, ubx = made.bounds(problem)
    free = made.nlp.x.numel() - np.sum(made.nlp.lbg == made.nlp.ubg) - np.sum(lbx == ubx) - 1
    clear_builds()
    return free / problem.robot.n


def smallest_knots(transcription: str, segments: int) -> int:
    """The fewest knots the transcription's constructor takes on `segments` segments."""
    options = {"segments": segments} if segments > 1 else {}
    for knots in count(2):
        try:
            TRANSCRIPTIONS.get(transcription)(knots=knots, **options)
            return knots
        except OptionError:
            continue


@pytest.mark.parametrize("transcription, segments", [("chebyshev", 1), ("lgl", 1), ("lgr", 1), ("trapezoidal", 1),
                                                     ("hermite-simpson", 1), ("chebyshev", 3), ("lgr", 2)])
def test_the_smallest_knot_count_taken_is_the_fewest_that_leave_the_path_free(transcription, segments):
    lowest = smallest_knots(transcription, segments)
    method = TRANSCRIPTIONS.get(transcription)(knots=lowest, **({"segments": segments} if segments > 1 else {}))
    for knots in (lowest, lowest + 1):  # the formula the constructor uses is what a built NLP leaves free
        assert free_path_values(transcription, knots, segments) == method.free_path_values(knots)
    assert method.free_path_values(lowest) >= 1 and method.free_path_values(lowest - 1) < 1


def test_plan_checks_the_knots_for_python_callers():
    problem = ocpkit.load_scenario(CASE2)
    with pytest.raises(OptionError, match="knots ≥ 6"):
        ocpkit.plan(problem, knots=2)
    with pytest.raises(OptionError, match="knot intervals"):
        ocpkit.plan(problem, transcription="hermite-simpson",
                    knots=TRANSCRIPTIONS.get("hermite-simpson").max_intervals + 1)
    with pytest.raises(OptionError, match="needs knots ≥ 4 on 3 segments"):
        ocpkit.plan(problem, knots=3, transcription_options={"segments": 3})
