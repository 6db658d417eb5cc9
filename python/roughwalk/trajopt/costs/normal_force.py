"""Melon et al.'s desired normal force (§III-A.1): f·n close to the foot's share of the weight.

During a stance phase the reference is m·g divided by the mean number of
feet in stance over that phase (from the nominal schedule), and n is the
terrain normal at the phase's foothold; forces enter divided by m·g.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from roughwalk.trajopt.constraints.force import terrain_basis
from roughwalk.trajopt.costs import Cost, CostTerm, register
from roughwalk.trajopt.costs.integral import melon_integral_function

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation
    from roughwalk.trajopt.gaits import ContactSchedule

__all__ = ["NormalForce", "stance_share"]


def stance_share(schedule: ContactSchedule, foot: int, phase: int, samples: int = 50) -> float:
    """1 / (mean number of feet in stance) over ``foot``'s ``phase``: its share of the weight."""
    bounds = schedule.phase_times(foot)
    times = np.linspace(bounds[phase], bounds[phase + 1], samples + 2)[1:-1]
    count = sum(schedule.in_contact(f, times).astype(float) for f in range(schedule.n_feet))
    return float(np.mean(1.0 / np.maximum(count, 1.0)))


@register("normal_force")
class NormalForce(Cost):
    """ω Σ ∫ ((f·n/mg − share)² + ω_d (ḟ·n/mg)²) dt over stance polynomials."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """Sum over feet and stance polynomials."""
        w = nlp.config.costs.normal_force
        if w.weight == 0:
            return None
        term = melon_integral_function(0)
        scale = 1.0 / nlp.body.weight
        total: Any = 0
        for foot, force in enumerate(nlp.forces):
            s = force.spline
            for phase in nlp.stance_phases(foot):
                n = terrain_basis(nlp.foothold_terrain(foot, phase))[0]
                share = stance_share(nlp.schedule, foot, phase)
                first = force.first_poly_of_phase(phase)
                for k in range(first, first + force.polys[first].polys_in_phase):
                    total += term(
                        s.positions[k],
                        s.velocities[k],
                        s.positions[k + 1],
                        s.velocities[k + 1],
                        s.durations[k],
                        scale * n,
                        share,
                        w.derivative_weight,
                    )
        return CostTerm(self.name, w.weight * total)
