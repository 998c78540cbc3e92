"""The Transcription interface and the NLP it produces.

A transcription turns a Problem (through a Dynamics backend and the path constraints) into an NLP

    minimize f(w; p)  subject to  lbg ≤ g(w; p) ≤ ubg,  lbx ≤ w ≤ ubx,

built once per problem *shape*: start, goal, time bounds and μ enter through lbx/ubx and the
parameter vector p, so many queries of the same shape share one NLP (and one compiled solver).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ocpkit.problem import Problem
from ocpkit.registry import Registry
from ocpkit.trajectory import Trajectory


@dataclass(frozen=True)
class Refinement:
    """What a refinement round may change without a rebuild: where the adaptive check slots sit (fractions
    of t_f, newest first), how much the clearance margin grows (m), and the fraction of the velocity, torque
    and torque-rate limits the NLP may use."""

    check_fractions: np.ndarray = field(default_factory=lambda: np.zeros(0))
    extra_margin: float = 0.0
    limit_scale: float = 1.0


@dataclass
class NLP(ABC):
    """Symbolic NLP (x: decision column, p: parameter column, f: objective, g: constraints) and the
    rules that map a Problem of its shape onto numbers and a solution back onto a Trajectory."""

    x: ca.SX
    p: ca.SX
    f: ca.SX
    g: ca.SX
    lbg: np.ndarray
    ubg: np.ndarray
    shape_key: tuple
    exact_hessian: bool = True  # False: a dynamics backend (e.g. a callback) gives no second derivatives

    @abstractmethod
    def bounds(self, problem: Problem, refinement: Refinement = Refinement()) -> tuple[np.ndarray, np.ndarray]:
        """(lbx, ubx) for this problem: limits, boundary conditions, time bounds."""

    @abstractmethod
    def parameters(self, problem: Problem, refinement: Refinement = Refinement()) -> np.ndarray:
        """The parameter vector p for this problem, after `refinement` (ignored where not supported)."""

    @abstractmethod
    def initial_guess(self, problem: Problem) -> np.ndarray:
        """The default starting point w0."""

    @abstractmethod
    def decode(self, w: np.ndarray) -> Trajectory:
        """The trajectory that the decision vector w represents."""

    @abstractmethod
    def encode(self, trajectory: Trajectory) -> np.ndarray:
        """A decision vector w that samples `trajectory` (any planner's) on this NLP's grid: a warm start."""


class Transcription(ABC):
    """Builds an NLP from a problem; `shape_key` says which problems share a build."""

    name: str

    @abstractmethod
    def shape_key(self, problem: Problem, dynamics_name: str) -> tuple:
        """Hashable key: two problems with equal keys can share one NLP."""

    @abstractmethod
    def build(self, problem: Problem, dynamics_name: str) -> NLP:
        """The NLP for problems of this problem's shape."""


TRANSCRIPTIONS: Registry[type] = Registry("transcription", "ocpkit.transcriptions")
