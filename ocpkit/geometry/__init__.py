"""Geometry in numbers: quaternions, the scene's obstacles, exact distances and the robot's sphere clearances."""
