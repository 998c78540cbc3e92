"""Re-check every `verified` plan of an `ocpkit bench run` or `ocpkit bench random --out` folder with
tests/outside_check.py.

Run from the repository root:  .venv/bin/python scripts/check_run.py results/mbm-first10
For each row of DIR/results.csv with status `verified`, runs the outside checker on its trajectory, its robot's
spec and URDF and its scenario (DIR/scenarios/SCENE/CASE.yaml; bench random's rows have no scene and no trajectory
column: DIR/scenarios/CASE.yaml and DIR/trajectories/CASE.json); prints each failure and a count, exits 1 if any
fails. Robots: a built-in name (ocpkit/robots/data/NAME/spec.yaml) or `{spec: FILE}` in the scenario; the URDF is
the one the spec names, else robot.urdf beside it (industrial6).
"""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parent.parent
CHECKER = REPO / "tests/outside_check.py"


def spec_of(scenario: Path) -> Path:
    """The spec.yaml of the scenario's robot (built-in name or `{spec: FILE}`, relative to the scenario)."""
    robot = yaml.safe_load(scenario.read_text())["robot"]
    if isinstance(robot, str):
        return REPO / "ocpkit/robots/data" / robot / "spec.yaml"
    return (scenario.parent / robot["spec"]).resolve()


def main(out: Path) -> int:
    rows = [r for r in csv.DictReader((out / "results.csv").open(newline="")) if r["status"] == "verified"]
    failed = 0
    for row in rows:
        scenario = out / "scenarios" / row.get("scene", "") / f"{row['case']}.yaml"
        trajectory = row.get("trajectory") or f"trajectories/{row['case']}.json"
        spec = spec_of(scenario)
        urdf = "-" if "urdf" in yaml.safe_load(spec.read_text()) else str(spec.parent / "robot.urdf")
        checked = subprocess.run([sys.executable, str(CHECKER), str(out / trajectory), str(spec), urdf, str(scenario)],
                                 capture_output=True, text=True)
        if checked.returncode != 0:
            failed += 1
            print(f"FAILED {scenario.relative_to(out)} {row.get('method', row['planner'])}:\n{checked.stdout}"
                  f"{checked.stderr}")
    print(f"{len(rows) - failed} of {len(rows)} verified plans pass tests/outside_check.py")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1])))
