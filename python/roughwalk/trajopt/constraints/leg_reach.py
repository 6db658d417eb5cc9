"""Each foot within its leg's reach: a ball around the hip, in the base frame.

TOWR's box (``range_of_motion``) is a box because it is cheap, but a leg's
workspace is round: the box's lower corners lie beyond a real leg's full
stretch (9 cm beyond it for ANYmal C's box), and plans that use them cannot
be executed. With the body's ``reach_centres`` and ``reach_radius``
(:func:`~roughwalk.trajopt.robot_model.leg_reach_sphere`), at every
``dt_range_of_motion`` and T:

    ‖Rᵀ (pᵢ − c) − oᵢ‖² ≤ ρ²

with pᵢ the contact point, c the CoM and oᵢ the ball's centre relative to
the CoM, lowered by the foot radius (the ball holds foot centres). A pure
box inside the ball (0.09, 0.063, 0.03 m for ANYmal C) leaves too little
travel: no single- or double-pallet task of six solved with it in 100
iterations. No rows for a body without a ball (TOWR's ANYmal).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_calls
from roughwalk.trajopt.variables import base_to_world

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["LegReach", "reach_squared_function"]


def reach_squared_function() -> ca.Function:
    """SX function (c, η, p, o) → ‖Rᵀ(p − c) − o‖² [m²], R = R(η).

    Written as ‖d‖² − 2 (R o)ᵀd + ‖o‖² with d = p − c, which is the same
    since R is orthonormal: its exact Hessian (evaluated at every IPOPT
    iteration) takes 0.3 k instead of 1.2 k operations a row (R o as three
    turns, :func:`base_to_world`), and its
    position block 2I is diagonal (R Rᵀ as CasADi sees it is a dense 3×3),
    which leaves 23 % fewer Hessian entries on the learned single-pallet walk.
    """
    c, eta, foot, o = (ca.SX.sym(n, 3) for n in ("c", "eta", "p", "o"))
    d = foot - c
    value = ca.dot(d, d) - 2 * ca.dot(base_to_world(eta, o), d) + ca.dot(o, o)
    return ca.Function("reach_squared", [c, eta, foot, o], [value])


@register("leg_reach")
class LegReach(Constraint):
    """One row per foot and sample: squared distance from the reach centre [m²]."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Rows at the range-of-motion samples (None without a reach model)."""
        centres, radius = nlp.body.reach_centres, nlp.body.reach_radius
        if centres is None or radius is None:
            return None
        squared = reach_squared_function()
        centre = np.asarray(centres, dtype=float)
        parts = []
        for t in nlp.sample_times(nlp.config.dt_range_of_motion):
            base = nlp.base_lin.spline.point(t)[0]
            angles = nlp.base_ang.spline.point(t)[0]
            for i, motion in enumerate(nlp.feet):
                point = motion.spline.point(t)[0]
                parts.append(((base, angles, point, ca.SX(ca.DM(centre[i]))), 0.0, radius**2))
        # Kept as calls: the formulation builds their Hessian from the
        # function's own small one (see Call), not from the inlined rows.
        return stack_calls(self.name, squared, parts)
