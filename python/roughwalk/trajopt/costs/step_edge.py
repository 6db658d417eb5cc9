"""Melon et al.'s step-edge cost (§III-A.2): a Gaussian exp(−x_s²/2σ²) per foothold.

x_s is the distance from the foothold to the nearest terrain edge; the
terrain model holds the cost field as a smooth spline, so the cost only
affects footholds close to an edge.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from roughwalk.trajopt.costs import Cost, CostTerm, register

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["StepEdge"]


@register("step_edge")
class StepEdge(Cost):
    """ω Σ_footholds exp(−x_s²/2σ²)."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """Sum over the footholds that are variables."""
        weight = nlp.config.costs.step_edge
        if weight == 0 or not nlp.terrain.has_edges:
            return None
        total: Any = 0
        for foot in range(nlp.n_feet):
            for phase in nlp.stance_phases(foot):
                if not nlp.fixed_foothold(foot, phase):
                    total += nlp.foothold_terrain(foot, phase)[3]
        return CostTerm(self.name, weight * total)
