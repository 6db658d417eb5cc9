"""Melon et al.'s cost on contact force magnitudes and their derivatives (§III-A.1).

ω Σ_feet Σ_axes ∫ ((fₐ/mg)² + ω_d (ḟₐ/mg)²) dt over the stance polynomials
(forces are zero in swing), in closed form.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import casadi as ca

from roughwalk.trajopt.costs import Cost, CostTerm, register
from roughwalk.trajopt.costs.integral import melon_integral_function

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["ForceMagnitude"]


@register("force")
class ForceMagnitude(Cost):
    """Squared forces and force rates, normalised by the weight m·g."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """Sum over feet, stance polynomials and axes."""
        w = nlp.config.costs.force
        if w.weight == 0:
            return None
        term = melon_integral_function(0)
        scale = 1.0 / nlp.body.weight
        total: Any = 0
        for force in nlp.forces:
            s = force.spline
            for k, info in enumerate(force.polys):
                if info.constant:
                    continue
                for axis in range(3):
                    e = ca.DM.zeros(3)
                    e[axis] = scale
                    total += term(
                        s.positions[k],
                        s.velocities[k],
                        s.positions[k + 1],
                        s.velocities[k + 1],
                        s.durations[k],
                        e,
                        0.0,
                        w.derivative_weight,
                    )
        return CostTerm(self.name, w.weight * total)
