"""Suite files of `ocpkit bench run`: scenario sources × a grid of methods × repeats (docs/formats.md, 'Suite files').

A suite is checked with the project schema (ocpkit.formats.schema; errors name the field, e.g. `methods[1].knots`),
every scenario is loaded and validated, and every method's options are checked against its planner, all before
the first plan. `tasks` then gives one plain-data `Task` per (scenario, method, repeat), which any worker process
or Dask worker can run (ocpkit.bench.task).

Scenario sources:
- `paths`: scenario files or globs, relative to the suite file; scene = the file's folder name.
- `mbm`: `{robot, scenes, problems}`: the MotionBenchMaker problems converted to scenario files, looked up in
  `scenarios/mbm/<robot>/<scene>/` next to the suite file or in its parent folder (the shipped subset), then in
  the cache folder of `ocpkit data mbm` (MBM_CACHE): the first of these that holds every problem asked for.
  Problem k (1-based) is the k-th file of the scene folder in natural order (problem2 before problem10); all of
  the first folder's when `problems` is left out. Problems `ocpkit data mbm` found invalid for the robot model
  (its invalid.txt: a start or goal in collision, as vamp's own evaluation finds and skips) are left out, and the
  suite lists them (`Suite.left_out`). Their scene is ROBOT/SCENE (e.g. panda/cage: both robots have the same
  scenes and problem names).
- `random`: `{robot: industrial6, count, seed, obstacles: [min, max]}`: ocpkit.bench.random.random_problems.
"""

from __future__ import annotations

import glob
import inspect
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ocpkit.errors import OcpkitError, within
from ocpkit.formats.schema import Choice, Mapping, Number, Sequence, String, Tagged, check, read_bytes, read_yaml, show


class SuiteError(OcpkitError):
    """A suite file is malformed, names a scenario that is not there, or a method option a planner does not take."""


MBM_CACHE = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "ocpkit" / "mbm"
"""Where `ocpkit data mbm` converts the MotionBenchMaker problems to (one folder per robot and scene)."""
MBM_SHIPPED = Path("scenarios") / "mbm"
"""The shipped MBM subset, relative to the suite file's folder or its parent."""
RANDOM_ROBOTS = ("industrial6",)

_INTEGER = Number("positive", integer=True)
_SECONDS = Number("positive", unbounded=True)
METHOD = Mapping(
    required={"planner": String("a planner name")},
    optional={"transcription": String(), "knots": _INTEGER, "segments": _INTEGER, "solver": String(),
              "dynamics": String(), "guess": String(), "refinements": Number("non-negative", integer=True),
              "max_wall_time": _SECONDS, "single_shot": Choice((True, False)),
              "seed": Number("non-negative", integer=True), "planner_name": String(),
              "planning_time": _SECONDS, "max_checks": _INTEGER, "max_step": Number("positive"),
              "label": String()},
)
"""One method of the grid: a planner and its options (`label` names it in tables; default: planner + options).
`max_wall_time` and `planning_time` may be `.inf`: no wall-clock limit, so that the plan ends by budgets counted in
work (IPOPT iterations, configurations checked: `max_checks`) and the row repeats on any machine and load."""
SOURCE = Tagged({
    "paths": Sequence(String("a file or glob"), min_length=1),
    "mbm": Mapping(required={"robot": String(), "scenes": Sequence(String(), min_length=1)},
                   optional={"problems": Sequence(_INTEGER, min_length=1)}),
    "random": Mapping(required={"count": _INTEGER},
                      optional={"robot": Choice(RANDOM_ROBOTS), "seed": Number("non-negative", integer=True),
                                "obstacles": Sequence(Number("non-negative", integer=True), length=2)}),
})
SUITE = Mapping(required={"scenarios": Sequence(SOURCE, min_length=1), "methods": Sequence(METHOD, min_length=1)},
                optional={"name": String(), "repeats": _INTEGER})
"""A suite file (module docstring)."""


@dataclass(frozen=True)
class Scenario:
    """One problem of a suite as plain data: the parsed scenario mapping (robot files as absolute paths), its
    case name and scene (a random set's scene names its seed: random-seed1)."""

    case: str
    scene: str
    data: dict


@dataclass(frozen=True)
class Method:
    """One method of the grid: `label`, the planner and the options as written in the suite."""

    label: str
    planner: str
    options: dict = field(default_factory=dict)

    def plan_options(self, repeat: int) -> tuple[dict, int | None]:
        """The options for `ocpkit.plan` at repeat `repeat` (0-based) and the OMPL seed they use (None if the
        method uses none): seed = the method's `seed` (default 0) + repeat, OMPL's own or the OMPL guess's;
        `single_shot` → no fallback ladder; `segments` → transcription_options."""
        options = dict(self.options)
        seed = options.pop("seed", 0) + repeat
        if options.pop("single_shot", False):
            options["fallbacks"] = ()
        if "segments" in options:
            options["transcription_options"] = {"segments": options.pop("segments")}
        if self.planner == "simultaneous":
            if options.get("guess") != "ompl":
                return options, None
            options["guess_options"] = {"seed": seed}
        elif "seed" in _planner_parameters(self.planner):
            options["seed"] = seed
        else:
            return options, None
        return options, seed


