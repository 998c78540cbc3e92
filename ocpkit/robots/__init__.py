"""Robot models and the built-in robot data files; numeric friction, rigid-body torque and sphere reach."""

from ocpkit.robots.friction import friction_slope, friction_torque
from ocpkit.robots.reach import sphere_reach
from ocpkit.robots.rigid_body import rigid_torque
from ocpkit.robots.robot import Robot, builtin_robots, load_robot, robot_from_files, robot_from_spec

__all__ = ["Robot", "builtin_robots", "friction_slope", "friction_torque", "load_robot", "rigid_torque",
           "robot_from_files", "robot_from_spec", "sphere_reach"]
