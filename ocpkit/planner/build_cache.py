"""The build cache: one Discretization and prepared solver per problem shape, shared by every query of it.

`build(problem, ...)` returns the Discretization of the problem's shape and a solver prepared for its NLP,
building both on first use; `shape` then `prepare` does the same in two steps, so a plan can screen its collision
rows by its guess, found on the first Discretization, before it prepares a solver (ocpkit.planner.simultaneous).
The key is the transcription's options, the dynamics backend (its robot's content included), each constraint's
shape, the solver and its options: start, goal, time bounds, μ and obstacle positions are numbers, so queries that
differ only in them share a build. The cache holds the most recently used
builds within a memory budget (`memory_budget`): each build's size is estimated as the growth of the process's
resident memory while it was made, and the least recently used builds are dropped while the estimates add up to
more than the budget or the process's resident memory exceeds it (the newest always stays); dropped builds' memory
is handed back to the operating system.
"""

from __future__ import annotations

import ctypes
import gc
import inspect
import os
import time
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import psutil

from ocpkit.constraints import DEFAULT_CONSTRAINTS, Constraint, make_constraints
from ocpkit.dynamics import Dynamics, make_dynamics
from ocpkit.errors import OptionError
from ocpkit.kept import Kept
from ocpkit.planner.screening import screened
from ocpkit.problem import Problem
from ocpkit.registry import construct
from ocpkit.solvers import SOLVERS, PreparedSolver
from ocpkit.solvers.base import STAGES_NEEDED, Solver
from ocpkit.solvers.compiled import compile_seconds
from ocpkit.solvers.pointwise import forget_made
from ocpkit.transcription import TRANSCRIPTIONS, Discretization
from ocpkit.transcription.assembly import forget_defects
from ocpkit.transcription.ocp import OCP

MEMORY_BUDGET = 2 * 1024**3
"""Bytes of resident memory a process keeps cached builds within by default ($OCPKIT_BUILD_MEMORY_MB overrides)."""
SMALLEST_BUILD = 1024**2
"""Bytes a build is counted as at least (memory freed by an evicted build can be reused by the next one)."""


@dataclass(frozen=True)
class Build:
    """A Discretization, a solver prepared for its NLP, the seconds its set-up took (0 when it came from the
    cache) and their split: `setup_parts` {"graph": the transcription's build, "solver": the solver's prepare,
    "compile": the part of it spent compiling C (ocpkit.solvers.compiled; 0 when the disk cache had it)}
    (s, empty when cached)."""

    discretization: Discretization
    solver: PreparedSolver
    setup_time: float
    setup_parts: dict = field(default_factory=dict)
    nbytes: int = 0  # estimated memory held, bytes (0 when it came from the cache)
    screened: bool = False  # its collision rows screened for one problem's motion (`drop_screened`)


_BUILDS: OrderedDict[tuple, Build] = OrderedDict()
_LAYOUTS: Kept[Discretization] = Kept(8)
"""Discretizations without constraints kept for reuse (`layout`)."""


@dataclass(frozen=True)
class Shaped:
    """A problem shape's Discretization whose solver is not prepared yet (`prepare`): a cached build's, or a new one
    whose graph took `graph_time` s. The step between lets a plan look at its guess on the discretization, and
    screen again, before it pays for the solver."""

    discretization: Discretization
    key: tuple
    solver: Solver  # to prepare for the discretization's NLP
    cached: Build | None
    graph_time: float
    resident: int  # bytes of resident memory before the graph was built
    screened: bool = False  # its collision rows screened for one problem's motion


