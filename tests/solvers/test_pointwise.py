"""IPOPT's derivatives built point by point (ocpkit.solvers.pointwise) against CasADi's own Jacobian and Hessian of
the same NLP, at random points, for every transcription family, a scene with spheres, a box and a cylinder, the
path-timing OCP (whose point inputs are not linear in w) and a robot with friction; with the dynamics rows' point
derivatives compiled to C (ocpkit.solvers.compiled) and without, and without a C compiler."""

from __future__ import annotations

import dataclasses

import casadi as ca
import numpy as np
import pytest
from helpers import REPO

import ocpkit.solvers.compiled as compiled_module
from ocpkit import load_scenario
from ocpkit.constraints import make_constraints
from ocpkit.dynamics import make_dynamics
from ocpkit.geometry.scene import Boxes, Cylinders
from ocpkit.path_spline import PathSpline
from ocpkit.nlp import Refinement
from ocpkit.planner import screening
from ocpkit.solvers.pointwise import _input_map, forget_made, pointwise_derivatives
from ocpkit.transcription import TRANSCRIPTIONS
from ocpkit.transcription.ocp import PathTimingOCP

CASE = load_scenario(REPO / "scenarios/paper/case1.yaml")
PROBLEM = dataclasses.replace(CASE, scene=dataclasses.replace(
    CASE.scene, boxes=Boxes(np.array([[0.9, 0.3, 0.6]]), np.array([[0.2, 0.3, 0.4]]), np.eye(3)[None]),
    cylinders=Cylinders(np.array([[0.8, -0.4, 0.7]]), np.array([0.1]), np.array([0.5]), np.eye(3)[None])))


def _path_timing() -> PathTimingOCP:
    waypoints = np.stack([CASE.start, (CASE.start + CASE.goal) / 2 + 0.3, CASE.goal])
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))])
    return PathTimingOCP(CASE.robot, PathSpline.fit(lengths, waypoints))


def _reference(nlp) -> ca.Function:
    """CasADi's own Jacobian of g and upper triangle of the Lagrangian's Hessian, of (w, p, λ_f, λ_g)."""
    x, p, f, g = nlp.x, nlp.p, nlp.f, nlp.g
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g.numel())
    return ca.Function("reference", [x, p, lam_f, lam_g], [
        ca.jacobian(g, x), ca.triu(ca.hessian(lam_f * f + ca.dot(lam_g, g), x)[0])])


def _assert_same_derivatives(discretization, problem, compile: bool = True,
                             reference: ca.Function | None = None) -> dict[str, ca.Function]:
    nlp = discretization.nlp
    assert nlp.point_calls and nlp.exact_hessian
    x, p, g = nlp.x, nlp.p, nlp.g
    reference = _reference(nlp) if reference is None else reference
    ours = pointwise_derivatives(nlp, compile)
    rng = np.random.default_rng(0)
    w0, params = discretization.initial_guess(problem), discretization.parameters(problem)
    for _ in range(3):
        w = w0 + 0.1 * rng.standard_normal(w0.size)
        lam = (rng.uniform(0.5, 2.0), rng.standard_normal(g.numel()))
        jac_expected, hess_expected = (ca.densify(m).full() for m in reference(w, params, *lam))
        values, jac = ours["jac_g"](w, params)
        np.testing.assert_allclose(np.asarray(values).ravel(), ca.Function("g", [x, p], [g])(w, params).full().ravel())
        np.testing.assert_allclose(ca.densify(jac).full(), jac_expected, rtol=1e-9, atol=1e-9)
        hess = ca.densify(ours["hess_lag"](w, params, *lam)).full()
        np.testing.assert_allclose(hess, hess_expected, rtol=1e-9, atol=1e-9 * np.abs(hess_expected).max())
    return ours


def _compiled_in(function: ca.Function) -> list[str]:
    """The names of the compiled (external) Functions `function` calls."""
    return [f.name() for f in function.find_functions() if f.is_a("External")]


def _discretization(transcription: str, options: dict):
    dynamics = make_dynamics("casadi-rnea", PROBLEM.robot)
    return TRANSCRIPTIONS.get(transcription)(**options).build(PROBLEM, dynamics, make_constraints(PROBLEM))


@pytest.fixture(scope="module")
def built():
    """`built(transcription, options)`: its discretization of PROBLEM and CasADi's own derivatives of it, made once
    for the module (the compiled and the uncompiled variant compare against the same)."""
    made = {}

    def get(transcription: str, options: dict):
        key = (transcription, tuple(sorted(options.items())))
        if key not in made:
            discretization = _discretization(transcription, options)
            made[key] = discretization, _reference(discretization.nlp)
        return made[key]

    return get


@pytest.mark.parametrize("compile", [
    pytest.param(True, marks=pytest.mark.skipif(compiled_module.compiler() is None, reason="no C compiler")), False])
@pytest.mark.parametrize("transcription, options", [
    ("chebyshev", {"knots": 8}), ("lgl", {"knots": 5, "segments": 2}), ("lgr", {"knots": 6}),
    ("hermite-simpson", {"knots": 6}), ("trapezoidal", {"knots": 8})])
