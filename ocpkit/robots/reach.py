"""A bound on how far each collision sphere can move, from the kinematic tree alone (no configuration)."""

from __future__ import annotations

import functools

import numpy as np

from ocpkit.robots.robot import Robot


@functools.lru_cache(maxsize=32)
def sphere_reach(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    """(anchors (M, 3) m, reach (M,) m): sphere j's centre stays within reach[j] of anchors[j] at every q
    (computed once per robot: robots hash by identity; the arrays are shared, read-only).

    The anchor is the origin of the first joint on the sphere's chain (fixed in the world), the reach the sum of
    the link lengths out to the sphere, plus the stroke of any prismatic joint; a sphere on the universe (joint
    0) is its own anchor with reach 0."""
    model = robot.model
    anchors, reach = [], []
    for joint, offset in zip(robot.sphere_joint.tolist(), robot.sphere_offset):
        distance = np.linalg.norm(offset)
        while joint > 0 and model.parents[joint] > 0:
            distance += np.linalg.norm(model.jointPlacements[joint].translation)
            if model.joints[joint].shortname().startswith("JointModelP"):  # prismatic: add its stroke
                i = model.joints[joint].idx_q
                distance += max(abs(robot.q_lower[i]), abs(robot.q_upper[i]))
            joint = model.parents[joint]
        anchors.append(model.jointPlacements[joint].translation if joint > 0 else offset)
        reach.append(distance if joint > 0 else 0.0)
    anchors, reach = np.asarray(anchors).reshape(-1, 3), np.asarray(reach)
    anchors.flags.writeable = reach.flags.writeable = False
    return anchors, reach
