"""The base stays above every foot (Melon 2020, §III-A.2).

TOWR's box allows the base to sink towards a foot on a tilted body; keeping
the CoM at least ``base_clearance`` × nominal height above every foot keeps
the trunk off the ground at the range-of-motion samples.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["BaseAboveFeet"]


@register("base_above_feet")
class BaseAboveFeet(Constraint):
    """One row per foot and sample: z_base − z_foot ≥ clearance [m]."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Rows at the range-of-motion samples."""
        clearance = nlp.config.base_clearance * nlp.body.nominal_height
        parts = []
        for t in nlp.sample_times(nlp.config.dt_range_of_motion):
            base_z = nlp.base_lin.spline.point(t)[0][2]
            for motion in nlp.feet:
                parts.append((base_z - motion.spline.point(t)[0][2], clearance, np.inf))
        return stack_rows(self.name, parts)
