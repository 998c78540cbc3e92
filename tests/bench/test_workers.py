"""The worker processes of `ocpkit bench run --jobs N`: every outcome once, a killed worker or a failing task ends
the run with a clear error, and leaving early (Ctrl-C) stops at once even while workers are sending large
results."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest
from helpers import REPO

from ocpkit.bench.workers import in_processes
from ocpkit.errors import WorkerDied


def _echo(task: dict) -> dict:
    return {"id": task["id"], "pid": os.getpid()}


def _killed(task: dict) -> dict:
    """A plan whose worker process the system kills (as the out-of-memory killer does)."""
    if task["die"]:
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(0.2)
    return {"row": task}


def _failing(task: dict) -> dict:
    raise ValueError(f"task {task['id']} cannot be planned")


def test_every_task_comes_back_once_from_both_workers():
    outcomes = list(in_processes([{"id": i} for i in range(12)], 2, work=_echo))
    assert sorted(o["id"] for o in outcomes) == list(range(12))
    assert len({o["pid"] for o in outcomes} - {os.getpid()}) == 2


def test_a_worker_killed_by_the_system_ends_the_run_with_an_error_not_a_hang():
    outcomes = in_processes([{"die": False}, {"die": True}, {"die": False}], 2, work=_killed)
    started = time.perf_counter()
    with pytest.raises(WorkerDied, match="worker process died"):
        list(outcomes)
    assert time.perf_counter() - started < 60


def test_an_exception_in_a_task_is_raised_with_the_workers_traceback():
    with pytest.raises(RuntimeError, match=r"(?s)ValueError: task 0 cannot be planned"):
        list(in_processes([{"id": 0}], 2, work=_failing))


INTERRUPTED = """
import sys
sys.path.insert(0, {tests!r})
from bench.test_workers import _large
from ocpkit.bench.workers import in_processes
for outcome in in_processes([{{"id": i}} for i in range(6)], 2, work=_large):
    raise KeyboardInterrupt
"""


def _large(task: dict) -> dict:
    """A result larger than a pipe's buffer (trajectories are about 1 MB): the worker blocks while sending it."""
    return {"id": task["id"], "trajectory": "x" * 8_000_000}


def test_ctrl_c_while_a_worker_is_sending_a_large_result_exits_at_once():
    script = INTERRUPTED.format(tests=str(REPO / "tests"))
    started = time.perf_counter()
    process = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert process.stderr.strip().splitlines()[-1] == "KeyboardInterrupt"  # not turned into another error
    assert time.perf_counter() - started < 30