def build(problem: Problem, transcription: str = "chebyshev", knots: int = 12, dynamics: str | Dynamics = "casadi-rnea",
          solver: str = "ipopt", constraints: Sequence[str | type[Constraint]] = DEFAULT_CONSTRAINTS,
          transcription_options: dict | None = None, solver_options: dict | None = None,
          dynamics_options: dict | None = None, ocp: OCP | None = None, near: np.ndarray | None = None) -> Build:
    """The build for `problem`'s shape (module docstring): components by registered name (`ocpkit list`), a
    dynamics backend also as an instance; unknown options raise OptionError. `ocp` is the OCP to discretize:
    the robot OCP of `problem` by default (ocpkit.transcription.ocp). With `near` (K, n), the constraints keep only
    the rows that can be active near those configurations (ocpkit.planner.screening). `shape` then `prepare` is
    the same in two steps."""
    return prepare(shape(problem, transcription, knots, dynamics, solver, constraints, transcription_options,
                         solver_options, dynamics_options, ocp, near))


def shape(problem: Problem, transcription: str = "chebyshev", knots: int = 12, dynamics: str | Dynamics = "casadi-rnea",
          solver: str = "ipopt", constraints: Sequence[str | type[Constraint]] = DEFAULT_CONSTRAINTS,
          transcription_options: dict | None = None, solver_options: dict | None = None,
          dynamics_options: dict | None = None, ocp: OCP | None = None, near: np.ndarray | None = None) -> Shaped:
    """`build`'s first step: the Discretization of the shape (the cached build's when there is one), its solver not
    prepared."""
    options = solver_options or {}
    transcription_options = _staged_for(solver, options, transcription, transcription_options or {})
    method = construct(TRANSCRIPTIONS.get(transcription), transcription, {"knots": knots, **transcription_options})
    backend = make_dynamics(dynamics, problem.robot, **(dynamics_options or {}))
    plugins = make_constraints(problem, constraints) if near is None else screened(problem, constraints, near)
    nlp_solver = construct(SOLVERS.get(solver), solver, options)  # a wrong name or option fails before a build
    key = (method.shape_key(backend, plugins, ocp), solver, frozen(options))
    if key in _BUILDS:
        return Shaped(_BUILDS[key].discretization, key, nlp_solver, _BUILDS[key], 0.0, 0)
    if not plugins and key in _LAYOUTS:
        return Shaped(_LAYOUTS[key], key, nlp_solver, None, 0.0, _resident())
    began, resident = time.perf_counter(), _resident()
    discretization = method.build(problem, backend, plugins, ocp)
    return Shaped(discretization, key, nlp_solver, None, time.perf_counter() - began, resident, near is not None)


def layout(problem: Problem, transcription: str = "chebyshev", knots: int = 12,
           dynamics: str | Dynamics = "casadi-rnea", solver: str = "ipopt", transcription_options: dict | None = None,
           solver_options: dict | None = None, dynamics_options: dict | None = None) -> tuple[Discretization, float]:
    """The Discretization of the shape without its constraints, kept for reuse (the most recently used, `_LAYOUTS`),
    and the seconds its graph took (0 when kept): its variables, grid and checks are the shape's whatever
    the constraints, so it encodes and decodes a guess as the shape's own would, and a plan can find its guess,
    and screen the collision rows by it, before it builds the rows (ocpkit.planner.simultaneous)."""
    shaped = shape(problem, transcription, knots, dynamics, solver, (), transcription_options, solver_options,
                   dynamics_options)
    _LAYOUTS.put(shaped.key, shaped.discretization)
    return shaped.discretization, shaped.graph_time


def prepare(shaped: Shaped, graph_time: float | None = None) -> Build:
    """`build`'s second step: the solver of `shaped` prepared, the build cached (or the cached build, set-up 0).
    `graph_time` (s): the graph's time to report, when more than this shape's graph was built on the way."""
    if shaped.cached is not None:
        _BUILDS.move_to_end(shaped.key)
        return Build(shaped.cached.discretization, shaped.cached.solver, 0.0)
    graph = shaped.graph_time if graph_time is None else graph_time
    began, compiling = time.perf_counter(), compile_seconds()
    prepared = shaped.solver.prepare(shaped.discretization.nlp)
    ended, compiled = time.perf_counter(), compile_seconds() - compiling
    _BUILDS[shaped.key] = Build(shaped.discretization, prepared, graph + ended - began,
                                {"graph": graph, "solver": ended - began - compiled, "compile": compiled},
                                max(_resident() - shaped.resident, SMALLEST_BUILD), shaped.screened)
    _evict(memory_budget())
    return _BUILDS[shaped.key]


