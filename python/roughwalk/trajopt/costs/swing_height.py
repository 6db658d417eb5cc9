"""Melon et al.'s swing-height cost (§III-A.2): keep the swing apex low.

ω Σ (z_apex − (z_before + z_after)/2)² [m²]: large leg motions create
angular momentum the single rigid body does not model; the swing-height
constraint keeps the apex high enough, this cost keeps it no higher.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from roughwalk.trajopt.constraints.swing_apex import swing_neighbours
from roughwalk.trajopt.costs import Cost, CostTerm, register

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["SwingHeightCost"]


@register("swing_height")
class SwingHeightCost(Cost):
    """Squared apex height above the mean of the swing's two footholds."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """Sum over swings between two stances."""
        weight = nlp.config.costs.swing_height
        if weight == 0:
            return None
        total: Any = 0
        for f, motion in enumerate(nlp.feet):
            for phase in nlp.swing_phases(f):
                around = swing_neighbours(nlp, f, phase)
                inner = motion.inner_nodes(phase)
                if around is None or not inner:
                    continue
                apex_z = motion.node_pos[inner[len(inner) // 2]][2]
                mean = 0.5 * (motion.foothold(around[0])[2] + motion.foothold(around[1])[2])
                total += (apex_z - mean) ** 2
        return CostTerm(self.name, weight * total)
