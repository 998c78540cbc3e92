"""Robot models and the built-in robot data files."""

from ocpkit.robots.robot import Robot, builtin_robots, load_robot, robot_from_files

__all__ = ["Robot", "builtin_robots", "load_robot", "robot_from_files"]
