"""Chebyshev pseudospectral transcription (`chebyshev`): the paper's section III with one segment (the default).

    D X = h F at the N + 1 Chebyshev–Lobatto points s_i = cos(iπ/N),  h = t_f/(2K)

Only the node family lives here (`polynomials.CHEBYSHEV`: points, barycentric weights, Clenshaw–Curtis weights);
the NLP, the segments, the checks between knots and the interpolant are pseudospectral.py's, shared with lgl.py
and lgr.py.

Equations: docs/transcription.md, section "Pseudospectral" (family "Chebyshev–Lobatto").
"""

from __future__ import annotations

from ocpkit.transcription.polynomials import CHEBYSHEV
from ocpkit.transcription.pseudospectral import Pseudospectral


class Chebyshev(Pseudospectral):
    """Chebyshev pseudospectral transcription on Chebyshev–Lobatto points, in one or more equal segments.

    N = `knots` intervals (N + 1 Chebyshev–Lobatto points) on each of `segments` equal segments."""

    name = "chebyshev"
    family = CHEBYSHEV


