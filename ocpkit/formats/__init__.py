"""The file formats: scenario and robot-spec schema, scenario files, MoveIt scenes, MotionBenchMaker data,
trajectory JSON and the plan's record."""
