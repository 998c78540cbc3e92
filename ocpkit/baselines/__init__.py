"""Baseline planners to compare against: importing this package registers them with `ocpkit.plan`.

`ompl-toppra`: the path–velocity decomposition (OMPL path, TOPP-RA timing); needs `ompl` and `toppra`,
imported on first use.
"""

from ocpkit.baselines import ompl_toppra  # noqa: F401  (registers "ompl-toppra")
