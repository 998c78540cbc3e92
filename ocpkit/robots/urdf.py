"""URDF text to a pinocchio model, with the URDF parser's console complaints turned into a one-line RobotError."""

from __future__ import annotations

import importlib.metadata
import os
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

import pinocchio as pin

from ocpkit.errors import RobotError
from ocpkit.formats.schema import one_line

EXAMPLE_ROBOT_DATA = "example-robot-data:"
"""Prefix of a spec's `urdf:` naming a file inside the example-robot-data package's share/example-robot-data/."""


def example_robot_data_dir() -> Path:
    """The share/example-robot-data folder of the installed example-robot-data package."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        raise RobotError("the example-robot-data package is not installed (pip install example-robot-data)") from None
    return Path(dist.locate_file("cmeel.prefix/share/example-robot-data"))


def resolve_urdf(reference: str, spec_dir: Path) -> Path:
    """The file a spec's `urdf:` names: `example-robot-data:<path>` or a path relative to the spec's folder."""
    if reference.startswith(EXAMPLE_ROBOT_DATA):
        return example_robot_data_dir() / reference.removeprefix(EXAMPLE_ROBOT_DATA)
    return spec_dir / reference


def model_from_urdf(text: bytes, path: Path) -> pin.Model:
    """The full pinocchio model of URDF bytes; RobotError naming `path` and the parser's reasons if invalid."""
    try:
        xml = text.decode("utf-8")
    except UnicodeDecodeError:
        raise RobotError(f"{path}: not a valid URDF: not UTF-8 text") from None
    with tempfile.TemporaryFile() as sink:
        try:
            with _stderr_into(sink):
                model = pin.buildModelFromXML(xml)
        except (ValueError, RuntimeError) as exc:
            reasons = _parser_errors(_read_back(sink)) or str(exc)
            raise RobotError(f"{path}: not a valid URDF: {one_line(reasons)}") from None
        sys.stderr.write(_read_back(sink))  # a valid file's warnings still reach the user
    return model


@contextmanager
def _stderr_into(sink: BinaryIO) -> Iterator[None]:
    """Send file descriptor 2 (where the C++ URDF parser prints) into `sink` for the duration."""
    sys.stderr.flush()
    saved = os.dup(2)
    os.dup2(sink.fileno(), 2)
    try:
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _read_back(sink: BinaryIO) -> str:
    sink.seek(0)
    return sink.read().decode(errors="replace")


def _parser_errors(console: str) -> str:
    """The urdfdom 'Error: ...' lines of `console`, without their source locations, joined by '; '."""
    lines = (line.strip() for line in console.splitlines())
    return "; ".join(line.removeprefix("Error:").strip() for line in lines if line.startswith("Error:"))
