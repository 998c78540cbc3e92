"""The constraint Jacobian and the Lagrangian's Hessian of an NLP built point by point, for IPOPT's `jac_g` and
`hess_lag` options, from the NLP's point calls (`NLP.point_calls`, `NLP.objective_call`: rows, or the objective,
that are one point function's value).

CasADi differentiates a whole graph at once, sweeping all of it once per colour of the Jacobian's columns; a
Chebyshev row reads every knot of a joint, so there are several colours per knot, and those sweeps make the
set-up slow (figures: docs/design-notes.md). Here each distinct point function F(z) is differentiated once, on
its own few inputs z, and the chain rule joins the calls (Z stacks every call's z; λ_k weighs call k: its rows'
multipliers, or λ_f):

    ∂g/∂x = blockdiag(∂F/∂z(z_k)) A,    A = ∂Z/∂x
    ∇²ₓ(λ_f f + λᵀg) = Aᵀ blockdiag(∇²_z(λ_kᵀF)(z_k)) A + Σᵢ vᵢ ∇²ₓZᵢ,    v = blockdiag(∂F/∂z(z_k))ᵀ λ

The last term appears only where Z is not linear in x (a torque with friction, a path-timing OCP's jerk). Inputs
shared by several calls (the values at one point) are differentiated once. The other rows (collocation and
interpolation defects, nearly linear) are differentiated by CasADi a few rows at a time, and the objective too
when it is not a point call. The result equals CasADi's own derivatives (tests/solvers/test_pointwise.py).

Calls whose inputs are linear in x (A_k constant, or a function of the parameters p alone: a check point whose
time is a parameter) are not inlined: each distinct point function's derivatives are built once, evaluated over
all its points by one mapped call, and joined by constant sparse matrices, blocks B_k placed as Σ_k L_kᵀ B_k R_k
(L_k, R_k: row selections or A_k), whose nonzeros are P times the blocks' stacked nonzeros, P's entries
L_k[i, r] R_k[j, c] per nonzero (i, j) of B_k. Inlining them cost most of the set-up on a large NLP (a copy of a
point Hessian per point); the mapped call evaluates as fast. A parametric A_k(p) joins by MX products instead,
S_k B_k A_k(p) and A_k(p)ᵀ H_k A_k(p); the objective, when it is a point call, joins the same way with λ_f. Calls
marked `compiled` (the dynamics rows: their point function depends on the robot and the OCP only, so its C is
the same for every problem of a robot) run their point derivatives compiled to C (ocpkit.solvers.compiled),
CasADi's virtual machine where nothing compiles. The collision rows' point derivatives are computed by hand in
compiled C (ocpkit.solvers.collision_derivatives: the same for every problem, unlike their graph), mapped over their
calls the same way. Calls with inputs not linear in x (a torque with friction, a path-timing OCP's jerk in its
objective) take the SX graph.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, TypeVar

import casadi as ca
import numpy as np
import scipy.sparse as sps

from ocpkit.kept import Kept
from ocpkit.nlp import NLP, PointCall
from ocpkit.solvers.collision_derivatives import CollisionDerivatives, derivatives_by_hand
from ocpkit.solvers.compiled import cache_directory, compiled, compiler

T = TypeVar("T")
_MADE: Kept[tuple[tuple[ca.Function, ...], Any]] = Kept(16)
"""Point derivatives and compiled code kept for reuse (`_made_once`), with the Functions they were made for."""

ROWS_AT_ONCE = 6
"""The other rows are differentiated this many consecutive rows at a time: rows added together read the same few
knots, so each chunk needs few sweeps over a small graph, where all rows at once need as many sweeps over all of
them (figures: docs/design-notes.md)."""


def pointwise_derivatives(nlp: NLP, compile: bool = True) -> dict[str, ca.Function]:
    """IPOPT's {"jac_g": (x, p) → (g, ∂g/∂x), "hess_lag": (x, p, λ_f, λ_g) → upper triangle of
    ∇²ₓ(λ_f f + λ_gᵀ g)} for `nlp` (SX, with point calls), built as the module docstring says; `compile`: the
    calls marked `compiled` through compiled point functions."""
    maps: dict[tuple[int, ...], InputMap] = {}  # by the inputs' identities: calls at a point share them

    def input_map(call: PointCall) -> InputMap:
        key = tuple(map(id, call.inputs))
        if key not in maps:
            maps[key] = _input_map(call, nlp)
        return maps[key]

    mapped = [(call, a) for call in nlp.point_calls if (a := input_map(call)) is not None]
    kept = [call for call in nlp.point_calls if input_map(call) is None]
    objective = nlp.objective_call
    objective_map = None if objective is None else input_map(objective)
    objective_map = objective_map if isinstance(objective_map, sps.csr_matrix) else None  # placed as a constant
    if not mapped and objective_map is None:
        return _graph_derivatives(nlp, kept, np.zeros(0, dtype=int), objective)
    left = np.concatenate([np.zeros(0, dtype=int), *(_rows(call) for call, _ in mapped)])
    graphs = _graph_derivatives(nlp, kept, left, objective if objective_map is None else None)
    terms = _mapped_terms(nlp, mapped, None if objective_map is None else (objective, objective_map), compile)
    return _joined(nlp, graphs, terms)


InputMap = sps.csr_matrix | ca.SX | None
"""A call's A = ∂z/∂x: a constant sparse matrix, an SX matrix of the parameters p only (a check point whose time is
a parameter: z is linear in x with coefficients set by p), or None (z not linear in x)."""


def _input_map(call: PointCall, nlp: NLP) -> InputMap:
    """`call`'s A = ∂z/∂x (InputMap)."""
    a = ca.jacobian(ca.vertcat(*(ca.vec(v) for v in call.inputs)), nlp.x)
    if ca.depends_on(a, nlp.x):
        return None
    if ca.depends_on(a, nlp.p):
        return a
    return sps.csr_matrix(ca.evalf(a).sparse())


