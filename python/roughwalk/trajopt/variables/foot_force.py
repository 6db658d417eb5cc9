"""A foot's contact force: free nodes in stance, zero in swing (Winkler 2018, §V-B).

A stance phase has ``force_polys_per_stance`` polynomials; each of its inner
nodes (and the first and last nodes of the motion, when in stance) has the
force and its rate as variables: 6 per node. In swing the force is zero.
"""

from __future__ import annotations

from roughwalk.trajopt.variables.phase_durations import PhaseDurations
from roughwalk.trajopt.variables.phase_nodes import PhaseNodes
from roughwalk.trajopt.variables.variable_set import NodeIndex

__all__ = ["FootForce"]


class FootForce(PhaseNodes):
    """Foot ``foot``'s contact force nodes [N] and their rates [N/s], world frame."""

    def __init__(
        self,
        foot: int,
        in_contact_at_start: bool,
        polys_per_stance: int,
        durations: PhaseDurations,
    ) -> None:
        self.foot = foot
        n_phases = durations.n_phases
        stance = [in_contact_at_start == (k % 2 == 0) for k in range(n_phases)]
        self.stance_phases = stance
        swing = [not s for s in stance]
        super().__init__(f"foot_force_{foot}", swing, polys_per_stance, durations)

    def parametrize(self, n_nodes: int) -> list[list[NodeIndex]]:
        """Free: force and force rate at every node that is not held at zero by a swing."""
        index: list[list[NodeIndex]] = []
        node = 0
        while node < n_nodes:
            if not self.constant_node[node]:
                for dim in range(3):
                    index.append([NodeIndex(node, "pos", dim)])
                    index.append([NodeIndex(node, "vel", dim)])
                node += 1
            else:
                node += 2
        return index

    def free_nodes(self, phase: int) -> list[int]:
        """Nodes of stance phase ``phase`` whose force is a variable."""
        return [n for n in self.phase_nodes(phase) if not self.constant_node[n]]
