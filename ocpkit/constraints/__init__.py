"""Path constraints: actuator limits and sphere collision, evaluated point by point."""

from ocpkit.constraints.base import Constraint, PointValues
from ocpkit.constraints.collision import SphereCollision
from ocpkit.constraints.limits import StateLimits, TorqueLimit, TorqueRateLimit

__all__ = ["Constraint", "PointValues", "SphereCollision", "StateLimits", "TorqueLimit", "TorqueRateLimit"]