def _rows(call: PointCall) -> np.ndarray:
    """The rows of g that `call` gives."""
    return np.arange(call.first_row, call.first_row + call.function.numel_out(0))


def _graph_derivatives(nlp: NLP, point_calls: list[PointCall], left: np.ndarray,
                       objective_call: PointCall | None) -> dict[str, ca.Function]:
    """The derivatives as SX graphs, of g's rows less `left` (rows another term gives: zero here), the objective's
    through `objective_call` if given, not at all if the NLP has a call for it elsewhere (mapped)."""
    x, p, f, g = nlp.x, nlp.p, nlp.f, nlp.g
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g.numel())
    rows = [_rows(c) for c in point_calls]
    calls = [*zip(point_calls, (lam_g[r.tolist()] for r in rows))]
    if objective_call is not None:
        calls.append((objective_call, lam_f))
    A, jacobians, hessians = _chain(calls, x)
    called = np.concatenate([*rows, left]).astype(int)
    others = np.setdiff1d(np.arange(g.numel()), called).tolist()
    rest = g[others]
    objective = 0 if nlp.objective_call is not None else lam_f * f
    hess = ca.mtimes([A.T, ca.diagcat(*hessians), A]) + ca.hessian(objective + ca.dot(lam_g[others], rest), x)[0]
    if ca.depends_on(A, x):
        hess += _second_order(calls, jacobians, x)
    constraint_jacobians = jacobians[:len(rows)]  # the objective's, if any, comes last
    point_rows = ca.mtimes(ca.diagcat(*constraint_jacobians), A[:sum(j.size2() for j in constraint_jacobians), :])
    starts = range(0, len(others), ROWS_AT_ONCE)
    other_rows = [ca.jacobian(rest[i:min(i + ROWS_AT_ONCE, len(others))], x) for i in starts]
    jac = ca.vertcat(point_rows, ca.SX(len(left), x.numel()), *other_rows)
    jac = jac[np.argsort(np.concatenate([called, others])).tolist(), :]
    return {"jac_g": ca.Function("nlp_jac_g", [x, p], [g, jac], ["x", "p"], ["g", "jac_g_x"]),
            "hess_lag": ca.Function("nlp_hess_l", [x, p, lam_f, lam_g], [ca.triu(hess)],
                                    ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])}


def _joined(nlp: NLP, graphs: dict[str, ca.Function],
            terms: tuple[ca.Function, ca.Function]) -> dict[str, ca.Function]:
    """IPOPT's derivatives (as `pointwise_derivatives`) as MX Functions: the SX `graphs` plus the mapped `terms`."""
    x, p = ca.MX.sym("x", nlp.x.numel()), ca.MX.sym("p", nlp.p.numel())
    lam_f, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", nlp.g.numel())
    g, jac = graphs["jac_g"](x, p)
    hess = graphs["hess_lag"](x, p, lam_f, lam_g) + terms[1](x, p, lam_f, lam_g)
    return {"jac_g": ca.Function("nlp_jac_g", [x, p], [g, jac + terms[0](x, p)], ["x", "p"], ["g", "jac_g_x"]),
            "hess_lag": ca.Function("nlp_hess_l", [x, p, lam_f, lam_g], [hess],
                                    ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])}


