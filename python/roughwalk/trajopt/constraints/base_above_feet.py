"""The base stays above every foot (Melon 2020, §III-A.2).

TOWR's box allows the base to sink towards a foot on a tilted body; keeping
the CoM at least ``base_clearance`` × nominal height above every foot keeps
the trunk off the ground at the range-of-motion samples.

A foot in swing may have its own clearance, ``swing_base_clearance``: on
the double pallet a front foot swinging onto the top (0.31 m, plus the
0.08 m swing clearance) holds ANYmal C's CoM at least 0.72 m up at 0.7 ×
0.49 m while a hind foot still stands on the ground, more than the leg's
0.61 m: the trunk pitches up, the hind legs stretch to their reach and
carry the climb with 300–560 N·m at HFE. Joint-torque rows cannot be met there (see
:mod:`.joint_torques`); over a swinging foot 0.5 leaves the trunk 0.25 m
above it and the stance feet keep the full clearance.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["BaseAboveFeet"]


@register("base_above_feet")
class BaseAboveFeet(Constraint):
    """One row per foot and sample: z_base − z_foot ≥ clearance [m] (its own over a swing)."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Rows at the range-of-motion samples."""
        config = nlp.config
        clearance = config.base_clearance * nlp.body.nominal_height
        swing = config.swing_base_clearance
        over_swing = clearance if swing is None else swing * nlp.body.nominal_height
        parts = []
        for t in nlp.sample_times(config.dt_range_of_motion):
            base_z = nlp.base_lin.spline.point(t)[0][2]
            for motion, force in zip(nlp.feet, nlp.forces, strict=True):
                swinging = ca.SX(force.spline.point(t)[0]).is_zero()
                lower = over_swing if swinging else clearance
                parts.append((base_z - motion.spline.point(t)[0][2], lower, np.inf))
        return stack_rows(self.name, parts)
