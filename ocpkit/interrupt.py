"""Ctrl-C that a solver cannot swallow.

CasADi polls Python for signals during a solve; a KeyboardInterrupt raised there ends the solve, which CasADi
then reports as an ordinary failed solve. Inside `watching()`, SIGINT still raises KeyboardInterrupt (so the
solve stops promptly) and is also recorded, so that `check()` raises it again once the solver has returned.
After a Ctrl-C, CasADi's own warning that the interrupt stopped its solve is left out of sys.stderr.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

SOLVER_NOTICE = "KeyboardInterruptException"
"""What CasADi's warning says when a Ctrl-C stopped its solve."""

_state = {"depth": 0, "interrupted": False}


class _QuietStderr:
    """sys.stderr passed on line by line, without the lines that hold SOLVER_NOTICE."""

    def __init__(self, stream) -> None:
        self.stream, self.pending = stream, ""

    def write(self, text: str) -> int:
        *lines, self.pending = (self.pending + text).split("\n")
        for line in lines:
            if SOLVER_NOTICE not in line:
                self.stream.write(line + "\n")
        return len(text)

    def __getattr__(self, name: str):
        return getattr(self.stream, name)


def _record(signum: int, frame: FrameType | None) -> None:
    """The SIGINT handler inside `watching()`: remember the interrupt, quieten the solver's notice of it, then
    interrupt as Python does."""
    _state["interrupted"] = True
    if not isinstance(sys.stderr, _QuietStderr):
        sys.stderr = _QuietStderr(sys.stderr)
    raise KeyboardInterrupt


@contextmanager
def watching() -> Iterator[None]:
    """Record SIGINT for `check()` while inside (nestable; the outermost starts with no interrupt recorded).
    Outside the main thread, where Python cannot install handlers, it does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous, stderr = signal.signal(signal.SIGINT, _record), sys.stderr
    if _state["depth"] == 0:
        _state["interrupted"] = False
    _state["depth"] += 1
    try:
        yield
    finally:
        _state["depth"] -= 1
        signal.signal(signal.SIGINT, previous)
        if sys.stderr is not stderr and isinstance(sys.stderr, _QuietStderr):
            sys.stderr.stream.write(sys.stderr.pending)
            sys.stderr = stderr


def check() -> None:
    """Raise KeyboardInterrupt if SIGINT arrived inside `watching()`, even if something caught it since."""
    if _state["interrupted"]:
        raise KeyboardInterrupt


def ignore() -> None:
    """Ignore SIGINT from now on (while an interrupted command finishes, so that a second Ctrl-C is harmless)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