def _mapped_terms(nlp: NLP, mapped: list[tuple[PointCall, InputMap]],
                  objective: tuple[PointCall, sps.csr_matrix] | None,
                  compile: bool) -> tuple[ca.Function, ca.Function]:
    """MX Functions (x, p → the `mapped` calls' rows of ∂g/∂x; x, p, λ_f, λ_g → their part, and the `objective`
    call's, of the Hessian's upper triangle) for calls whose input maps A are constant or functions of p (module
    docstring): one point function's derivatives mapped over all its calls, compiled where every call is marked
    `compiled` (and `compile`), else run by CasADi's virtual machine."""
    x, p, n_x, n_g = nlp.x, nlp.p, nlp.x.numel(), nlp.g.numel()
    X, P = ca.MX.sym("x", n_x), ca.MX.sym("p", nlp.p.numel())
    lam_f, lam_g = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", n_g)
    groups: dict[int, list[tuple[PointCall, InputMap]]] = {}
    for call, a in mapped:
        groups.setdefault(id(call.function), []).append((call, a))
    derivatives, marked = [], []
    for calls in groups.values():
        names = (f"jac_{len(marked)}", f"hess_{len(marked)}")  # the compiled ones named alike for every problem
        function, differentiated = calls[0][0].function, len(calls[0][0].inputs)
        make = functools.partial(_point_nonzeros, function, differentiated, names)
        by_hand = derivatives_by_hand(calls[0][0].constraint) if compile else None
        if by_hand is not None:
            derivatives.append(by_hand)
        elif compile and all(call.compiled for call, _ in calls):
            marked.append(len(derivatives))
            derivatives.append(_made_once((function,), (differentiated, names), make))
        else:
            derivatives.append(make())
    to_compile = tuple(f for k in marked for f, _ in derivatives[k])
    where = ("compiled", str(cache_directory()), compiler())  # the library depends on both
    loaded = _made_once(to_compile, where, lambda: compiled(to_compile)) if marked else None
    for k, pair in zip(marked, zip(loaded[0::2], loaded[1::2]) if loaded else ()):
        derivatives[k] = [(f, sparsity) for f, (_, sparsity) in zip(pair, derivatives[k])]
    jacobians, hessians, jacobian_places, hessian_places = [], [], [], []
    jacobian_sums, hessian_sums = [], []  # the terms of calls with parametric A, as MX matrices
    for calls, made in zip(groups.values(), derivatives):
        arguments = _mapped_arguments([call for call, _ in calls], x, p)(X, P)
        rows = [_rows(call) for call, _ in calls]
        weights = ca.reshape(lam_g[np.concatenate(rows).tolist()], -1, len(calls))
        if isinstance(made, CollisionDerivatives):  # mapped already
            jacobian, hessian = made.mapped(calls[0][0].function, len(calls[0][0].inputs), len(calls))
            jacobian_sparsity, hessian_sparsity = made.sparsities(_input_size(calls[0][0]))
        else:
            (point_jacobian, jacobian_sparsity), (point_hessian, hessian_sparsity) = made
            jacobian, hessian = point_jacobian.map(len(calls)), point_hessian.map(len(calls))
        blocks = jacobian(*arguments), hessian(*arguments, weights)
        constant = [k for k, (_, a) in enumerate(calls) if isinstance(a, sps.csr_matrix)]
        jacobians.append(ca.vec(blocks[0][:, constant]))
        hessians.append(ca.vec(blocks[1][:, constant]))
        for k in constant:
            selection = sps.csr_matrix((np.ones(len(rows[k])), (np.arange(len(rows[k])), rows[k])),
                                       shape=(len(rows[k]), n_g))
            jacobian_places.append((jacobian_sparsity, selection, calls[k][1]))
            hessian_places.append((hessian_sparsity, calls[k][1], calls[k][1]))
        parametric = [k for k, (_, a) in enumerate(calls) if not isinstance(a, sps.csr_matrix)]
        maps = ca.Function("input_maps", [p], [calls[k][1] for k in parametric]).call([P]) if parametric else []
        for k, a in zip(parametric, maps):
            selection = ca.MX(ca.DM(sps.csc_matrix((np.ones(len(rows[k])), (rows[k], np.arange(len(rows[k])))),
                                                   shape=(n_g, len(rows[k])))))
            jacobian_sums.append(ca.mtimes([selection, ca.MX(jacobian_sparsity, blocks[0][:, k]), a]))
            hessian_sums.append(ca.mtimes([a.T, ca.MX(hessian_sparsity, blocks[1][:, k]), a]))
    if objective is not None:
        call, a = objective
        _, (hessian, sparsity) = _point_nonzeros(call.function, len(call.inputs), ("objective_jac", "objective_hess"))
        hessians.append(hessian(*_mapped_arguments([call], x, p)(X, P), lam_f))
        hessian_places.append((sparsity, a, a))
    jacobian_nonzeros = ca.vertcat(*jacobians) if jacobians else ca.MX(0, 1)
    jac = _placed(jacobian_places, jacobian_nonzeros, n_g, n_x) + sum(jacobian_sums, ca.MX(n_g, n_x))
    hess = _placed(hessian_places, ca.vertcat(*hessians), n_x, n_x, upper=True) + ca.triu(sum(hessian_sums,
                                                                                             ca.MX(n_x, n_x)))
    return (ca.Function("mapped_jacobian", [X, P], [jac]),
            ca.Function("mapped_hessian", [X, P, lam_f, lam_g], [hess]))