def test_pointwise_derivatives_equal_casadis_own(built, transcription, options, compile):
    discretization, reference = built(transcription, options)
    ours = _assert_same_derivatives(discretization, PROBLEM, compile, reference)
    assert bool(_compiled_in(ours["hess_lag"])) == compile  # the dynamics rows' point Hessian, loaded from C


@pytest.mark.skipif(compiled_module.compiler() is None, reason="no C compiler (make test installs gcc as root)")
def test_compiled_libraries_are_kept_and_reused(tmp_path, monkeypatch):
    monkeypatch.setenv("OCPKIT_COMPILED_DIR", str(tmp_path))
    _assert_same_derivatives(_discretization("chebyshev", {"knots": 6}), PROBLEM)
    libraries = sorted(tmp_path.glob("*.so"))
    assert len(libraries) == 1
    stamp = libraries[0].stat().st_mtime_ns
    _assert_same_derivatives(_discretization("chebyshev", {"knots": 9}), PROBLEM)  # other knots, the same C
    assert sorted(tmp_path.glob("*.so")) == libraries and libraries[0].stat().st_mtime_ns == stamp


@pytest.mark.skipif(compiled_module.compiler() is None, reason="no C compiler (make test installs gcc as root)")
def test_a_damaged_library_falls_back_to_the_graphs_with_a_warning(tmp_path, monkeypatch):
    monkeypatch.setenv("OCPKIT_COMPILED_DIR", str(tmp_path))
    monkeypatch.setattr(compiled_module, "_warned", set())
    _assert_same_derivatives(_discretization("chebyshev", {"knots": 6}), PROBLEM)
    forget_made()  # the code loaded is kept for later builds: let it go, and load it again
    for library in tmp_path.glob("*.so"):
        library.write_bytes(b"not a shared library")
    with pytest.warns(UserWarning, match="cannot load"):
        ours = _assert_same_derivatives(_discretization("chebyshev", {"knots": 6}), PROBLEM)
    assert not _compiled_in(ours["hess_lag"])


def test_without_a_compiler_the_graphs_are_used_with_a_warning(tmp_path, monkeypatch):
    monkeypatch.setenv("OCPKIT_COMPILED_DIR", str(tmp_path))
    monkeypatch.setenv("CC", "no-such-compiler-here")
    monkeypatch.setattr(compiled_module, "_warned", set())
    with pytest.warns(UserWarning, match="no C compiler"):
        ours = _assert_same_derivatives(_discretization("chebyshev", {"knots": 6}), PROBLEM)
    assert not _compiled_in(ours["hess_lag"]) and not list(tmp_path.iterdir())


def test_pointwise_derivatives_with_inputs_not_linear_in_w():
    """The path-timing OCP's state p(s), p′(s)ṡ, ... is not linear in w: its constraint rows read the node (s, ṡ, s̈,
    the slopes), mapped like a robot's, and its objective's jerk p′s⃛ + ... takes the chain rule's second-order
    term."""
    dynamics = make_dynamics("casadi", CASE.robot)
    constraints = make_constraints(CASE, ("state-limits", "torque", "torque-rate"))
    discretization = TRANSCRIPTIONS.get("chebyshev")(knots=8).build(CASE, dynamics, constraints, _path_timing())
    nlp = discretization.nlp
    assert nlp.point_calls and all(_input_map(call, nlp) is not None for call in nlp.point_calls)
    assert _input_map(nlp.objective_call, nlp) is None
    _assert_same_derivatives(discretization, CASE)


def test_a_callback_backend_gives_no_point_calls():
    dynamics = make_dynamics("pinocchio", CASE.robot)
    discretization = TRANSCRIPTIONS.get("chebyshev")(knots=6).build(CASE, dynamics, make_constraints(CASE))
    assert discretization.nlp.point_calls == () and discretization.nlp.objective_call is None


def test_check_points_whose_times_are_parameters_are_mapped_too():
    """A check point's inputs are linear in w with coefficients set by its time, an NLP parameter (refinement
    rounds move it): its derivatives join through ∂z/∂w as a function of p, the same values as CasADi's own."""
    problem = load_scenario(REPO / "scenarios/mbm/panda/table_pick/0001.yaml")
    constraints = make_constraints(problem, screen=(screening.line_samples(problem), 0.05))
    discretization = TRANSCRIPTIONS.get("chebyshev")(knots=6).build(
        problem, make_dynamics("casadi-rnea", problem.robot), constraints)
    nlp = discretization.nlp
    assert sum(isinstance(_input_map(call, nlp), ca.SX) for call in nlp.point_calls) >= 8
    ours, reference = pointwise_derivatives(nlp), _reference(nlp)
    params = discretization.parameters(problem, Refinement(np.array([0.3, 0.55, 0.8])))
    w = discretization.initial_guess(problem) + 0.05 * np.random.default_rng(0).standard_normal(nlp.x.numel())
    lam = (1.3, np.random.default_rng(1).standard_normal(nlp.g.numel()))
    jac_expected, hess_expected = (ca.densify(m).full() for m in reference(w, params, *lam))
    np.testing.assert_allclose(ca.densify(ours["jac_g"](w, params)[1]).full(), jac_expected, rtol=1e-9, atol=1e-9)
    hess = ca.densify(ours["hess_lag"](w, params, *lam)).full()
    np.testing.assert_allclose(hess, hess_expected, rtol=1e-9, atol=1e-9 * np.abs(hess_expected).max())
