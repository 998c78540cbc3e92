"""Transcriptions (registry `TRANSCRIPTIONS`): `chebyshev` (the paper's pseudospectral method)."""

from ocpkit.transcription import chebyshev  # noqa: F401  (registers the built-in transcriptions)
from ocpkit.transcription.base import NLP, TRANSCRIPTIONS, Transcription

__all__ = ["NLP", "TRANSCRIPTIONS", "Transcription"]
