"""Each foot inside a box around its nominal position, in the base frame (Winkler 2018, §V-D).

At every ``dt_range_of_motion`` and T: Rᵀ (pᵢ − c) ∈ nominalᵢ ± max_deviation.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_calls
from roughwalk.trajopt.variables import sample_points, world_to_base

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["RangeOfMotion"]


@register("range_of_motion")
class RangeOfMotion(Constraint):
    """The legs' reach as a box per foot [m]."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Three rows per foot and sample time."""
        c, eta, foot = ca.SX.sym("c", 3), ca.SX.sym("eta", 3), ca.SX.sym("p", 3)
        # Rᵀ(p − c) as three turns: a third fewer operations in the exact Hessian.
        in_base = ca.Function("foot_in_base", [c, eta, foot], [world_to_base(eta, foot - c)])
        stance = nlp.body.stance
        dev = np.asarray(nlp.body.max_deviation)
        times = nlp.sample_times(nlp.config.dt_range_of_motion)
        splines = [nlp.base_lin.spline, nlp.base_ang.spline] + [m.spline for m in nlp.feet]
        base, angles, *feet = sample_points(splines, times)
        parts = []
        for j in range(len(times)):
            for i, points in enumerate(feet):
                parts.append(
                    ((base[j][0], angles[j][0], points[j][0]), stance[i] - dev, stance[i] + dev)
                )
        return stack_calls(self.name, in_base, parts)
