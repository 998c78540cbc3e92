"""The mesh transcriptions with `staged=True`: the stage structure fatrop is handed (ocpkit.nlp.Stages) against
the NLP's actual Jacobian and Hessian sparsity, the staged NLP against the unstaged one on exact polynomial
motions, and paper case 2 solved by fatrop on it."""

from __future__ import annotations

import functools

import casadi as ca
import numpy as np
import pytest
from helpers import REPO, discretize, evaluate, monomial, polynomial_motion
from numpy.polynomial import Polynomial

import ocpkit
from ocpkit.nlp import Refinement

PROBLEM = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
TF = 2.0
# name → (intervals N, the highest degree of q(t) the method is exact for)
METHODS = {"trapezoidal": (5, 2), "hermite-simpson": (4, 3)}
PAPER_KNOTS = {"trapezoidal": 40, "hermite-simpson": 10}


@functools.cache
def build(name: str, staged: bool):
    return discretize(PROBLEM, name, knots=METHODS[name][0], staged=staged)


@pytest.fixture(scope="module", params=list(METHODS))
def name(request):
    return request.param


class Blocks:
    """Column and row ranges of each stage of a staged NLP, from its Stages alone (the layout fatrop assumes):
    w = [x_0, u_0, ..., x_N]; g = [gap_0, stage_0, gap_1, stage_1, ..., stage_N], gap_k having nx[k+1] rows."""

    def __init__(self, stages) -> None:
        self.N = len(stages.nx) - 1
        self.x, self.u, self.gap, self.rows = [], [], [], []
        column = row = 0
        for k in range(self.N + 1):
            self.x.append(np.arange(column, column + stages.nx[k]))
            column += stages.nx[k]
            self.u.append(np.arange(column, column + stages.nu[k]))
            column += stages.nu[k]
            if k < self.N:
                self.gap.append(np.arange(row, row + stages.nx[k + 1]))
                row += stages.nx[k + 1]
            self.rows.append(np.arange(row, row + stages.ng[k]))
            row += stages.ng[k]
        self.columns, self.row_count = column, row

    def stage_of_columns(self) -> np.ndarray:
        stage = np.full(self.columns, -1)
        for k in range(self.N + 1):
            stage[self.x[k]] = stage[self.u[k]] = k
        return stage

    def gap_mask(self) -> np.ndarray:
        mask = np.zeros(self.row_count, dtype=bool)
        for rows in self.gap:
            mask[rows] = True
        return mask


def random_point(disc, seed=0) -> tuple[np.ndarray, np.ndarray]:
    """A random w near an encoded motion (t_f copies positive) and the problem's parameters."""
    rng = np.random.default_rng(seed)
    w = disc.encode(polynomial_motion(PROBLEM, TF, Polynomial([0.0, 0.3, -0.2, 0.9])))
    w = w + 0.1 * rng.standard_normal(w.shape)
    disc.nlp.variables.write(w, "tf", TF + 0.1 * rng.standard_normal(disc.nlp.variables.index("tf").shape))
    return w, disc.parameters(PROBLEM, Refinement(np.array([0.37])))


def test_stages_account_for_every_variable_and_row(name):
    N, _ = METHODS[name]
    disc = build(name, True)
    nlp, stages = disc.nlp, disc.nlp.stages
    assert stages is not None and build(name, False).nlp.stages is None
    assert len(stages.nx) == len(stages.nu) == len(stages.ng) == N + 1
    assert stages.nu[N] == 0 and all(nu > 0 for nu in stages.nu[:N])
    assert sum(stages.nx) + sum(stages.nu) == nlp.x.numel() == nlp.variables.size
    assert sum(stages.ng) + sum(stages.nx[1:]) == nlp.g.numel() == len(nlp.lbg) == len(nlp.ubg)
    # the states are [q, q̇, q̈, u, T_k]: the knot and its own copy of t_f, in that order
    blocks = Blocks(stages)
    layout = nlp.variables
    tf = layout.index("tf")
    assert tf.shape == (N + 1,)
    for k in range(N + 1):
        np.testing.assert_array_equal(blocks.x[k], np.r_[layout.index("X")[k], tf[k]])
        if k < N:  # the end copy e_k of interval k sits in its controls
            assert set(layout.index("E")[k]) <= set(blocks.u[k])
            assert set(layout.index("q_check")[k]) <= set(blocks.u[k])


