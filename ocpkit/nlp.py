"""The NLP as a value the solvers consume, and the `Layout` that names the parts of its vectors.

    minimize f(w; p)  subject to  lbg ≤ g(w; p) ≤ ubg,  lbx ≤ w ≤ ubx

w (n_w,) is the decision vector and p (n_p,) the parameter vector; a `Layout` names their parts (per knot q,
q̇, q̈, u; check points; t_f; μ, the margin, obstacle data, ...), the way dymos's grid data names node subsets,
so numbers are read and written by name and never by hand-computed offsets. Solvers see only `NLP`; the maps
between a Problem and these numbers belong to the transcription that built it (`transcription.base`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np


class Layout:
    """Named parts of one column vector, in the order they were added.

    `add` appends a new CasADi symbol and records where its entries sit (column-major, as `ca.vec` orders
    them); `name` gives a gathered set of entries a name of its own (e.g. q at every knot). `index(name)` is
    an int array of the part's shape holding positions in the vector."""

    def __init__(self, label: str) -> None:
        self.label, self.size = label, 0
        self._symbols: list[ca.SX] = []
        self._index: dict[str, np.ndarray] = {}

    def add(self, name: str, rows: int = 1, columns: int = 1) -> ca.SX:
        """A new symbol (rows, columns) appended to the vector under `name`; its index has shape (rows,) for a
        column, else (rows, columns)."""
        symbol = ca.SX.sym(name, rows, columns)
        positions = self.size + np.arange(rows * columns).reshape((rows, columns), order="F")
        self.name(name, positions[:, 0] if columns == 1 else positions)
        self._symbols.append(ca.vec(symbol))
        self.size += rows * columns
        return symbol

    def name(self, name: str, index: np.ndarray) -> None:
        """Call the entries at `index` (an int array of any shape) `name`."""
        if name in self._index:
            raise ValueError(f"{self.label} already has a part named {name!r}")
        self._index[name] = np.asarray(index, dtype=int)

    def index(self, name: str) -> np.ndarray:
        """Positions of the part `name` in the vector (an int array of the part's shape)."""
        return self._index[name]

    def __contains__(self, name: str) -> bool:
        return name in self._index

    def symbol(self) -> ca.SX:
        """The whole vector (size, 1): every added symbol, in order."""
        return ca.vertcat(*self._symbols) if self._symbols else ca.SX(0, 1)

    def read(self, vector: np.ndarray, name: str) -> np.ndarray:
        """The entries of `vector` (size,) belonging to `name`, in the part's shape."""
        return np.asarray(vector)[self.index(name)]

    def write(self, vector: np.ndarray, name: str, values) -> None:
        """Set the entries of `vector` (size,) belonging to `name`: values of the part's size (any shape, read
        in C order), or values that broadcast to the part's shape."""
        index, values = self.index(name), np.asarray(values, dtype=float)
        vector[index] = values.reshape(index.shape) if values.size == index.size else values


@dataclass(frozen=True)
class Stages:
    """The stage structure of an optimal-control NLP, for structure-exploiting solvers (fatrop).

    w = [x_0, u_0, x_1, u_1, ..., x_N]: stage k has nx[k] states and nu[k] controls (nu[N] = 0). g is ordered
    stage by stage: for k < N the nx[k+1] gap-closing rows x_{k+1} − F_k(x_k, u_k) = 0 (x_{k+1} with
    coefficient exactly +1), then stage k's ng[k] rows, which read (x_k, u_k) only; the objective is a sum of
    terms each reading one stage's (x_k, u_k)."""

    nx: tuple[int, ...]
    nu: tuple[int, ...]
    ng: tuple[int, ...]


@dataclass(frozen=True)
class PointCall:
    """Rows first_row, first_row + 1, ... of an NLP's g that are `function(*inputs, *parameters)`: one point
    function (one constraint or the dynamics at one point) at that point's `inputs` (expressions of x and p,
    differentiated) and `parameters` (symbols of p, not differentiated)."""

    function: ca.Function
    inputs: tuple[ca.SX, ...]
    parameters: tuple[ca.SX, ...]
    first_row: int
    compiled: bool = False
    """Whether its derivatives are worth compiling to C: set for a function that depends on the robot and the OCP
    only (the dynamics rows), whose C is then the same for every problem of the robot (ocpkit.solvers.compiled)."""
    constraint: Any = None
    """The path constraint (ocpkit.constraints.Constraint) whose rows at a point's values these are, None for other
    rows: a constraint may have its derivatives computed by hand (ocpkit.solvers.collision_derivatives)."""


@dataclass(frozen=True)
class NLP:
    """x: decision column (n_w), p: parameter column (n_p), f: objective, g: constraint column (n_g) with
    numeric bounds lbg ≤ g ≤ ubg; `variables` and `parameters` name the parts of x and p. `shape_key` is
    equal for NLPs that are identical up to the numbers in p and the bounds; `exact_hessian` is False when
    a dynamics backend gives first derivatives only; `stages` is set when the rows and variables follow a
    stage structure; `point_calls` lists the rows that are point functions of few inputs, and `objective_call`
    gives f that way (its first_row unused), so their derivatives can be built point by point
    (ocpkit.solvers.pointwise)."""

    x: ca.SX | ca.MX
    p: ca.SX | ca.MX
    f: ca.SX | ca.MX
    g: ca.SX | ca.MX
    lbg: np.ndarray
    ubg: np.ndarray
    variables: Layout
    parameters: Layout
    shape_key: tuple
    exact_hessian: bool = True
    stages: Stages | None = None
    point_calls: tuple[PointCall, ...] = ()
    objective_call: PointCall | None = None


@dataclass(frozen=True)
class Refinement:
    """What a refinement round may change without a rebuild: where the adaptive check slots sit (fractions of
    t_f, newest first), how much the clearance margin grows (m), and the fraction of the velocity, torque and
    torque-rate limits the NLP may use. The policy that chooses them is `ocpkit.planner.refinement`."""

    check_fractions: np.ndarray = field(default_factory=lambda: np.zeros(0))
    extra_margin: float = 0.0
    limit_scale: float = 1.0
