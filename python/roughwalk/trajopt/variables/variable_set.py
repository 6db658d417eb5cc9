"""The base of every variable set: named CasADi symbols with bounds and a node index map."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["VariableSet", "NodeVariableSet", "NodeIndex"]


@dataclass(frozen=True)
class NodeIndex:
    """Where one decision variable lands: node ``node``'s ``kind`` ("pos"/"vel"), axis ``dim``."""

    node: int
    kind: str
    dim: int


class VariableSet:
    """A named block of decision variables.

    Subclasses create :attr:`symbols` (an (n, 1) SX) and may tighten
    :attr:`lower` and :attr:`upper` (variable bounds, ±inf by default).
    """

    name: str = "variables"

    def __init__(self, name: str, size: int) -> None:
        self.name = name
        self.symbols = ca.SX.sym(name, size)
        self.lower = np.full(size, -np.inf)
        self.upper = np.full(size, np.inf)

    @property
    def size(self) -> int:
        """Number of decision variables."""
        return int(self.symbols.numel())

    def values(self, x: ArrayLike) -> NDArray[np.float64]:
        """Return ``x`` as an array (see :meth:`Formulation.split` for a set's slice)."""
        return np.asarray(x, dtype=float)


class NodeVariableSet(VariableSet):
    """A variable set whose variables are node values of a spline, with an index map.

    ``index[i]`` lists where variable i appears (a stance foothold appears
    at two nodes); nodes not reached by any variable keep fixed values
    (zero velocities in stance, zero forces in swing).
    """

    def __init__(self, name: str, index: list[list[NodeIndex]], n_nodes: int, dim: int = 3) -> None:
        super().__init__(name, len(index))
        self.index = index
        self.n_nodes = n_nodes
        self.dim = dim
        self.node_pos: list[ca.SX] = [ca.SX.zeros(dim, 1) for _ in range(n_nodes)]
        self.node_vel: list[ca.SX] = [ca.SX.zeros(dim, 1) for _ in range(n_nodes)]
        for i, places in enumerate(index):
            for place in places:
                target = self.node_pos if place.kind == "pos" else self.node_vel
                target[place.node][place.dim] = self.symbols[i]

    def pack(self, positions: ArrayLike, velocities: ArrayLike) -> NDArray[np.float64]:
        """Variables (n,) from node values (n_nodes, dim): the first node each variable reaches."""
        pos = np.asarray(positions, dtype=float)
        vel = np.asarray(velocities, dtype=float)
        out = np.empty(self.size)
        for i, places in enumerate(self.index):
            place = places[0]
            out[i] = (pos if place.kind == "pos" else vel)[place.node, place.dim]
        return out

    def unpack(self, values: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Node positions and velocities (n_nodes, dim) from this set's variables."""
        v = np.asarray(values, dtype=float)
        pos = np.zeros((self.n_nodes, self.dim))
        vel = np.zeros((self.n_nodes, self.dim))
        for i, places in enumerate(self.index):
            for place in places:
                (pos if place.kind == "pos" else vel)[place.node, place.dim] = v[i]
        return pos, vel
