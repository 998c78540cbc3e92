"""A third-party transcription for tests/test_registry.py, found only through its entry point."""

from ocpkit.transcription.chebyshev import Chebyshev


class Toy(Chebyshev):
    """Toy transcription from a plugin: the Chebyshev transcription under its own name."""

    name = "toy"