def test_jacobian_has_the_block_structure_fatrop_needs(name):
    """Stage rows read (x_k, u_k) only; gap rows read (x_k, u_k, x_{k+1}) with x_{k+1} through +I exactly."""
    disc = build(name, True)
    nlp = disc.nlp
    blocks = Blocks(nlp.stages)
    J = ca.jacobian(nlp.g, nlp.x)
    rows, columns = J.sparsity().get_triplet()
    rows, columns = np.asarray(rows), np.asarray(columns)
    stage = blocks.stage_of_columns()
    assert np.all(stage >= 0)
    row_stage, gap = np.full(blocks.row_count, -1), blocks.gap_mask()
    for k in range(blocks.N + 1):
        row_stage[blocks.rows[k]] = k
        if k < blocks.N:
            row_stage[blocks.gap[k]] = k
    assert np.all(row_stage >= 0)
    on_stage_rows = ~gap[rows]
    np.testing.assert_array_equal(stage[columns[on_stage_rows]], row_stage[rows[on_stage_rows]])
    on_gap_rows = gap[rows]
    reach = stage[columns[on_gap_rows]] - row_stage[rows[on_gap_rows]]
    assert set(reach) == {0, 1}
    # where a gap row reads x_{k+1}, it reads it through exactly +1 on its own state (and nothing of u_{k+1})
    w, p = random_point(disc)
    values = np.asarray(ca.Function("J", [nlp.x, nlp.p], [J])(w, p).full())
    for k in range(blocks.N):
        np.testing.assert_array_equal(values[np.ix_(blocks.gap[k], blocks.x[k + 1])], np.eye(len(blocks.x[k + 1])))
        np.testing.assert_array_equal(values[np.ix_(blocks.gap[k], blocks.u[k + 1])], 0.0)
        assert np.abs(values[np.ix_(blocks.gap[k], np.r_[blocks.x[k], blocks.u[k]])]).max() > 0.5  # − F_k
    # and the structure is not vacuous: every variable is read, every equality row reads something (a collision
    # row may read none: a sphere height under a vertical first joint against the workspace floor is constant)
    assert len(set(columns)) == blocks.columns
    assert set(np.flatnonzero(nlp.lbg == nlp.ubg)) <= set(rows)


def test_the_objective_and_the_lagrangian_do_not_couple_stages(name):
    disc = build(name, True)
    nlp = disc.nlp
    stage = Blocks(nlp.stages).stage_of_columns()
    H = ca.hessian(nlp.f, nlp.x)[0]
    rows, columns = (np.asarray(v) for v in H.sparsity().get_triplet())
    assert len(rows) > 0
    np.testing.assert_array_equal(stage[rows], stage[columns])
    lam = ca.SX.sym("lam", nlp.g.numel())
    H = ca.hessian(nlp.f + ca.dot(lam, nlp.g), nlp.x)[0]
    rows, columns = (np.asarray(v) for v in H.sparsity().get_triplet())
    np.testing.assert_array_equal(stage[rows], stage[columns])
    assert len(set(stage[rows])) == len(nlp.stages.nx)  # every stage has curvature


