"""Continuous base accelerations where base polynomials meet (TOWR's ``BaseAcc``).

Without it the accelerations, and so the forces the dynamics ask for, could
jump between polynomials.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_rows

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["BaseAccelerationContinuity"]


@register("base_acceleration")
class BaseAccelerationContinuity(Constraint):
    """Linear and angular base accelerations equal on both sides of every junction."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Six rows per junction."""
        parts = []
        for variables in (nlp.base_lin, nlp.base_ang):
            spline = variables.spline
            n = spline.n_polys - 1
            if spline.fixed:
                ends = spline.poly_points(range(n), spline.durations[:n])
                starts = spline.poly_points(range(1, n + 1), [0.0] * n)
                for end, start in zip(ends, starts, strict=True):
                    parts.append((end[2] - start[2], 0.0, 0.0))
                continue
            # Symbolic durations: the expressions in the order they were
            # always made (see sample_points: that order steers IPOPT).
            for k in range(n):
                before = spline.poly_point(k, spline.durations[k])[2]
                after = spline.poly_point(k + 1, 0.0)[2]
                parts.append((before - after, 0.0, 0.0))
        return stack_rows(self.name, parts)
