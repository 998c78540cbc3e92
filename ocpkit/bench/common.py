"""What every benchmark shares: measuring plans, loading a folder of scenarios, writing CSV (at once, or row by row
so that an interrupted benchmark can resume), naming the machine."""

from __future__ import annotations

import csv
import io
import os
import platform
import statistics
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from ocpkit.errors import ScenarioError
from ocpkit.formats.record import KEY_COLUMNS, RESULT_COLUMNS, row_key
from ocpkit.formats.scenario import load_scenario
from ocpkit.planner import plan
from ocpkit.problem import Problem
from ocpkit.result import Plan


@dataclass(frozen=True)
class Measured:
    """One method on one case: the last plan, median computation time and set-up time (s)."""

    plan: Plan
    solve_time: float
    setup_time: float


def measure(problem: Problem, repeats: int, **options) -> Measured:
    """Plan `problem` `repeats` times with `options` (as for `ocpkit.plan`)."""
    plans = [plan(problem, **options) for _ in range(max(repeats, 1))]
    return Measured(plans[-1], statistics.median(p.stats.solve_time for p in plans), plans[0].stats.setup_time)


def load_all(folder: Path) -> list[Problem]:
    """Every scenario (*.yaml) in `folder`, sorted by file name; ScenarioError if there is none."""
    files = sorted(folder.glob("*.yaml"))
    if not files:
        raise ScenarioError(f"no scenario files (*.yaml) in {folder}")
    return [load_scenario(f) for f in files]


def write_csv(path: Path, rows: list[dict], columns: tuple[str, ...] = RESULT_COLUMNS) -> None:
    """`rows` as CSV with `columns`, creating the folder."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)


class Results:
    """A results.csv that keeps every finished row: each row is appended as one complete, flushed and fsynced
    line when it is added. Rows already in the file (a complete row with this file's columns) are kept, and
    `row` does not plan their key again: a re-run with the same file resumes. A row's key is its `key_columns`."""

    def __init__(self, path: Path, columns: tuple[str, ...] = RESULT_COLUMNS,
                 key_columns: tuple[str, ...] = KEY_COLUMNS) -> None:
        self.path, self.columns, self.key_columns = Path(path), columns, key_columns
        self.rows = self._complete_rows()
        self.resumed = len(self.rows)
        self._done = {row_key(r, key_columns): r for r in self.rows}
        write_csv(self.path.with_name(self.path.name + ".tmp"), self.rows, columns)
        os.replace(self.path.with_name(self.path.name + ".tmp"), self.path)

    def _complete_rows(self) -> list[dict]:
        """The rows of the file with a value in every column (a line cut short by a crash is dropped)."""
        if not self.path.exists():
            return []
        with self.path.open(newline="") as handle:
            return [r for r in csv.DictReader(handle) if all(r.get(c) is not None for c in self.columns)]

    def row(self, key: tuple[str, ...], measure_row: Callable[[], dict]) -> dict:
        """The row with `key` (row_key), from the file if it is there, else `measure_row()` appended now."""
        if key not in self._done:
            self.add(measure_row())
        return self._done[key]

    def add(self, row: dict) -> None:
        """Append `row` to the file as one complete line, flushed to disk."""
        line = io.StringIO()
        csv.DictWriter(line, fieldnames=self.columns).writerow(row)
        with self.path.open("a", newline="") as handle:
            handle.write(line.getvalue())
            handle.flush()
            os.fsync(handle.fileno())
        self.rows.append(row)
        self._done[row_key(row, self.key_columns)] = row

    def __contains__(self, key: tuple[str, ...]) -> bool:
        """Whether a row with this key (row_key of key_columns) is in the file."""
        return key in self._done


@contextmanager
def reported_on_interrupt(results: Results) -> Iterator[None]:
    """On Ctrl-C inside, print what `results` kept and how to resume, then let the KeyboardInterrupt go on."""
    try:
        yield
    except KeyboardInterrupt:
        print(f"interrupted: {len(results.rows)} finished rows kept in {results.path.resolve()}; run the same "
              "command again to resume", flush=True)
        raise


def resumed_line(results: Results) -> str:
    """The line saying how many rows a resumed run keeps from an earlier one ('' if none)."""
    if not results.resumed:
        return ""
    return (f"resuming: {results.resumed} rows already in {results.path.resolve()} are kept and not run again "
            "(delete the file to start afresh)")


def cpu_name() -> str:
    """The CPU model name (for the machine line under a benchmark table)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine() -> str:
    """One line naming this machine, for under a benchmark table."""
    return f"machine: {cpu_name()}, {os.cpu_count()} cores, Python {platform.python_version()}"