def _input_size(call: PointCall) -> int:
    """The length of z, the differentiated inputs of `call`'s point function stacked."""
    return sum(call.function.numel_in(i) for i in range(len(call.inputs)))


def _made_once(functions: tuple[ca.Function, ...], key: tuple, make: Callable[[], T]) -> T:
    """make()'s value, made once for these Function objects and `key` while it is kept (`_MADE`): the dynamics
    rows' point Function is one object for every NLP of a robot and OCP (ocpkit.transcription.assembly), so its
    derivatives and their compiled code are built once. The entry holds the Functions, so no other object takes
    their ids while it lasts."""
    return _MADE.get((*map(id, functions), *key), lambda: (functions, make()))[1]


def forget_made() -> None:
    """Forget the point derivatives and compiled code kept for reuse (`_made_once`)."""
    _MADE.clear()


def _mapped_arguments(calls: list[PointCall], x: ca.SX, p: ca.SX) -> ca.Function:
    """x, p → the inputs and parameters of `calls` (one point function's) side by side, as its map takes them."""
    function = calls[0].function
    columns = [ca.vertcat(*(ca.vec(v) for v in (*c.inputs, *c.parameters))) for c in calls]
    sizes = [function.numel_in(i) for i in range(function.n_in())]
    stacked = ca.vertsplit(ca.horzcat(*columns), np.concatenate([[0], np.cumsum(sizes)]).astype(int).tolist())
    return ca.Function("mapped_arguments", [x, p], [ca.reshape(s, function.size1_in(i), function.size2_in(i) *
                                                                len(calls)) for i, s in enumerate(stacked)])


