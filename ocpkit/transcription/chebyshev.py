"""Chebyshev pseudospectral transcription, exactly the paper's section III (one segment, the default).

Knots T_i = (t_f/2)(cos(iπ/N) + 1), i = 0..N (knot 0 is t = t_f, knot N is t = 0). Per knot the
decision variables are x_i = [q_i, qd_i, qdd_i, u_i]. The control u is the rigid-body part of the joint
torque, scaled: tau = tau_max ∘ u + friction(qd). At the knots this is exactly the paper's control; between
knots the torque interpolant is the polynomial u plus the friction law on the velocity polynomial, which
follows the steep Coulomb term (tanh) where a joint reverses; a polynomial through the knot torques cannot
(we measured 2 % of the torque range of dynamic inconsistency from that alone). With the differentiation
matrix D (on s ∈ [-1, 1]) and Clenshaw–Curtis weights w:

    dynamics     D X = (t_f/2) F(X, U):  D Q = (t_f/2) Qd,  D Qd = (t_f/2) Qdd,
                 residual(q_i, qd_i, qdd_i, tau_max u_i) = 0
    torque rate  tau'(t) = (2/t_f) (tau_max D U + friction'(qd) (t_f/2) Qdd), bounded as |dtau/ds| ≤ (t_f/2) taud_max
    jerk         q'''(T_i) = (2/t_f) (D Qdd)_i
    cost         t_f + μ Σ_i (t_f/2) w_i q'''_iᵀ Q q'''_i  =  t_f + μ (2/t_f) Σ_i w_i (D Qdd)_iᵀ Q (D Qdd)_i

Because D is exact for degree-N polynomials, D Q = (t_f/2) Qd at all N+1 knots makes the velocity
polynomial the exact derivative of the position polynomial (likewise for acceleration).

`segments=K` splits [0, t_f] into K equal segments of N intervals each, C² at the joints (the h–p option):
t_f/2 becomes the segment's t_f/(2K), and the cost sums over segments. The NLP, the check times between knots
and the interpolant are pseudospectral.py's, shared with lgl.py; the path constraints, the parameter vector,
the bounds and the straight-line guess are shared by all transcriptions in assembly.py.
"""

from __future__ import annotations

from ocpkit.transcription.polynomials import CHEBYSHEV
from ocpkit.transcription.pseudospectral import Pseudospectral


class Chebyshev(Pseudospectral):
    """Chebyshev pseudospectral transcription with N = `knots` intervals (N + 1 Chebyshev–Lobatto points) on
    each of `segments` equal segments."""

    name = "chebyshev"
    family = CHEBYSHEV


