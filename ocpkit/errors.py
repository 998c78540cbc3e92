"""Exceptions for user mistakes: each message names the offending item so it can be fixed."""


class OcpkitError(Exception):
    """Base class of every error ocpkit raises for bad input; the CLI prints it without a traceback."""


class RobotError(OcpkitError):
    """A robot name, URDF or spec file is unknown or inconsistent."""


class ScenarioError(OcpkitError):
    """A scenario file is malformed or describes an impossible problem."""


class RegistryError(OcpkitError):
    """A component name (transcription, dynamics, solver, planner) is not registered."""


class OptionError(OcpkitError):
    """A planner, transcription or solver option is out of range."""
