"""Tasks run in spawned worker processes (no forked copies of solver threads), each worker on its own pipe, read
by the calling thread alone.

Why not concurrent.futures.ProcessPoolExecutor: its results come back through one queue read by a background
thread, and a worker terminated while writing a large result (a trajectory, sent in many pipe-sized pieces)
leaves that thread waiting for the rest forever, so the interpreter hangs at exit after Ctrl-C. Here the parent
holds no copy of a worker's end of its pipe, so a dead worker reads as end-of-file, and there is no thread to join.
"""

from __future__ import annotations

import multiprocessing
import signal
import traceback
from collections.abc import Callable, Iterator
from multiprocessing.connection import Connection, wait

from ocpkit.errors import WorkerDied

DIED = ("a worker process died before finishing its plan (killed by the system: out of memory?); the finished rows "
        "are kept: run the same command again to resume, with fewer --jobs if memory is short")


def in_processes(tasks: list[dict], workers: int, work: Callable[[dict], dict]) -> Iterator[dict]:
    """`work(task)` of every task, as they finish, from `workers` spawned processes. A worker that dies ends the
    run with WorkerDied; an exception inside `work` ends it with RuntimeError carrying the worker's traceback;
    leaving early (Ctrl-C, an error, closing the iterator) terminates the workers at once."""
    context = multiprocessing.get_context("spawn")
    processes: dict[Connection, multiprocessing.process.BaseProcess] = {}
    try:
        for _ in range(min(workers, len(tasks))):
            mine, theirs = context.Pipe()
            process = context.Process(target=_serve, args=(theirs, work), daemon=True)
            process.start()
            theirs.close()
            processes[mine] = process
        waiting, idle, busy = list(reversed(tasks)), list(processes), []
        while waiting or busy:
            while waiting and idle:
                connection = idle.pop()
                _send(connection, waiting.pop())
                busy.append(connection)
            for connection in wait(busy):
                busy.remove(connection)
                idle.append(connection)
                yield _received(connection)
    finally:
        for process in processes.values():
            process.terminate()
        for connection, process in processes.items():
            process.join(timeout=10)
            connection.close()


def _send(connection: Connection, task: dict) -> None:
    try:
        connection.send(task)
    except OSError:
        raise WorkerDied(DIED) from None


def _received(connection: Connection) -> dict:
    """The outcome a worker sent; WorkerDied if it died first, RuntimeError if its `work` raised."""
    try:
        failure, outcome = connection.recv()
    except (EOFError, OSError):
        raise WorkerDied(DIED) from None
    if failure:
        raise RuntimeError(f"a worker's plan raised an exception:\n{failure}")
    return outcome


def _serve(connection: Connection, work: Callable[[dict], dict]) -> None:
    """A worker's loop: run `work` on each task received and send back (None, outcome) or (traceback text,
    None), until the pipe closes. Ctrl-C is left to the main process, which stops the workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    while True:
        try:
            task = connection.recv()
        except EOFError:
            return
        try:
            reply = (None, work(task))
        except Exception:  # any failure goes back to the parent, which raises it
            reply = (traceback.format_exc(), None)
        connection.send(reply)
