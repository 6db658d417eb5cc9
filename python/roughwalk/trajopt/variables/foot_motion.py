"""A foot's motion: one position per stance phase, free nodes in swing (Winkler 2018, §V-B).

In stance the foot does not move: both nodes of the stance polynomial share
one (x, y, z) foothold variable and have zero velocity. A swing phase has
``foot_polys_per_swing`` polynomials; each inner node has its position and
its x, y velocity as variables, and a vertical velocity fixed at zero, so
that with two polynomials the middle node is the apex of the step.
"""

from __future__ import annotations

import casadi as ca

from roughwalk.trajopt.variables.phase_durations import PhaseDurations
from roughwalk.trajopt.variables.phase_nodes import PhaseNodes
from roughwalk.trajopt.variables.variable_set import NodeIndex

__all__ = ["FootMotion"]


class FootMotion(PhaseNodes):
    """Foot ``foot``'s position nodes [m] (world frame) and swing velocities [m/s]."""

    def __init__(
        self,
        foot: int,
        in_contact_at_start: bool,
        polys_per_swing: int,
        durations: PhaseDurations,
    ) -> None:
        self.foot = foot
        n_phases = durations.n_phases
        stance = [in_contact_at_start == (k % 2 == 0) for k in range(n_phases)]
        self.stance_phases = stance
        super().__init__(f"foot_motion_{foot}", stance, polys_per_swing, durations)

    def parametrize(self, n_nodes: int) -> list[list[NodeIndex]]:
        """Free: each foothold (on both its stance nodes), each swing node's xyz and xy-velocity."""
        index: list[list[NodeIndex]] = []
        node = 0
        while node < n_nodes:
            if not self.constant_node[node]:
                for dim in range(3):
                    index.append([NodeIndex(node, "pos", dim)])
                    if dim < 2:
                        index.append([NodeIndex(node, "vel", dim)])
                node += 1
            else:
                for dim in range(3):
                    index.append([NodeIndex(node, "pos", dim), NodeIndex(node + 1, "pos", dim)])
                node += 2
        return index

    def foothold(self, phase: int) -> ca.SX:
        """The (3, 1) foothold [m] of stance phase ``phase``."""
        if not self.stance_phases[phase]:
            raise ValueError(f"phase {phase} of foot {self.foot} is a swing phase")
        return self.node_pos[self.phase_nodes(phase)[0]]
