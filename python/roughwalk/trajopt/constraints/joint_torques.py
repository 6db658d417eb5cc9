"""The joint torques the stance forces ask of the legs, within the motors' limits.

The single rigid body has massless legs and unbounded hips: it bounds a
foot's force by friction and f_max and the foot by its leg's reach, never
by what the leg's motors can push. Converged double-pallet optima asked
250–480 N·m of a hind HFE (ANYmal C's limit 80 N·m, :mod:`.implied_torques`)
and fell when executed. With each leg's geometry
(:class:`~roughwalk.trajopt.leg_statics.LegStatics`), at every
``dt_joint_torques`` and T and for every foot whose force there is not
structurally zero (in stance at that time):

    |τ_k(c, η, pᵢ, fᵢ)| ≤ margin · τ_max,k,   τ = −Jᵀ f

three rows per leg (HAA, HFE, KFE), τ in closed form
(:func:`~roughwalk.trajopt.leg_statics.joint_torques_function`). No rows
for a body without leg geometry (TOWR's ANYmal).

Opt-in: append ``"joint_torques"`` to ``TrajoptConfig.constraints``; the
margin is ``joint_torque_margin``. Measured (session 14, 16-step walk in
5.5 s, learned initialiser): flat and single pallet converge in about as
many iterations as without (single pallet 9–16 against 7–14, worst joint
81–87 N·m at 100 Hz against 98–195), at twice the solve CPU (0.4–0.6 s).
On the double pallet's 18 held-out tasks 0–29 that start at x > 0.057 m, no
solve with the rows converged (warm-started from the free optimum where
there is one, else from the learned guess; ≤ 700 iterations or 150 s: 13
time-outs, 3 iteration limits, 2 locally infeasible; median 99 s CPU). From
the free optimum of task 3, margin 4 converged in 81 iterations and margin 2
did not in 225. Yet the unconverged plans, which ask 80–108 N·m where the
free optima ask 261–592, executed better: 12 of 18 tracked against 8 of 18
(6 gained, 2 lost; median tracking error 3.1 against 4.9 cm). Not the
default: it needs a problem (or experience) in which it converges.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import casadi as ca
import numpy as np

from roughwalk.trajopt.constraints import Constraint, Rows, register, stack_calls
from roughwalk.trajopt.leg_statics import joint_torques_function

if TYPE_CHECKING:
    from roughwalk.trajopt.formulation import Formulation

__all__ = ["JointTorques"]


@register("joint_torques")
class JointTorques(Constraint):
    """Three rows per stance foot and sample: its leg's HAA, HFE, KFE torques [N·m]."""

    def build(self, nlp: Formulation) -> Rows | None:
        """Rows at the ``dt_joint_torques`` samples (None without leg geometry)."""
        legs = nlp.body.legs
        if legs is None:
            return None
        torques = joint_torques_function(nlp.body.com_in_base)
        margin = nlp.config.joint_torque_margin
        parts = []
        for t in nlp.sample_times(nlp.config.dt_joint_torques):
            base = nlp.base_lin.spline.point(t)[0]
            angles = nlp.base_ang.spline.point(t)[0]
            for i, leg in enumerate(legs):
                force = nlp.forces[i].spline.point(t)[0]
                if ca.SX(force).is_zero():
                    continue  # a swing: no force, no torque
                point = nlp.feet[i].spline.point(t)[0]
                limit = margin * np.asarray(leg.torque_limits, dtype=float)
                parameters = ca.SX(ca.DM(leg.vector()))
                parts.append(((base, angles, point, force, parameters), -limit, limit))
        # Kept as calls: the formulation builds their Hessian from the
        # function's own small one (see Call), not from the inlined rows.
        return stack_calls(self.name, torques, parts)
