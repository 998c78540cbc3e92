"""The build cache: one Discretization and prepared solver per problem shape, bounded, keyed on what shapes the
NLP (and nothing else)."""

from __future__ import annotations

import dataclasses
import shutil

import numpy as np
import pytest
import yaml
from helpers import REPO

import ocpkit
from ocpkit.constraints import DEFAULT_CONSTRAINTS
from ocpkit.constraints.limits import TorqueLimit
from ocpkit.errors import OptionError, RegistryError
from ocpkit.planner import build_cache
from ocpkit.planner.build_cache import clear_builds
from ocpkit.robots.robot import DATA_DIR
from ocpkit.transcription.pseudospectral import Pseudospectral

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")


@pytest.fixture(autouse=True)
def empty_cache():
    clear_builds()
    yield
    clear_builds()


def with_obstacles(centers, radii) -> ocpkit.Problem:
    scene = dataclasses.replace(PROBLEM.scene, obstacle_centers=np.asarray(centers, float).reshape(-1, 3),
                                obstacle_radii=np.asarray(radii, float))
    return dataclasses.replace(PROBLEM, scene=scene)


def test_a_second_build_of_the_same_shape_is_the_cached_one():
    first = ocpkit.build(PROBLEM, knots=6)
    again = ocpkit.build(dataclasses.replace(PROBLEM, goal=PROBLEM.goal + 0.01, mu=0.1), knots=6)
    assert first.setup_time > 0 and again.setup_time == 0.0
    assert again.discretization is first.discretization and again.solver is first.solver
    nlp = first.discretization.nlp
    assert nlp.x.numel() == nlp.variables.size and nlp.p.numel() == nlp.parameters.size
    assert first.solver.nlp is nlp


def test_a_moved_obstacle_reuses_the_build_and_an_extra_one_does_not():
    first = ocpkit.build(PROBLEM, knots=6)
    moved = with_obstacles(PROBLEM.scene.obstacle_centers + [0.0, 0.05, 0.0], PROBLEM.scene.obstacle_radii)
    assert ocpkit.build(moved, knots=6).discretization is first.discretization
    extra = with_obstacles([*PROBLEM.scene.obstacle_centers, [0.9, -0.9, 0.6]], [*PROBLEM.scene.obstacle_radii, 0.1])
    added = ocpkit.build(extra, knots=6)
    assert added.discretization is not first.discretization and added.setup_time > 0
    assert added.discretization.nlp.parameters.index("collision.obstacle_radius").size == 2


def test_the_moved_obstacle_is_in_the_parameters_of_the_shared_build():
    made = ocpkit.build(PROBLEM, knots=6).discretization
    moved = with_obstacles([[1.0, 0.2, 0.9]], [0.2])
    p = made.parameters(moved)
    np.testing.assert_array_equal(made.nlp.parameters.read(p, "collision.obstacle_center"), [[1.0, 0.2, 0.9]])


def test_a_different_solver_option_or_transcription_option_is_a_new_build():
    first = ocpkit.build(PROBLEM, knots=6)
    solver = ocpkit.build(PROBLEM, knots=6, solver_options={"max_iterations": 50})
    margin = ocpkit.build(PROBLEM, knots=6, transcription_options={"margin": 0.02})
    assert len({id(b.discretization) for b in (first, solver, margin)}) == 3
    assert margin.discretization.margin == 0.02


def test_an_unknown_transcription_option_is_an_option_error_naming_it():
    with pytest.raises(OptionError, match="bogus"):
        ocpkit.build(PROBLEM, knots=6, transcription_options={"bogus": 1})


def test_an_edited_robot_spec_is_a_new_build_with_the_new_limits(tmp_path):
    for name in ("robot.urdf", "spec.yaml"):
        shutil.copy(DATA_DIR / "industrial6" / name, tmp_path / name)
    spec = yaml.safe_load((tmp_path / "spec.yaml").read_text())
    spec["limits"]["velocity"] = [v / 2 for v in spec["limits"]["velocity"]]
    (tmp_path / "spec.yaml").write_text(yaml.safe_dump(spec))
    slow_robot = ocpkit.load_robot({"urdf": str(tmp_path / "robot.urdf"), "spec": str(tmp_path / "spec.yaml")})
    np.testing.assert_allclose(slow_robot.qd_max, PROBLEM.robot.qd_max / 2)

    original = ocpkit.build(PROBLEM, knots=6).discretization
    edited_problem = dataclasses.replace(PROBLEM, robot=slow_robot)
    edited = ocpkit.build(edited_problem, knots=6).discretization
    assert edited is not original
    cases = ((original, PROBLEM, PROBLEM.robot.qd_max), (edited, edited_problem, slow_robot.qd_max))
    for made, problem, qd_max in cases:
        lbx, ubx = made.bounds(problem)
        interior = slice(1, -1)  # the start and goal knots are at rest
        inner = made.nlp.variables.read(ubx, "qd")[interior], made.nlp.variables.read(lbx, "qd")[interior]
        np.testing.assert_allclose(inner[0], np.broadcast_to(qd_max, inner[0].shape))
        np.testing.assert_allclose(inner[1], -np.broadcast_to(qd_max, inner[1].shape))


