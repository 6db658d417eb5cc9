"""Unilateral contact forces up to f_max inside a friction pyramid (Winkler 2018, §V-D).

For every force node of a stance phase, with n, t₁, t₂ the terrain's normal
and tangents at that phase's foothold:

    0 ≤ f·n ≤ f_max,   |f·t₁| ≤ μ f·n,   |f·t₂| ≤ μ f·n.

The tangents are the surface's x and y directions, (1, 0, ∂h/∂x) and
(0, 1, ∂h/∂y), normalised, as in TOWR's height map.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["ForceLimits", "force_limit_rows", "terrain_basis"]


def terrain_basis(terrain_values: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
    """Unit normal and tangents (n, t₁, t₂) from terrain values (h, ∂h/∂x, ∂h/∂y, ...)."""
    hx, hy = terrain_values[1], terrain_values[2]
    n = ca.vertcat(-hx, -hy, 1.0)
    t1 = ca.vertcat(1.0, 0.0, hx)
    t2 = ca.vertcat(0.0, 1.0, hy)
    return n / ca.norm_2(n), t1 / ca.norm_2(t1), t2 / ca.norm_2(t2)


def force_limit_rows(
    f: ca.SX, basis: tuple[ca.SX, ca.SX, ca.SX], mu: float, f_max: float
) -> list[tuple[ca.SX, float, float]]:
    """The five (row, lower, upper) of one force ``f``: 0 ≤ f·n ≤ f_max and the friction pyramid."""
    n, t1, t2 = basis
    return [
        (ca.dot(f, n), 0.0, f_max),
        (ca.dot(f, t1 - mu * n), -np.inf, 0.0),
        (ca.dot(f, t1 + mu * n), 0.0, np.inf),
        (ca.dot(f, t2 - mu * n), -np.inf, 0.0),
        (ca.dot(f, t2 + mu * n), 0.0, np.inf),
    ]


@register("force")
class ForceLimits(Constraint):
    """Normal force bounds [N] and friction pyramid."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Five rows per stance force node."""
        mu = nlp.body.friction
        f_max = nlp.body.force_limit
        parts = []
        for foot, force in enumerate(nlp.forces):
            for phase in nlp.stance_phases(foot):
                n, t1, t2 = terrain_basis(nlp.foothold_terrain(foot, phase))
                for node in force.free_nodes(phase):
                    parts += force_limit_rows(force.node_pos[node], (n, t1, t2), mu, f_max)
        return stack_rows(self.name, parts)
