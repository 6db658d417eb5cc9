"""Melon et al.'s cost on the base's vertical velocity ż (and z̈), reference 0 (§III-A.1)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import casadi as ca

from roughwalk.trajopt.costs import Cost, CostTerm, register
from roughwalk.trajopt.costs.integral import melon_integral_function

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["BaseVerticalVelocity"]


@register("base_vertical_velocity")
class BaseVerticalVelocity(Cost):
    """ω ∫ (ż² + ω_d z̈²) dt over the base spline, in closed form."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """Sum over the base polynomials."""
        w = nlp.config.costs.base_vertical_velocity
        if w.weight == 0:
            return None
        term = melon_integral_function(1)
        s = nlp.base_lin
        up = ca.DM([0.0, 0.0, 1.0])
        total: Any = 0
        for k, d in enumerate(s.durations):
            total += term(
                s.node_pos[k],
                s.node_vel[k],
                s.node_pos[k + 1],
                s.node_vel[k + 1],
                d,
                up,
                0.0,
                w.derivative_weight,
            )
        return CostTerm(self.name, w.weight * total)
