"""The certification contract: how far each quantity `ocpkit.verify` checks may exceed its limit and still pass.

Hard limits (joint positions, the obstacles, the workspace) pass only within round-off: a robot meets them as a
collision. The ratings of a drive (velocity, torque, torque rate) pass within 1 % relative. Relative tolerances
are fractions of the limit (dynamics: of the torque range 2·τ_max); geometry is in metres, the boundary in rad,
rad/s and rad/s². What each check measures: ocpkit.verify.
"""

POSITION_TOLERANCE = 1e-4
"""rad (m for a prismatic joint): a position limit is a hard stop, so only numerical round-off may pass it."""
LIMIT_TOLERANCE = 0.01
"""Relative, for velocity, torque and torque rate: ratings a drive meets with some reserve, so 1 % of the limit
between the samples of a smooth motion is within what its controller absorbs."""
DYNAMICS_TOLERANCE = 0.01
GEOMETRY_TOLERANCE = 0.0
BOUNDARY_TOLERANCE = 1e-6
QD_CONSISTENCY_TOLERANCE = 0.01
QDD_CONSISTENCY_TOLERANCE = 0.05
