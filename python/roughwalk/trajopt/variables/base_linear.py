"""Base linear motion: the centre of mass as a spline of cubic Hermite polynomials.

One polynomial per ``base_poly_duration`` (0.1 s by default, the last one
shorter if the duration is not a multiple); every node's position and
velocity are decision variables: 6 per node (Winkler 2018, §V-A).
"""

from __future__ import annotations

from collections.abc import Sequence

from roughwalk.trajopt.variables.spline import NodeSpline
from roughwalk.trajopt.variables.variable_set import NodeIndex, NodeVariableSet

__all__ = ["BaseLinear", "base_poly_durations", "all_node_index"]


def base_poly_durations(total_duration: float, poly_duration: float) -> list[float]:
    """Durations [s] of the base polynomials: ``poly_duration`` each, the last one the remainder."""
    durations: list[float] = []
    left = total_duration
    while left > 1e-10:
        durations.append(min(poly_duration, left))
        left -= poly_duration
    return durations


def all_node_index(n_nodes: int, dim: int = 3) -> list[list[NodeIndex]]:
    """Index map where every node's position and velocity are variables, node by node."""
    index: list[list[NodeIndex]] = []
    for node in range(n_nodes):
        for kind in ("pos", "vel"):
            index.extend([NodeIndex(node, kind, d)] for d in range(dim))
    return index


class BaseLinear(NodeVariableSet):
    """Base (CoM) position [m] and velocity [m/s] at every node of the base spline."""

    def __init__(self, durations: Sequence[float], name: str = "base_lin") -> None:
        n_nodes = len(durations) + 1
        super().__init__(name, all_node_index(n_nodes), n_nodes)
        self.durations = list(durations)
        self.spline = NodeSpline(self.node_pos, self.node_vel, self.durations)
