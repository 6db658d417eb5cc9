"""Feet on the terrain in stance and above it in swing (Winkler 2018, §V-D).

Every stance foothold satisfies z = h(x, y) (except the start foothold,
which the initial state fixes); every swing node satisfies z ≥ h(x, y).
As in TOWR, this holds at the nodes only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["TerrainContact"]


@register("terrain")
class TerrainContact(Constraint):
    """Foot heights [m] against the terrain's."""

    def build(self, nlp: Formulation) -> Rows | None:
        """One row per free foothold and per swing node."""
        parts = []
        for f, motion in enumerate(nlp.feet):
            for phase in nlp.stance_phases(f):
                if nlp.fixed_foothold(f, phase):
                    continue
                p = motion.foothold(phase)
                parts.append((p[2] - nlp.foothold_terrain(f, phase)[0], 0.0, 0.0))
            for phase in nlp.swing_phases(f):
                for node in motion.inner_nodes(phase):
                    p = motion.node_pos[node]
                    h = nlp.terrain_at(f"swing/{f}/{node}", p[:2])[0]
                    parts.append((p[2] - h, 0.0, np.inf))
        return stack_rows(self.name, parts)
