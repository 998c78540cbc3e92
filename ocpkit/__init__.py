"""ocpkit: robot motion planning as an optimal control problem (path and timing together).

Public API: load_scenario, load_robot, Problem, plan, build, Trajectory, verify; any optimal control problem:
ocpkit.ocp (Ocp, solve, certify) and its classic test problems, ocpkit.problems.
"""

import os

# One BLAS thread: the NLPs are small and threading only costs kernel time on few cores. Must precede numpy.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from ocpkit.formats.scenario import load_scenario  # noqa: E402
from ocpkit.formats.trajectory import Trajectory, write_json  # noqa: E402
from ocpkit.geometry.scene import Scene, Workspace  # noqa: E402
from ocpkit.planner import plan  # noqa: E402
from ocpkit.planner.build_cache import Build, build  # noqa: E402
from ocpkit.problem import Problem, TimeBounds  # noqa: E402
from ocpkit.result import Plan  # noqa: E402
from ocpkit.robots import Robot, load_robot  # noqa: E402
from ocpkit.verify import Verification, verify  # noqa: E402

__all__ = ["Build", "Plan", "Problem", "Robot", "Scene", "TimeBounds", "Trajectory", "Verification", "Workspace",
           "build", "load_robot", "load_scenario", "plan", "verify", "write_json"]
