"""Phase-based splines (Winkler 2018, §V-B): polynomials laid out phase by phase.

A foot's motion is constant in stance (one polynomial whose two nodes share
one position variable) and moves in swing (several polynomials); its force is
zero in swing (one constant polynomial) and shaped by several polynomials in
stance. The polynomials of a phase share its duration equally, so optimising
a phase duration stretches them together.
"""

from __future__ import annotations

from dataclasses import dataclass

from roughwalk.trajopt.variables.phase_durations import PhaseDurations
from roughwalk.trajopt.variables.spline import NodeSpline
from roughwalk.trajopt.variables.variable_set import NodeIndex, NodeVariableSet

__all__ = ["PolyInfo", "PhaseNodes", "build_poly_infos"]


@dataclass(frozen=True)
class PolyInfo:
    """Polynomial ``index_in_phase`` of ``polys_in_phase`` in ``phase``; ``constant`` if held."""

    phase: int
    index_in_phase: int
    polys_in_phase: int
    constant: bool


def build_poly_infos(constant_phases: list[bool], polys_per_changing_phase: int) -> list[PolyInfo]:
    """The polynomials of a phase-based spline: one per constant phase, n per changing one."""
    infos: list[PolyInfo] = []
    for phase, constant in enumerate(constant_phases):
        if constant:
            infos.append(PolyInfo(phase, 0, 1, True))
        else:
            n = polys_per_changing_phase
            infos.extend(PolyInfo(phase, j, n, False) for j in range(n))
    return infos


class PhaseNodes(NodeVariableSet):
    """Node variables of a phase-based spline; subclasses choose which node values are free."""

    def __init__(
        self,
        name: str,
        constant_phases: list[bool],
        polys_per_changing_phase: int,
        durations: PhaseDurations,
    ) -> None:
        self.polys = build_poly_infos(constant_phases, polys_per_changing_phase)
        n_nodes = len(self.polys) + 1
        self.constant_node = [
            any(self.polys[k].constant for k in self.adjacent_polys(node, n_nodes))
            for node in range(n_nodes)
        ]
        super().__init__(name, self.parametrize(n_nodes), n_nodes)
        self.phase_durations = durations
        poly_durations = [durations.durations[p.phase] / p.polys_in_phase for p in self.polys]
        windows = [
            durations.poly_window(p.phase, p.index_in_phase, p.polys_in_phase) for p in self.polys
        ]
        self.spline = NodeSpline(self.node_pos, self.node_vel, poly_durations, windows)

    @staticmethod
    def adjacent_polys(node: int, n_nodes: int) -> list[int]:
        """Polynomials that start or end at ``node``."""
        if node == 0:
            return [0]
        if node == n_nodes - 1:
            return [n_nodes - 2]
        return [node - 1, node]

    def parametrize(self, n_nodes: int) -> list[list[NodeIndex]]:
        """The index map (which node values are variables); see subclasses."""
        raise NotImplementedError

    def first_poly_of_phase(self, phase: int) -> int:
        """Index of the first polynomial of ``phase``."""
        return next(k for k, p in enumerate(self.polys) if p.phase == phase)

    def phase_nodes(self, phase: int) -> list[int]:
        """Nodes of ``phase`` from its start node to its end node."""
        first = self.first_poly_of_phase(phase)
        n = self.polys[first].polys_in_phase
        return list(range(first, first + n + 1))

    def inner_nodes(self, phase: int) -> list[int]:
        """Nodes strictly inside ``phase``."""
        return self.phase_nodes(phase)[1:-1]
