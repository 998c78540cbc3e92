"""Helpers of the tests that look at pages as a person would: headless Chromium and a free port."""

from __future__ import annotations

import shutil
import socket

import pytest


def chromium() -> str:
    """The headless browser (Debian's `chromium`; .ci/run and `make test` install it); fails the test if missing."""
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None:
        pytest.fail("chromium is not installed: apt-get install chromium (make test does, as root)")
    return path


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]
