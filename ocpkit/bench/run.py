"""`ocpkit bench run SUITE.yaml`: every (scenario, method, repeat) of a suite, serially, in local worker processes
or on a Dask cluster, into DIR/results.csv (one row each, appended as it finishes; a re-run skips finished rows),
DIR/trajectories/ and DIR/scenarios/ (each scenario's file, for `ocpkit report` and `ocpkit show`).

Ctrl-C keeps the finished rows (the command exits 130); the progress bar shows the rows done and the ETA.
"""

from __future__ import annotations

import csv
from collections.abc import Iterator
from pathlib import Path

import yaml
from tqdm import tqdm

from ocpkit.bench.common import Results, reported_on_interrupt, resumed_line
from ocpkit.bench.metrics import formatted, summarize
from ocpkit.bench.suite import load_suite
from ocpkit.bench.task import RUN_COLUMNS, RUN_KEY_COLUMNS, make_task, run_task, task_key
from ocpkit.bench.workers import in_processes
from ocpkit.errors import OptionError

CONNECT_TIMEOUT = "20s"
"""How long to wait for a Dask scheduler before giving up."""


def run_suite(suite_file: str | Path, out: str | Path, jobs: int = 1, scheduler: str | None = None,
              progress: bool = True, repeats: int | None = None) -> list[dict]:
    """Run the suite into `out` with `jobs` local processes (1: in this process) or on the Dask scheduler at
    address `scheduler` (e.g. tcp://host:8786), `repeats` times (default: the suite's); return every row of
    results.csv, earlier or new. OptionError if out/results.csv holds another suite's or another command's rows."""
    suite, out = load_suite(suite_file), Path(out)
    tasks = [make_task(suite.name, s, m, r) for s in suite.scenarios for m in suite.methods
             for r in range(repeats or suite.repeats)]
    _check_earlier(out / "results.csv", suite.name)
    results = Results(out / "results.csv", RUN_COLUMNS, RUN_KEY_COLUMNS)
    if results.resumed:
        print(resumed_line(results), flush=True)
    _write_scenarios(out, tasks)
    pending = [t for t in tasks if task_key(t) not in results]
    where = f"Dask scheduler {scheduler}" if scheduler else f"{jobs} process{'es' if jobs > 1 else ''}"
    print(f"suite {suite.name}: {len(suite.scenarios)} scenarios x {len(suite.methods)} methods x "
          f"{repeats or suite.repeats} repeats = {len(tasks)} rows, {len(pending)} to run on {where}", flush=True)
    if suite.left_out:
        print(f"left out, invalid for the robot model: {'; '.join(suite.left_out)}", flush=True)
    with reported_on_interrupt(results), tqdm(total=len(tasks), initial=len(tasks) - len(pending), unit="plan",
                                              disable=not progress, dynamic_ncols=True) as bar:
        for outcome in _outcomes(pending, jobs, scheduler):
            path = out / outcome["row"]["trajectory"]
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(outcome["trajectory"])
            results.add(outcome["row"])
            bar.update()
    for line in summary_lines(results.rows):
        print(line)
    verified = sum(r["status"] == "verified" for r in results.rows)
    print(f"{verified} of {len(results.rows)} plans verified; results: {results.path.resolve()}; "
          f"report: ocpkit report {out}")
    return results.rows


def summary_lines(rows: list[dict]) -> list[str]:
    """One line per method: runs, success, the verified plans' median and 98th-percentile computation time and
    median t_f, and every plan's median wait (computation and set-up, failures included)."""
    return [f"{s['method']}: {s['runs']} runs, {formatted(s['success_%'])} % verified, computation median "
            f"{formatted(s['time_median_s'])} s, p98 {formatted(s['time_p98_s'])} s, "
            f"t_f median {formatted(s['tf_s'])} s; with set-up, every plan: median {formatted(s['all_median_s'])} s, "
            f"p90 {formatted(s['all_p90_s'])} s" for s in summarize(rows, ("method",))]


def _check_earlier(path: Path, suite: str) -> None:
    """OptionError unless `path` is absent or a `bench run` results file of `suite` (resuming never drops rows)."""
    if not path.exists():
        return
    with path.open(newline="") as handle:
        reader = csv.DictReader(handle)
        if tuple(reader.fieldnames or ()) != RUN_COLUMNS:
            raise OptionError(f"{path} is not a results file of `ocpkit bench run` (other columns); choose another "
                              "--out")
        others = {row["suite"] for row in reader} - {suite}
    if others:
        raise OptionError(f"{path} holds rows of suite {sorted(others)[0]!r}, not {suite!r}; choose another --out")


def _write_scenarios(out: Path, tasks: list[dict]) -> None:
    """Each task's scenario file as scenarios/SCENE/CASE.yaml (radians or degrees as given)."""
    for task in tasks:
        path = out / "scenarios" / task["scene"] / f"{task['case']}.yaml"
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(yaml.safe_dump(task["scenario"], sort_keys=False))


def _outcomes(tasks: list[dict], jobs: int, scheduler: str | None) -> Iterator[dict]:
    """run_task's outcome of every task, in the order they finish."""
    if scheduler:
        yield from _on_dask(tasks, scheduler)
    elif jobs > 1 and len(tasks) > 1:
        yield from in_processes(tasks, jobs, run_task)
    else:
        yield from map(run_task, tasks)


def _on_dask(tasks: list[dict], scheduler: str) -> Iterator[dict]:
    from dask.distributed import Client, as_completed

    try:
        client = Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as exc:
        raise OptionError(f"--scheduler {scheduler}: cannot connect to a Dask scheduler there ({exc})") from None
    with client:
        futures = [client.submit(run_task, task, pure=False) for task in tasks]
        try:
            for future in as_completed(futures):
                yield future.result()
        finally:
            client.cancel(futures)
