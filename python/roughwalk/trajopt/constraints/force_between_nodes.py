"""Unilateral force and friction pyramid along the whole force spline, not only at its nodes.

:class:`~roughwalk.trajopt.constraints.force.ForceLimits` bounds the force
at its nodes. A cubic Hermite segment between two nodes that satisfy
0 ≤ f·n can still dip far below zero in between when the node rates are
large: converged double-pallet plans pulled on the ground during 19 % of
stance time, down to −430 N, and the tracking controller, which can only
push, lost its footing there.

A cubic segment of duration d from (f₀, ḟ₀) to (f₁, ḟ₁) is the Bézier curve
with control points

    f₀,   f₀ + d ḟ₀ / 3,   f₁ − d ḟ₁ / 3,   f₁,

and lies in their convex hull. The set 0 ≤ f·n ≤ f_max inside the friction
pyramid is convex, so the two inner control points satisfying the node rows
keep the whole segment inside it (the end points are the nodes, which
ForceLimits checks). The condition is sufficient, slightly conservative, and
linear in the force variables when the phase durations are fixed.

Opt-in (append ``"force_between_nodes"`` to ``TrajoptConfig.constraints``;
it is not in :func:`~roughwalk.trajopt.parameters.melon_config`'s default
set). Measured from the shipped learned models on 10 held-out tasks each:
single pallet, all converge either way (21 against 17 iterations), least
normal force 0 N against −191 N, tracking at 5 iterations 10/10 against
9/10; double pallet, none converges within the 40 s limit (600–1000
iterations from the current model, which was trained without it), and at
5 iterations tracking is unchanged (1/10); yet with a 240 s limit the plans
of 6 tasks (violation ≤ 0.04) track 5/6, where the same tasks' plans
without it track 1/6. A double-pallet model trained with it is the step
that would make it the default.

``unilateral_between_nodes`` keeps only the first of the five rows at the
inner control points (0 ≤ f·n: no pulling, what the controller cannot do).
From the same double-pallet model it converges as the problem without it
does (session 7, first 14 training tasks 419–432, limit 300: 5 converged in
23–102 iterations, 0.5–3 s CPU each), where the full rows converged on none
of three (520–600 iterations, 18–23 s CPU each).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import casadi as ca

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows
from roughwalk.trajopt.constraints.force import force_limit_rows, terrain_basis

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["ForceBetweenNodes", "UnilateralBetweenNodes", "inner_control_points", "stance_segments"]


def inner_control_points(
    f0: ca.SX, rate0: ca.SX, f1: ca.SX, rate1: ca.SX, d: ca.SX | float
) -> tuple[ca.SX, ca.SX]:
    """Inner Bézier control points of the cubic Hermite segment (f₀, ḟ₀) → (f₁, ḟ₁) of d [s]."""
    return f0 + d * rate0 / 3.0, f1 - d * rate1 / 3.0


def stance_segments(nlp: Formulation) -> Iterator[tuple[Any, tuple[Any, Any]]]:
    """(terrain basis, inner control points) of every stance force segment, feet in order."""
    for foot, force in enumerate(nlp.forces):
        for phase in nlp.stance_phases(foot):
            basis = terrain_basis(nlp.foothold_terrain(foot, phase))
            for k in force.phase_nodes(phase)[:-1]:
                yield (
                    basis,
                    inner_control_points(
                        force.node_pos[k],
                        force.node_vel[k],
                        force.node_pos[k + 1],
                        force.node_vel[k + 1],
                        force.spline.durations[k],
                    ),
                )


@register("force_between_nodes")
class ForceBetweenNodes(Constraint):
    """Ten rows per stance force segment: the node rows at its two inner control points."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Normal force bounds [N] and friction pyramid at every segment's inner control points."""
        mu = nlp.body.friction
        f_max = nlp.body.force_limit
        parts = []
        for basis, points in stance_segments(nlp):
            for f in points:
                parts += force_limit_rows(f, basis, mu, f_max)
        return stack_rows(self.name, parts)


@register("unilateral_between_nodes")
class UnilateralBetweenNodes(Constraint):
    """Two rows per stance force segment: 0 ≤ f·n at its two inner control points.

    The pulling half of :class:`ForceBetweenNodes` alone (what the tracking
    controller, which can only push, cannot realise). Without the friction
    pyramid and f_max at the inner points, the double pallet's solves from a
    model trained without either constraint converge: measured from the
    session-6 model on training task 421, 28 iterations (0.7 s CPU) against
    521 and no convergence with the full set of rows.
    """

    def build(self, nlp: Formulation) -> Rows | None:
        """The normal force [N] at every segment's inner control points, ≥ 0."""
        parts = []
        for basis, points in stance_segments(nlp):
            parts += [(ca.dot(f, basis[0]), 0.0, math.inf) for f in points]
        return stack_rows(self.name, parts)
