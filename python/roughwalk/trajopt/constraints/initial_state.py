"""The start state from the task: base pose at rest, feet on their start footholds.

TOWR bounds the first nodes (``AddStartBound``); here the bounds read the
task parameters p, so the same NLP serves every task.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["InitialState"]


@register("initial_state")
class InitialState(Constraint):
    """First base node = start pose with zero velocity; first foot nodes = start footholds."""

    def build(self, nlp: Formulation) -> Rows | None:
        """24 rows for the base and 3 per foot."""
        task = nlp.task
        parts = [
            (nlp.base_lin.node_pos[0] - task.start_position, 0.0, 0.0),
            (nlp.base_lin.node_vel[0], 0.0, 0.0),
            (nlp.base_ang.node_pos[0] - task.start_euler, 0.0, 0.0),
            (nlp.base_ang.node_vel[0], 0.0, 0.0),
        ]
        for f, motion in enumerate(nlp.feet):
            parts.append((motion.node_pos[0] - task.start_feet[f], 0.0, 0.0))
        return stack_rows(self.name, parts)
