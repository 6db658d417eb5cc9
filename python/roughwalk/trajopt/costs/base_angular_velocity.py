"""Melon et al.'s cost on the base's angular velocities (§III-A.1): the Euler rates, reference 0.

The Euler rates (roll, pitch and yaw rate) [rad/s] are the derivatives of the
angular spline, so the integral has a closed form; for the small roll and
pitch of a walking base they are close to the body's angular velocity.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import casadi as ca

from roughwalk.trajopt.costs import Cost, CostTerm, register
from roughwalk.trajopt.costs.integral import melon_integral_function

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["BaseAngularVelocity"]


@register("base_angular_velocity")
class BaseAngularVelocity(Cost):
    """ω Σ_axes ∫ (η̇ₐ² + ω_d η̈ₐ²) dt over the base spline, in closed form."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """Sum over the base polynomials and the three axes."""
        w = nlp.config.costs.base_angular_velocity
        if w.weight == 0:
            return None
        term = melon_integral_function(1)
        s = nlp.base_ang
        total: Any = 0
        for axis in range(3):
            e = ca.DM.zeros(3)
            e[axis] = 1.0
            for k, d in enumerate(s.durations):
                total += term(
                    s.node_pos[k],
                    s.node_vel[k],
                    s.node_pos[k + 1],
                    s.node_vel[k + 1],
                    d,
                    e,
                    0.0,
                    w.derivative_weight,
                )
        return CostTerm(self.name, w.weight * total)
