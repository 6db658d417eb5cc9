"""Room for each foot's last phase when durations are optimised (TOWR's ``TotalDuration``).

The last phase is the total minus the others, so the others must sum to at
most T − 0.2 s (and at least 0.1 s), TOWR's numbers.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["TotalDuration"]

_MIN_LAST_PHASE = 0.2  # [s]
_MIN_SUM = 0.1  # [s]


@register("total_duration")
class TotalDuration(Constraint):
    """Σ of a foot's optimised phase durations ∈ [0.1, T − 0.2] [s]."""

    def build(self, nlp: Formulation) -> Rows | None:
        """One row per foot, none when durations are fixed."""
        parts = []
        for d in nlp.durations:
            if d.size:
                parts.append((ca.sum1(d.symbols), _MIN_SUM, d.total - _MIN_LAST_PHASE))
        return stack_rows(self.name, parts)
