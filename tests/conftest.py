"""How the suite is spread over its pytest-xdist workers (pyproject.toml: `-n logical`, one worker per CPU).

Each test goes to the next free worker, in an order set here once, the same on every worker: first the tests that
need the network (they mostly wait), then the `slow` end-to-end solves, then the rest, each part in collection
order, so that no long test starts last and keeps one worker busy while the other idles.

The tests of a module that share a module-scoped fixture (a suite run, a report, a plan) go to one worker together,
so that the fixture is made once. pytest-xdist's own `--dist loadgroup` cannot do this under pytest 9 (it renames
node ids, which pytest 9 no longer allows), so the workers write each such test's module to a file after
collecting, and the scheduler below (xdist's LoadScopeScheduling, one test or one such module per unit, in the
order above) reads it. Without that file every test is its own unit: the same results, a fixture made twice.
`--dist` with any other mode than the default (load) uses xdist's own scheduler instead.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

import pytest

GROUPS = "OCPKIT_TEST_GROUPS"  # environment: the file the workers write the groups to, made by the controller


def pytest_configure(config: pytest.Config) -> None:
    if not hasattr(config, "workerinput") and GROUPS not in os.environ:  # the controller (or a run without xdist)
        folder = tempfile.mkdtemp(prefix="ocpkit-test-groups-")
        os.environ[GROUPS] = str(Path(folder) / "groups.json")  # inherited by the workers, started after this
        config.add_cleanup(lambda: (shutil.rmtree(folder, ignore_errors=True), os.environ.pop(GROUPS, None)))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    items.sort(key=lambda item: (item.get_closest_marker("network") is None, item.get_closest_marker("slow") is None))
    if hasattr(config, "workerinput") and os.environ.get(GROUPS):
        groups = {item.nodeid: item.nodeid.split("::")[0] for item in items if _uses_a_module_fixture(item)}
        path = Path(os.environ[GROUPS])
        partial = path.with_name(f"{path.name}.{config.workerinput['workerid']}")
        partial.write_text(json.dumps(groups))
        os.replace(partial, path)  # every worker writes the same; a reader sees one whole file


def _uses_a_module_fixture(item: pytest.Item) -> bool:
    info = getattr(item, "_fixtureinfo", None)
    return info is not None and any(definition.scope == "module" for definitions in info.name2fixturedefs.values()
                                    for definition in definitions)


def pytest_xdist_make_scheduler(config: pytest.Config, log):
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class ModuleFixtureScheduling(LoadScopeScheduling):
        """One unit per test, or per module for the tests sharing a module-scoped fixture; units in the
        collection's order (module docstring)."""

        groups: dict[str, str] | None = None

        def schedule(self) -> None:
            self.config.option.loadscopereorder = False  # keep the order above, not the largest units first
            super().schedule()

        def _split_scope(self, nodeid: str) -> str:
            if self.groups is None:  # read once, after every worker has collected
                try:
                    self.groups = json.loads(Path(os.environ[GROUPS]).read_text())
                except (KeyError, OSError, ValueError):
                    self.groups = {}
            return self.groups.get(nodeid, nodeid)

    return ModuleFixtureScheduling(config, log)