@dataclass(frozen=True)
class Suite:
    """A checked suite: its name, scenarios, methods and repeats; `left_out`: the MBM problems asked for whose start or
    goal the robot model rejects, each "file: reason" (module docstring)."""

    name: str
    scenarios: tuple[Scenario, ...]
    methods: tuple[Method, ...]
    repeats: int = 1
    left_out: tuple[str, ...] = ()


def load_suite(path: str | Path) -> Suite:
    """Read, check and resolve a suite file; SuiteError (or the scenario's own error) naming what is wrong."""
    path = Path(path)
    text = read_bytes(path, SuiteError, "suite")
    with within(path):
        data = read_yaml(text, SuiteError)
        check(data, SUITE, SuiteError)
        resolved = [_resolve(source, path.parent, f"scenarios[{k}]") for k, source in enumerate(data["scenarios"])]
        methods = [_method(m, f"methods[{k}]") for k, m in enumerate(data["methods"])]
    scenarios = [s for found, _ in resolved for s in found]
    _unique([(s.scene, s.case) for s in scenarios], "scenario (scene, case)")
    _unique([m.label for m in methods], "method label")
    return Suite(data.get("name", path.stem), tuple(scenarios), tuple(methods), data.get("repeats", 1),
                 tuple(line for _, left_out in resolved for line in left_out))


def _unique(names: list, what: str) -> None:
    seen = set()
    for name in names:
        if name in seen:
            raise SuiteError(f"the {what} {show(name)} appears twice; give each a different name")
        seen.add(name)


def _resolve(source: dict, base: Path, where: str) -> tuple[list[Scenario], list[str]]:
    """The scenarios of one source, and the problems it left out ("file: reason")."""
    kind, body = next(iter(source.items()))
    return {"paths": _paths, "mbm": _mbm, "random": _random}[kind](body, base, f"{where}.{kind}")


def _paths(patterns: list[str], base: Path, where: str) -> tuple[list[Scenario], list[str]]:
    """The scenario files matching `patterns` (relative to `base`), each pattern's matches sorted; none left out."""
    files = []
    for k, pattern in enumerate(patterns):
        matches = sorted(glob.glob(str(base / pattern))) if glob.has_magic(pattern) else [str(base / pattern)]
        matches = [m for m in matches if Path(m).is_file()]
        if not matches:
            raise SuiteError(f"{where}[{k}]: no scenario file matches {show(pattern)} (relative to {base})")
        files += [Path(m) for m in matches]
    return [_from_file(f, f.parent.name) for f in files], []


def _from_file(file: Path, scene: str) -> Scenario:
    """The Scenario of a scenario file, loaded and validated now (its errors name the file)."""
    from ocpkit.formats.scenario import load_scenario

    problem = load_scenario(file)  # validates, naming the file
    with within(file):
        data = read_yaml(file.read_bytes(), SuiteError)
    if isinstance(data["robot"], dict):  # robot files relative to the scenario: make them absolute
        data["robot"] = {key: str((file.parent / value).resolve()) for key, value in data["robot"].items()}
    data["name"] = problem.name
    return Scenario(problem.name, scene, data)


def mbm_folders(robot: str, scene: str, base: Path) -> list[Path]:
    """The folders searched for an MBM scene, in order (module docstring)."""
    return [base / MBM_SHIPPED / robot / scene, base.parent / MBM_SHIPPED / robot / scene, MBM_CACHE / robot / scene]


def _natural(path: Path) -> list:
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", path.name)]


def _mbm(body: dict, base: Path, where: str) -> tuple[list[Scenario], list[str]]:
    scenarios, left_out = [], []
    for scene in body["scenes"]:
        folders = mbm_folders(body["robot"], scene, base)
        found = [files for f in folders if (files := sorted(f.glob("*.yaml"), key=_natural))]
        if not found:
            raise SuiteError(f"{where}: no MBM scenario files for robot {show(body['robot'])}, scene {show(scene)} "
                             f"in {', '.join(map(str, folders))}; run `ocpkit data mbm` to convert them")
        numbers = body.get("problems", range(1, len(found[0]) + 1))
        files = next((files for files in found if len(files) >= max(numbers)), None)
        if files is None:
            k = list(numbers).index(max(numbers))
            raise SuiteError(f"{where}.problems[{k}]: problem {numbers[k]} does not exist: the most problems found "
                             f"for {body['robot']}/{scene} are {max(map(len, found))} (in "
                             f"{', '.join(map(str, folders))}); `ocpkit data mbm` converts all of them")
        rejected = _rejected(files[0].parent)
        for number in numbers:
            file = files[number - 1]
            if file.name in rejected:
                left_out.append(f"{file}: {rejected[file.name]}")
            else:
                scenarios.append(_from_file(file, f"{body['robot']}/{scene}"))
    return scenarios, left_out