def test_an_unchanged_copy_of_the_robot_files_shares_the_build(tmp_path):
    for name in ("robot.urdf", "spec.yaml"):
        shutil.copy(DATA_DIR / "industrial6" / name, tmp_path / name)
    copy = ocpkit.load_robot({"urdf": str(tmp_path / "robot.urdf"), "spec": str(tmp_path / "spec.yaml")})
    first = ocpkit.build(PROBLEM, knots=6)
    assert ocpkit.build(dataclasses.replace(PROBLEM, robot=copy), knots=6).discretization is first.discretization


def test_the_cache_keeps_the_most_recently_used_builds_within_its_memory_budget(monkeypatch):
    clear_builds()
    monkeypatch.setattr(build_cache, "SMALLEST_BUILD", 400 * 1024**2)  # every build counts as 400 MiB
    monkeypatch.setattr(build_cache, "_resident", lambda: 0)  # and the process itself holds nothing
    monkeypatch.setenv("OCPKIT_BUILD_MEMORY_MB", "900")  # room for two
    a = ocpkit.build(PROBLEM, knots=6).discretization
    b = ocpkit.build(PROBLEM, knots=7).discretization
    assert ocpkit.build(PROBLEM, knots=6).discretization is a  # a is now the most recent
    ocpkit.build(PROBLEM, knots=8)  # evicts b, the least recently used
    assert ocpkit.build(PROBLEM, knots=6).discretization is a
    rebuilt = ocpkit.build(PROBLEM, knots=7)
    assert rebuilt.discretization is not b and rebuilt.setup_time > 0


def test_a_process_past_its_budget_keeps_only_the_newest_build_and_returns_the_memory(monkeypatch):
    clear_builds()
    monkeypatch.setenv("OCPKIT_BUILD_MEMORY_MB", "900")
    released = []
    monkeypatch.setattr(build_cache, "_release", lambda: released.append(True))
    a = ocpkit.build(PROBLEM, knots=6).discretization
    b = ocpkit.build(PROBLEM, knots=7).discretization  # both estimates are far below 900 MiB
    assert ocpkit.build(PROBLEM, knots=6).discretization is a and not released
    monkeypatch.setattr(build_cache, "_resident", lambda: 901 * 1024**2)  # the process grew past the budget
    ocpkit.build(PROBLEM, knots=8)
    assert len(released) == 2 and len(build_cache._BUILDS) == 1  # a and b dropped, each freed at once
    assert ocpkit.build(PROBLEM, knots=7).discretization is not b


def test_clear_builds_forgets_every_build():
    first = ocpkit.build(PROBLEM, knots=6)
    clear_builds()
    assert ocpkit.build(PROBLEM, knots=6).discretization is not first.discretization


def test_drop_screened_forgets_the_builds_screened_for_a_motion_and_keeps_the_others():
    near = np.vstack([PROBLEM.start, PROBLEM.goal])
    screened, shared = ocpkit.build(PROBLEM, knots=6, near=near), ocpkit.build(PROBLEM, knots=6)
    assert screened.screened and not shared.screened
    build_cache.drop_screened()
    assert ocpkit.build(PROBLEM, knots=6).setup_time == 0.0  # the unscreened build stays for other problems
    assert ocpkit.build(PROBLEM, knots=6, near=near).discretization is not screened.discretization


def test_a_solver_option_with_a_dict_value_is_accepted_and_cached():
    options = {"qpsol_options": {"printLevel": "none"}}  # sqpmethod passes any nlpsol option through
    first = ocpkit.build(PROBLEM, knots=6, solver="sqpmethod", solver_options=options)
    assert ocpkit.build(PROBLEM, knots=6, solver="sqpmethod", solver_options=options).solver is first.solver


def test_a_constraint_class_of_the_same_name_gets_its_own_build():
    def limit(fraction: float) -> type:
        class Slow(TorqueLimit):
            name = "slow"

        Slow.fraction = fraction
        return Slow

    first = ocpkit.build(PROBLEM, knots=6, constraints=DEFAULT_CONSTRAINTS + (limit(0.3),))
    second = ocpkit.build(PROBLEM, knots=6, constraints=DEFAULT_CONSTRAINTS + (limit(0.9),))
    assert second.discretization is not first.discretization and second.setup_time > 0


def test_an_unknown_solver_is_named_before_any_build(monkeypatch):
    monkeypatch.setattr(Pseudospectral, "build", lambda *args: pytest.fail("built an NLP for an unknown solver"))
    with pytest.raises(RegistryError, match="unknown solver 'nope'"):
        ocpkit.build(PROBLEM, knots=7, solver="nope")


def test_the_newest_build_stays_even_past_the_budget(monkeypatch):
    clear_builds()
    monkeypatch.setenv("OCPKIT_BUILD_MEMORY_MB", "0")
    first = ocpkit.build(PROBLEM, knots=6)
    assert first.nbytes >= build_cache.SMALLEST_BUILD and build_cache.cached_bytes() == first.nbytes
    assert ocpkit.build(PROBLEM, knots=6).discretization is first.discretization
    ocpkit.build(PROBLEM, knots=7)
    assert ocpkit.build(PROBLEM, knots=6).discretization is not first.discretization


def test_a_budget_that_is_no_number_is_named(monkeypatch):
    monkeypatch.setenv("OCPKIT_BUILD_MEMORY_MB", "lots")
    with pytest.raises(OptionError, match="OCPKIT_BUILD_MEMORY_MB"):
        build_cache.memory_budget()
