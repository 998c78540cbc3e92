"""URDF text to a pinocchio model, with the URDF parser's console complaints turned into a one-line RobotError."""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import BinaryIO

import pinocchio as pin

from ocpkit.errors import RobotError
from ocpkit.schema import one_line


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