def _placed(places: list[tuple[ca.Sparsity, sps.csr_matrix, sps.csr_matrix]], nonzeros: ca.MX, rows: int,
            columns: int, upper: bool = False) -> ca.MX:
    """Σ_k L_kᵀ B_k R_k (rows × columns, its upper triangle if `upper`) for places (sparsity of B_k, L_k, R_k), the
    B_k's nonzeros stacked in `nonzeros`: P · nonzeros on the sum's sparsity, P's entries L_k[i, r] R_k[j, c] for
    each nonzero (i, j) of B_k (module docstring)."""
    if not places:
        return ca.MX(rows, columns)
    targets, sources, weights, offset = [], [], [], 0
    for sparsity, left, right in places:
        i, j = np.asarray(sparsity.row(), dtype=int), np.asarray(sparsity.get_col(), dtype=int)
        by_left, r, left_values = _spread(left, i)
        by_right, c, right_values = _spread(right, j[by_left])
        r = r[by_right]
        keep = r <= c if upper else slice(None)
        targets.append((c * rows + r)[keep])
        sources.append((offset + by_left[by_right])[keep])
        weights.append((left_values[by_right] * right_values)[keep])
        offset += len(i)
    reached, target = np.unique(np.concatenate(targets), return_inverse=True)
    P = sps.csc_matrix((np.concatenate(weights), (target, np.concatenate(sources))), shape=(len(reached), offset))
    sparsity = ca.Sparsity.triplet(rows, columns, (reached % rows).tolist(), (reached // rows).tolist())
    return ca.MX(sparsity, ca.mtimes(ca.DM(P), nonzeros))


def _spread(matrix: sps.csr_matrix, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each entry e of `rows` repeated over the nonzeros of `matrix`'s row rows[e]: (e, their column, their value)."""
    starts, counts = matrix.indptr[rows], np.diff(matrix.indptr)[rows]
    owner = np.repeat(np.arange(len(rows)), counts)
    position = np.repeat(starts - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
    return owner, matrix.indices[position], matrix.data[position]


def _chain(calls: list[tuple[PointCall, ca.SX]], x: ca.SX) -> tuple[ca.SX, list[ca.SX], list[ca.SX]]:
    """(A = ∂Z/∂x with Z every call's z stacked, [∂F/∂z(z_k)], [∇²_z(λ_kᵀF)(z_k)]) for (call, λ_k) pairs; an input
    object shared by several calls is differentiated once."""
    derivatives: dict[int, tuple[ca.Function, ca.Function]] = {}
    offsets: dict[int, int] = {}  # id of an input → its first row in Z
    unique, positions, jacobians, hessians, size = [], [], [], [], 0
    for call, weights in calls:
        if id(call.function) not in derivatives:
            derivatives[id(call.function)] = _point_derivatives(call.function, len(call.inputs))
        jacobian, hessian = derivatives[id(call.function)]
        jacobians.append(jacobian(*call.inputs, *call.parameters))
        hessians.append(hessian(*call.inputs, *call.parameters, weights))
        for value in call.inputs:
            if id(value) not in offsets:
                offsets[id(value)], size = size, size + value.numel()
                unique.append(value)
            positions.append(offsets[id(value)] + np.arange(value.numel()))
    if not calls:
        return ca.SX(0, x.numel()), [], []
    Z = ca.vertcat(*(ca.vec(v) for v in unique))
    return ca.jacobian(Z, x)[np.concatenate(positions).tolist(), :], jacobians, hessians


def _second_order(calls: list[tuple[PointCall, ca.SX]], jacobians: list[ca.SX], x: ca.SX) -> ca.SX:
    """Σᵢ vᵢ ∇²ₓZᵢ with v = blockdiag(∂F/∂z)ᵀ λ: the chain rule's term for inputs not linear in x."""
    Z = ca.vertcat(*(ca.vec(value) for call, _ in calls for value in call.inputs))
    v = ca.densify(ca.mtimes(ca.diagcat(*jacobians).T, ca.vertcat(*(weights for _, weights in calls))))
    symbols = ca.SX.sym("v", Z.numel())
    return ca.substitute(ca.hessian(ca.dot(symbols, Z), x)[0], symbols, v)


def _point_derivatives(function: ca.Function, differentiated: int) -> tuple[ca.Function, ca.Function]:
    """(∂F/∂z, ∇²_z(λᵀF)) of a point function F whose first `differentiated` inputs make z, as Functions of F's
    inputs (and λ, one per output row)."""
    symbols, lam, jacobian, hessian = _derivative_expressions(function, differentiated)
    return (ca.Function("point_jacobian", symbols, [jacobian]),
            ca.Function("point_hessian", [*symbols, lam], [hessian]))


def _point_nonzeros(function: ca.Function, differentiated: int,
                    names: tuple[str, str]) -> list[tuple[ca.Function, ca.Sparsity]]:
    """As `_point_derivatives`, each derivative as (a Function so named whose one output is the column of its
    nonzeros, its sparsity)."""
    symbols, lam, jacobian, hessian = _derivative_expressions(function, differentiated)
    return [(ca.Function(name, inputs, [ca.vec(d.nz[:])]), d.sparsity())  # a column even for a one-row F
            for name, inputs, d in zip(names, (symbols, [*symbols, lam]), (jacobian, hessian))]


def _derivative_expressions(function: ca.Function, differentiated: int) -> tuple[list[ca.SX], ca.SX, ca.SX, ca.SX]:
    """(F's input symbols, λ, ∂F/∂z, ∇²_z(λᵀF)) for `_point_derivatives`."""
    symbols = [ca.SX.sym(function.name_in(i), function.size_in(i)) for i in range(function.n_in())]
    rows = function(*symbols)
    z = ca.vertcat(*(ca.vec(s) for s in symbols[:differentiated]))
    lam = ca.SX.sym("lam", rows.numel())
    return symbols, lam, ca.jacobian(rows, z), ca.hessian(ca.dot(lam, rows), z)[0]
