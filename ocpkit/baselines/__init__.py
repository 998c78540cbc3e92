"""Baseline planners to compare against, registered with `ocpkit.plan` through the `ocpkit.planners` entry points.

`ompl-toppra`: the path–velocity decomposition (OMPL path, TOPP-RA timing); needs `ompl` and `toppra`,
imported on first use. Its motion, the OMPL seed (ocpkit.planner.ompl_seed), also seeds the simultaneous planner
(`guess="ompl"`, group `ocpkit.guesses`).
"""
