"""Exceptions for user mistakes: each message names the offending item so it can be fixed."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager


class OcpkitError(Exception):
    """Base class of every error ocpkit raises for bad input; the CLI prints it without a traceback."""


class RobotError(OcpkitError):
    """A robot name, URDF or spec file is unknown or inconsistent."""


class ScenarioError(OcpkitError):
    """A scenario file is malformed or describes an impossible problem."""


class RegistryError(OcpkitError):
    """A component name (transcription, dynamics, solver, planner) is not registered."""


class WorkerDied(OcpkitError):
    """A benchmark worker process ended without a result (killed by the system); the run stops, its rows kept."""


class NoGuess(Exception):
    """An initial-guess rule asked not to fall back (`fallback=False`) has no start of its own to offer (OMPL found
    no path): not a user mistake, a finding the planner reports as `no_path`."""


class OptionError(OcpkitError):
    """A planner, transcription or solver option is out of range."""


@contextmanager
def within(where: object) -> Iterator[None]:
    """Prefix an OcpkitError raised inside with `where: ` (e.g. the file it is about), keeping its type."""
    try:
        yield
    except OcpkitError as exc:
        raise type(exc)(f"{where}: {exc}") from exc


class MoveItError(OcpkitError):
    """A MoveIt planning-scene or motion-plan-request file cannot be converted to a scenario."""