def _evict(budget: int) -> None:
    """Drop the least recently used builds (the newest stays) while their estimates add up to more than `budget`
    or the process's resident memory exceeds it, handing the freed memory back to the operating system."""
    while len(_BUILDS) > 1 and (cached_bytes() > budget or _resident() > budget):
        _BUILDS.popitem(last=False)
        _release()


def memory_budget() -> int:
    """Bytes the cached builds may hold: $OCPKIT_BUILD_MEMORY_MB (MiB) if set, else MEMORY_BUDGET."""
    given = os.environ.get("OCPKIT_BUILD_MEMORY_MB")
    if given is None:
        return MEMORY_BUDGET
    try:
        return int(float(given) * 1024**2)
    except ValueError:
        raise OptionError(f"OCPKIT_BUILD_MEMORY_MB must be a number of MiB, got {given!r}") from None


def cached_bytes() -> int:
    """The estimated bytes the cached builds hold now."""
    return sum(b.nbytes for b in _BUILDS.values())


def _resident() -> int:
    """This process's resident memory, bytes."""
    return psutil.Process().memory_info().rss


def _staged_for(solver: str, solver_options: dict, transcription: str, transcription_options: dict) -> dict:
    """`transcription_options` with `staged=True` when `solver` needs the NLP's stage structure (fatrop) and the
    transcription can give it; an OptionError saying what to ask for when it cannot (a pseudospectral one, or
    staged=False given), unless the solver was told to run without (`single_stage`)."""
    if not getattr(SOLVERS.get(solver), "needs_stages", False) or solver_options.get("single_stage"):
        return transcription_options
    if "staged" in inspect.signature(TRANSCRIPTIONS.get(transcription)).parameters \
            and transcription_options.get("staged", True):
        return {**transcription_options, "staged": True}
    unstaged = f"{transcription} with staged=False" if "staged" in transcription_options else transcription
    raise OptionError(STAGES_NEEDED.format(solver=solver, what=unstaged))


def drop_screened() -> None:
    """Forget the builds whose collision rows were screened for one problem's motion (no other problem has their
    key) and hand the memory back to the operating system; the others (a safety net's timing NLP, a problem's
    without screening) stay for the next problem of their shape, within the memory budget."""
    for key in [key for key, made in _BUILDS.items() if made.screened]:
        del _BUILDS[key]
    _release()


def clear_builds(parts: bool = False) -> None:
    """Forget every cached build and hand the memory back to the operating system. The small parts kept for a
    robot's later builds (`layout`s, the dynamics rows' Functions, their derivatives and compiled code) stay,
    unless `parts`."""
    _BUILDS.clear()
    if parts:
        _LAYOUTS.clear()
        forget_defects()
        forget_made()
    _release()


def _release() -> None:
    """Free dropped builds now (CasADi graphs can sit in reference cycles) and return the allocator's free pages
    to the operating system (glibc's malloc_trim; elsewhere only the collection)."""
    gc.collect()
    if _LIBC is not None:
        _LIBC.malloc_trim(0)


def _glibc() -> ctypes.CDLL | None:
    try:
        libc = ctypes.CDLL("libc.so.6")
        return libc if hasattr(libc, "malloc_trim") else None
    except OSError:  # not glibc (macOS, Windows, musl)
        return None


_LIBC = _glibc()


def frozen(value: Any) -> Any:
    """`value` made hashable for a cache key: mappings as sorted (key, value) tuples, sequences as tuples."""
    if isinstance(value, dict):
        return tuple(sorted((key, frozen(item)) for key, item in value.items()))
    if isinstance(value, (list, tuple)):
        return tuple(frozen(item) for item in value)
    return value