def _rejected(scene: Path) -> dict[str, str]:
    """File name → reason of the problems of the scene folder `scene` that `ocpkit data mbm` found invalid for its
    robot model (listed in the robot folder's invalid.txt as "path: reason"); none for the shipped subset."""
    listed = scene.parent / "invalid.txt"
    if not listed.is_file():
        return {}
    rejected = {}
    for line in listed.read_text().splitlines():
        file, _, reason = line.partition(": ")
        if Path(file).parent.name == scene.name:
            rejected[Path(file).name] = reason
    return rejected


def _random(body: dict, base: Path, where: str) -> tuple[list[Scenario], list[str]]:
    from ocpkit.bench.random import _scenario as scenario_data  # the random suite's own file content
    from ocpkit.bench.random import random_problems

    seed, low_high = body.get("seed", 1), tuple(body.get("obstacles", (1, 1)))
    if low_high[0] > low_high[1]:
        raise SuiteError(f"{where}.obstacles needs [min, max] with min ≤ max, got {show(list(low_high))}")
    scene = f"random-seed{seed}"
    return [Scenario(p.name, scene, scenario_data(p)) for p in random_problems(seed, body["count"], low_high)], []


def _planner_parameters(planner: str) -> list[str]:
    from ocpkit.planner import PLANNERS

    return list(inspect.signature(PLANNERS.get(planner)).parameters)[1:]


def _method(data: dict, where: str) -> Method:
    """The Method of a schema-checked method mapping; its planner, options and knot count checked."""
    options = {k: v for k, v in data.items() if k not in ("planner", "label")}
    planner = data["planner"]
    try:
        taken = _planner_parameters(planner)
    except OcpkitError as exc:
        raise SuiteError(f"{where}.planner: {exc}") from None
    translated = {"single_shot": "fallbacks", "segments": "transcription_options",
                  "seed": "guess_options" if planner == "simultaneous" else "seed"}
    for key in options:
        if translated.get(key, key) not in taken:
            raise SuiteError(f"{where}.{key}: planner {planner!r} takes no option {key!r}; its options: "
                             f"{', '.join(taken)}")
    if "planner_name" in options:
        from ocpkit.planner.ompl_seed import OMPL_PLANNERS

        if options["planner_name"] not in OMPL_PLANNERS:
            raise SuiteError(f"{where}.planner_name: unknown OMPL planner {options['planner_name']!r}; known: "
                             f"{', '.join(OMPL_PLANNERS)}")
    if options.get("planning_time") == math.inf and "max_checks" not in options:
        raise SuiteError(f"{where}.planning_time: .inf needs max_checks (OMPL's budget in configurations checked), "
                         "or the path search may never end")
    if planner == "simultaneous":
        _check_transcription(options, where)
        if "seed" in options and options.get("guess") != "ompl":
            raise SuiteError(f"{where}.seed: the simultaneous planner uses a seed only with guess: ompl (the OMPL "
                             "guess's); its fallback ladder picks its own seeds")
    label = data.get("label") or " ".join([planner] + [f"{k}={v}" for k, v in options.items()])
    return Method(label, planner, options)


def _check_transcription(options: dict[str, Any], where: str) -> None:
    """SuiteError now if the transcription, solver or dynamics is unknown or the transcription does not take the
    knots (and segments)."""
    from ocpkit.dynamics import DYNAMICS
    from ocpkit.planner import GUESSES
    from ocpkit.registry import construct
    from ocpkit.solvers import SOLVERS
    from ocpkit.transcription import TRANSCRIPTIONS

    for key, registry in (("solver", SOLVERS), ("dynamics", DYNAMICS), ("guess", GUESSES)):
        if key in options:
            try:
                registry.get(options[key])
            except OcpkitError as exc:
                raise SuiteError(f"{where}.{key}: {exc}") from None
    name = options.get("transcription", "chebyshev")
    shape = {"knots": options.get("knots", 12), **({"segments": options["segments"]} if "segments" in options else {})}
    try:
        construct(TRANSCRIPTIONS.get(name), name, shape)
    except OcpkitError as exc:
        raise SuiteError(f"{where}: {exc}") from None
