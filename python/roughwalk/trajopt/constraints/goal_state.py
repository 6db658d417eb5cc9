"""The goal from the task: base x, y and orientation, at rest; its height left free (as TOWR)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["GoalState"]


@register("goal_state")
class GoalState(Constraint):
    """Last base node: x, y and Euler angles from the task, zero linear and angular velocity."""

    def build(self, nlp: Formulation) -> Rows | None:
        """11 rows."""
        task = nlp.task
        return stack_rows(
            self.name,
            [
                (nlp.base_lin.node_pos[-1][:2] - task.goal_xy, 0.0, 0.0),
                (nlp.base_lin.node_vel[-1], 0.0, 0.0),
                (nlp.base_ang.node_pos[-1] - task.goal_euler, 0.0, 0.0),
                (nlp.base_ang.node_vel[-1], 0.0, 0.0),
            ],
        )
