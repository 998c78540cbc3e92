"""Ctrl-C: recorded even when a solver swallows it; `ocpkit plan` ends with exit 130, one line and no file."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers import REPO

from ocpkit import interrupt

OCPKIT = [sys.executable, "-m", "ocpkit.cli.main"]


def cpu_seconds(pid: int) -> float:
    """User + system CPU time (s) of process `pid` so far."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def interrupt_when_busy(process: subprocess.Popen, cpu: float) -> None:
    """Send SIGINT to `process` once it has used `cpu` seconds of CPU (imports and set-up done: it is planning)."""
    while process.poll() is None and cpu_seconds(process.pid) < cpu:
        time.sleep(0.1)
    time.sleep(1.0)
    process.send_signal(signal.SIGINT)


def test_check_raises_for_a_sigint_that_was_caught_inside():
    with pytest.raises(KeyboardInterrupt), interrupt.watching():
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)  # the handler runs here
        except KeyboardInterrupt:
            pass  # what CasADi does: the solve ends as failed
        interrupt.check()


def test_check_is_quiet_without_an_interrupt_and_the_handler_is_restored():
    before = signal.getsignal(signal.SIGINT)
    with interrupt.watching():
        interrupt.check()
    assert signal.getsignal(signal.SIGINT) is before


def test_a_new_watch_forgets_an_old_interrupt():
    with pytest.raises(KeyboardInterrupt), interrupt.watching():
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(1.0)
    with interrupt.watching():
        interrupt.check()


@pytest.mark.slow
def test_ctrl_c_during_plan_exits_130_with_one_line_and_no_file(tmp_path):
    out = tmp_path / "out.json"
    process = subprocess.Popen([*OCPKIT, "plan", str(REPO / "scenarios/paper/case1.yaml"), "--solver", "sqpmethod",
                                "--single-shot", "-o", str(out)],  # a solve of about 10 s: the signal lands in it
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    interrupt_when_busy(process, cpu=5.0)
    time.sleep(0.2)
    process.send_signal(signal.SIGINT)  # a second Ctrl-C while it finishes: still no traceback
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stdout + stderr
    assert stderr.splitlines() == ["interrupted"], stderr
    assert not out.exists()
    assert "status" not in stdout
