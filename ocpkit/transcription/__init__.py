"""Transcriptions (registry `TRANSCRIPTIONS`, entry-point group `ocpkit.transcriptions`): pseudospectral
`chebyshev` (the paper's), `lgl` and `lgr`, and local collocation `trapezoidal` and `hermite-simpson` on a
uniform mesh; their equations are in docs/transcription.md."""

from ocpkit.transcription.base import TRANSCRIPTIONS, Discretization, Transcription

__all__ = ["TRANSCRIPTIONS", "Discretization", "Transcription"]
