"""A soft friction pyramid between the force nodes: the squared violation of its rows as a cost.

:class:`~roughwalk.trajopt.constraints.force_between_nodes.ForceBetweenNodes`
asks, as hard rows, that the two inner Bézier control points of every stance
force segment satisfy the node rows (0 ≤ f·n ≤ f_max inside the friction
pyramid), which keeps the whole cubic inside the cone. From the shipped
double-pallet model those rows stall IPOPT: the model's guess breaks them by
up to 1.4 kN (its force rates carry the control points far out of the
pyramid), the predicted multipliers know nothing of them, and the filter
line search then takes steps of 10⁻⁴–10⁻¹ while the dual infeasibility
grows to 10⁸ and the restoration phase runs again and again (task 1 of the
held-out ten: 98 iterations, violation still 77 N).

This cost asks the same thing softly:

    ω Σ_segments Σ_{inner points} Σ_rows (max(0, r − r_max, r_min − r) / m g)²,

with the rows of :func:`~roughwalk.trajopt.constraints.force.force_limit_rows`.
It adds no row, so the learned model's multipliers keep their meaning and the
guess stays as feasible as it was; the price is that the cone may be left by
a little where the other rows pull against it (a quadratic penalty is not
exact). ω (``CostWeights.force_between_nodes_penalty``) is 0 by default.

Measured (session 9) from the shipped double-pallet model on the 10
held-out tasks, ω = 10, limit 100: the solves converge on the same 4 tasks
as without it (0, 2, 3, 8; 35–74 iterations), where the hard rows converge
on none, and the converged plans' largest control-point excess drops from
1.1–3.0 kN to 0.14–1.3 kN. Tracked (``bench_tracking.py --tasks 10 --env
double_pallet --init learned --durations fixed --iters 5,10,20 --trajopt
costs.force_between_nodes_penalty=10``): 7, 7, 5 of 10 at 5, 10, 20
iterations (without it 4, 7, 2; with the hard rows 6, 7, 9), median
sampled pyramid excess 536, 480, 528 N: within 5–20 iterations the plan is
still the model's guess, and the guess leaves the cone. Single pallet at 5
iterations: 10 / 10. Not a default: its use is to make solves that keep the
cone converge, for a model trained on them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import casadi as ca

from roughwalk.trajopt.constraints.force import force_limit_rows
from roughwalk.trajopt.constraints.force_between_nodes import stance_segments
from roughwalk.trajopt.costs import Cost, CostTerm, register

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["ForceBetweenNodesPenalty"]


@register("force_between_nodes_penalty")
class ForceBetweenNodesPenalty(Cost):
    """Squared violation of the node rows at every stance segment's inner control points."""

    def build(self, nlp: Formulation) -> CostTerm | None:
        """ω Σ (violation / m g)² over segments, inner points and the five rows."""
        w = nlp.config.costs.force_between_nodes_penalty
        if w == 0:
            return None
        mu = nlp.body.friction
        f_max = nlp.body.force_limit
        scale = 1.0 / nlp.body.weight
        total: Any = 0
        for basis, points in stance_segments(nlp):
            for f in points:
                for row, lower, upper in force_limit_rows(f, basis, mu, f_max):
                    excess = ca.fmax(0.0, ca.fmax(row - upper, lower - row))
                    total += (scale * excess) ** 2
        return CostTerm(self.name, w * total)