def test_staged_and_unstaged_agree_on_exact_motions(name):
    _, degree = METHODS[name]
    staged, plain = build(name, True), build(name, False)
    gap = Blocks(staged.nlp.stages).gap_mask()
    assert np.all(staged.nlp.lbg[gap] == 0.0) and np.all(staged.nlp.ubg[gap] == 0.0)
    # without the gap rows, the staged rows are the unstaged ones in the same order
    np.testing.assert_array_equal(staged.nlp.lbg[~gap], plain.nlp.lbg)
    np.testing.assert_array_equal(staged.nlp.ubg[~gap], plain.nlp.ubg)
    exact = (monomial(degree), Polynomial([0.0, 0.3, -0.2, 0.9][: degree + 1]))
    for shape in exact + (monomial(degree + 1), Polynomial([0.0, 0.0, 3.0, -2.0, 0.5])):
        motion = polynomial_motion(PROBLEM, TF, shape)
        f_staged, g_staged = evaluate(staged, staged.encode(motion), PROBLEM)
        f_plain, g_plain = evaluate(plain, plain.encode(motion), PROBLEM)
        if shape in exact:
            for disc, g in ((staged, g_staged), (plain, g_plain)):
                equalities = disc.nlp.lbg == disc.nlp.ubg
                assert np.abs(g[equalities]).max() < 1e-9, (shape, disc.staged)
        else:  # one degree more and the defects show, the same way in both
            assert np.abs(g_staged[staged.nlp.lbg == staged.nlp.ubg]).max() > 1e-5
        assert np.abs(g_staged[gap]).max() < 1e-12  # encode closes the gaps
        # the same objective and (gap rows aside) the same rows, at any encoded motion
        assert f_staged - TF == pytest.approx(f_plain - TF, rel=1e-9, abs=1e-15)  # μ × the jerk integral
        np.testing.assert_allclose(g_staged[~gap], g_plain, rtol=1e-12, atol=1e-12)
    assert f_plain - TF > 1e-5  # the last shape has jerk: the comparison saw the jerk term


def test_staged_encode_decode_and_bounds(name):
    N, degree = METHODS[name]
    disc = build(name, True)
    layout = disc.nlp.variables
    motion = polynomial_motion(PROBLEM, TF, Polynomial([0.0, 0.3, -0.2, 0.9][: degree + 1]))
    w = disc.encode(motion)
    np.testing.assert_array_equal(layout.read(w, "E"), layout.read(w, "X")[1:])  # the end copies close the gaps
    np.testing.assert_array_equal(layout.read(w, "tf"), TF)
    t = np.linspace(0, TF, 23)
    decoded = disc.decode(w)
    assert decoded.tf == TF
    for key in ("q", "qd", "qdd"):
        np.testing.assert_allclose(getattr(decoded.interpolant(t), key), getattr(motion.interpolant(t), key),
                                   atol=1e-9, err_msg=key)
    lbx, ubx = disc.bounds(PROBLEM)
    np.testing.assert_array_equal(layout.read(lbx, "tf"), PROBLEM.time.min)  # every copy
    np.testing.assert_array_equal(layout.read(ubx, "tf"), PROBLEM.time.max)
    for bound in (lbx, ubx):
        np.testing.assert_allclose(layout.read(bound, "q")[0], PROBLEM.start)
        np.testing.assert_allclose(layout.read(bound, "q")[N], PROBLEM.goal)
    assert np.all(np.isinf(layout.read(lbx, "E")))  # the copies are pinned by the gap rows, not by bounds


@pytest.mark.slow
@pytest.mark.parametrize("method", list(PAPER_KNOTS))
def test_fatrop_on_the_staged_nlp_plans_case_2_like_ipopt(method):
    problem = ocpkit.load_scenario(REPO / "scenarios/paper/case2.yaml")
    knots = PAPER_KNOTS[method]
    staged = ocpkit.plan(problem, transcription=method, knots=knots, solver="fatrop",
                         transcription_options={"staged": True})
    reference = ocpkit.plan(problem, transcription=method, knots=knots, solver="ipopt")
    assert staged.status == "verified", staged.verification.summary()
    assert reference.status == "verified", reference.verification.summary()
    assert staged.trajectory.tf == pytest.approx(reference.trajectory.tf, rel=0.002)
