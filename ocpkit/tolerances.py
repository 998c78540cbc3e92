"""The certification contract: how far each quantity `ocpkit.verify` checks may exceed its limit and still pass.

Relative tolerances are fractions of the limit (position: of the joint's range; dynamics: of the torque range
2·τ_max); geometry is in metres, the boundary in rad, rad/s and rad/s². What each check measures: ocpkit.verify.
"""

LIMIT_TOLERANCE = 0.01
DYNAMICS_TOLERANCE = 0.01
GEOMETRY_TOLERANCE = 0.0
BOUNDARY_TOLERANCE = 1e-6
QD_CONSISTENCY_TOLERANCE = 0.01
QDD_CONSISTENCY_TOLERANCE = 0.05
