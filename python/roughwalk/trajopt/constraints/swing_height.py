"""Swing apex high enough above both footholds (Melon 2020, §III-A.2).

TOWR checks the terrain only at nodes, so a swing may cut through a step's
edge between them; lifting the apex ``swing_clearance`` above both of the
swing's footholds makes the foot clear the higher one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows
from roughwalk.trajopt.constraints.swing_apex import swing_neighbours

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["SwingHeight"]


@register("swing_height")
class SwingHeight(Constraint):
    """Two rows per swing: apex z − foothold z ≥ clearance [m] for both footholds."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Rows for every swing between two stances."""
        clearance = nlp.config.swing_clearance
        parts = []
        for f, motion in enumerate(nlp.feet):
            for phase in nlp.swing_phases(f):
                around = swing_neighbours(nlp, f, phase)
                inner = motion.inner_nodes(phase)
                if around is None or not inner:
                    continue
                apex_z = motion.node_pos[inner[len(inner) // 2]][2]
                for stance in around:
                    parts.append((apex_z - motion.foothold(stance)[2], clearance, np.inf))
        return stack_rows(self.name, parts)
