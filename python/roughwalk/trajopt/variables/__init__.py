"""The NLP's decision variables, one variable set per file (TOWR's ``variables/``).

* :class:`BaseLinear`: CoM position and velocity nodes, one polynomial per 0.1 s;
* :class:`BaseAngular`: Euler ZYX angle and rate nodes, same timing;
* :class:`FootMotion`: per foot, phase-based motion (footholds and swing nodes);
* :class:`FootForce`: per foot, phase-based contact force;
* :class:`PhaseDurations`: per foot, the phase durations (fixed or optimised).
"""

from roughwalk.trajopt.variables.base_angular import (
    BaseAngular,
    angular_acceleration,
    angular_velocity,
    base_to_world,
    body_angular_acceleration,
    body_angular_velocity,
    euler_rate_matrix,
    euler_to_rotation,
    world_to_base,
)
from roughwalk.trajopt.variables.base_linear import BaseLinear, base_poly_durations
from roughwalk.trajopt.variables.foot_force import FootForce
from roughwalk.trajopt.variables.foot_motion import FootMotion
from roughwalk.trajopt.variables.hermite import (
    hermite_coefficients,
    hermite_point,
    polynomial_value,
)
from roughwalk.trajopt.variables.phase_durations import PhaseDurations
from roughwalk.trajopt.variables.spline import NodeSpline, NumericSpline, sample_points
from roughwalk.trajopt.variables.variable_set import NodeIndex, NodeVariableSet, VariableSet

__all__ = [
    "VariableSet",
    "NodeVariableSet",
    "NodeIndex",
    "BaseLinear",
    "BaseAngular",
    "FootMotion",
    "FootForce",
    "PhaseDurations",
    "NodeSpline",
    "NumericSpline",
    "sample_points",
    "base_poly_durations",
    "hermite_coefficients",
    "hermite_point",
    "polynomial_value",
    "euler_to_rotation",
    "euler_rate_matrix",
    "angular_velocity",
    "angular_acceleration",
    "body_angular_velocity",
    "body_angular_acceleration",
    "base_to_world",
    "world_to_base",
]
