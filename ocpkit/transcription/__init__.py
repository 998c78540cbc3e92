"""Transcriptions (registry `TRANSCRIPTIONS`, entry-point group `ocpkit.transcriptions`): `chebyshev` (the paper's
pseudospectral method), `trapezoidal` and `hermite-simpson` (local collocation on a uniform mesh, Kelly 2017)."""

from ocpkit.transcription.base import NLP, TRANSCRIPTIONS, Transcription

__all__ = ["NLP", "TRANSCRIPTIONS", "Transcription"]
