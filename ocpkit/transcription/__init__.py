"""Transcriptions (registry `TRANSCRIPTIONS`): `chebyshev` (the paper's pseudospectral method), `trapezoidal` and
`hermite-simpson` (local collocation on a uniform mesh, Kelly 2017)."""

from ocpkit.transcription import chebyshev, hermite_simpson, trapezoidal  # noqa: F401  (register the built-ins)
from ocpkit.transcription.base import NLP, TRANSCRIPTIONS, Transcription

__all__ = ["NLP", "TRANSCRIPTIONS", "Transcription"]
