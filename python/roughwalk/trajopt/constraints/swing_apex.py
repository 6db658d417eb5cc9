"""Swing apex over the middle of the step (TOWR's ``SwingConstraint``, with the actual swing time).

Each swing's middle node lies halfway between its two footholds in x, y and
moves at the step's mean horizontal velocity (footholds' distance over the
swing duration), which keeps fast swings from leaving the range of motion
between nodes.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["SwingApex", "swing_neighbours"]


def swing_neighbours(nlp: Formulation, foot: int, phase: int) -> tuple[int, int] | None:
    """The stance phases around swing ``phase`` of ``foot`` (None at the motion's ends)."""
    n = len(nlp.feet[foot].stance_phases)
    if phase == 0 or phase == n - 1:
        return None
    return phase - 1, phase + 1


@register("swing_apex")
class SwingApex(Constraint):
    """Four rows per swing between two stances."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Apex x, y and their velocities."""
        parts = []
        for f, motion in enumerate(nlp.feet):
            for phase in nlp.swing_phases(f):
                around = swing_neighbours(nlp, f, phase)
                inner = motion.inner_nodes(phase)
                if around is None or not inner:
                    continue
                apex = inner[len(inner) // 2]
                before = motion.foothold(around[0])[:2]
                after = motion.foothold(around[1])[:2]
                duration = nlp.durations[f].durations[phase]
                parts.append((motion.node_pos[apex][:2] - 0.5 * (before + after), 0.0, 0.0))
                parts.append((motion.node_vel[apex][:2] - (after - before) / duration, 0.0, 0.0))
        return stack_rows(self.name, parts)
