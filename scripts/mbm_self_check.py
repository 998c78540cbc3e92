"""Check MotionBenchMaker start and goal joint vectors against a robot's limits and self-collision spheres.

Usage: python scripts/mbm_self_check.py ROBOT PROBLEMS_DIR [--scenario SCENE/requestNNNN.yaml --out FILE.yaml]

ROBOT is a built-in name or a spec.yaml naming its URDF; PROBLEMS_DIR holds the scene folders of an unpacked
problems.tar.bz2 of the vamp-planner source distribution (each with requestNNNN.yaml MoveIt MotionPlanRequests).
Prints per scene how many of the start and goal vectors are inside the position limits and free of self-collision
(obstacles are not checked). With --scenario, writes that problem as an ocpkit scenario without obstacles.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import yaml

from ocpkit.geometry.clearances import collision_report
from ocpkit.robots import Robot, builtin_robots, load_robot
from ocpkit.robots.robot import robot_from_spec
from ocpkit.geometry.scene import Scene


def start_goal(request: dict, joints: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The start and goal (n,) of a MotionPlanRequest mapping for the named joints (rad or m)."""
    state = request["start_state"]["joint_state"]
    start = dict(zip(state["name"], state["position"]))
    goal = {c["joint_name"]: c["position"] for c in request["goal_constraints"][0]["joint_constraints"]}
    return np.array([start[j] for j in joints]), np.array([goal[j] for j in joints])


def problems(folder: Path) -> list[Path]:
    return sorted(folder.glob("request*.yaml"))


def problems_of(problems_dir: Path) -> dict[str, list[Path]]:
    return {scene.name: problems(scene) for scene in sorted(problems_dir.iterdir()) if scene.is_dir()}


def status(robot: Robot, q: np.ndarray) -> str:
    """'ok', 'limits' or 'self' for one joint vector."""
    if np.any(q < robot.q_lower - 1e-9) or np.any(q > robot.q_upper + 1e-9):
        return "limits"
    return "self" if collision_report(robot, Scene(), q) else "ok"


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("robot")
    parser.add_argument("problems")
    parser.add_argument("--scenario", help="SCENE/requestNNNN.yaml inside PROBLEMS_DIR to write as a scenario")
    parser.add_argument("--out", help="scenario file to write")
    args = parser.parse_args(argv)
    robot = load_robot(args.robot) if args.robot in builtin_robots() else robot_from_spec(Path(args.robot))
    if args.scenario:
        start, goal = start_goal(yaml.safe_load((Path(args.problems) / args.scenario).read_text()), robot.joint_names)
        spec = args.robot if args.robot in builtin_robots() else {"spec": str(Path(args.robot).resolve())}
        Path(args.out).write_text(yaml.safe_dump({"name": args.scenario.replace("/", "-").removesuffix(".yaml"),
                                                  "robot": spec, "unit": "rad", "start": start.tolist(),
                                                  "goal": goal.tolist()}, sort_keys=False))
        return 0
    totals = {"ok": 0, "limits": 0, "self": 0}
    print(f"{'scene':28s} {'vectors':>7s} {'ok':>4s} {'limits':>6s} {'self':>4s}")
    for scene, files in problems_of(Path(args.problems)).items():
        counts = {"ok": 0, "limits": 0, "self": 0}
        for file in files:
            for q in start_goal(yaml.safe_load(file.read_text()), robot.joint_names):
                counts[status(robot, q)] += 1
        print(f"{scene:28s} {sum(counts.values()):7d} {counts['ok']:4d} {counts['limits']:6d} {counts['self']:4d}")
        totals = {k: totals[k] + counts[k] for k in totals}
    print(f"{'all':28s} {sum(totals.values()):7d} {totals['ok']:4d} {totals['limits']:6d} {totals['self']:4d}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
