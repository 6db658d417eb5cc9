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

On the double pallet they need ``swing_base_clearance`` 0.5. With the base
0.7 × the nominal height above every foot, swing feet included, none of
the 18 held-out tasks 0–29 that start at x > 0.057 m converged (session
14: 13 time-outs, 3 iteration limits, 2 locally infeasible). Why (session
15, task 3): while a front foot swings onto the top the CoM must stay 0.72
m up and the hind legs, on the ground, stretch to their reach (at the free
optimum 82 of the 392 stance samples have a leg beyond 97 % of a + b), and
no plan near there asks much less: the soft form of these rows (their
squared excess as a cost, weight 100) converges to a plan that still asks
310 N·m, from the learned guess and from the free optimum alike. Given the
hard rows, IPOPT's accepted steps move the force rates by 10³–10⁴ N/s (no
cost curves them: the Lagrangian's Hessian there is ~10⁻⁹ against ~10⁸ for
the feet) while the multipliers of the rows on the feet (terrain, base
above feet, swing height, reach) grow to 10⁷ and the dual infeasibility to
10¹². Rows written as shares of the limit (IPOPT's gradient scaling
already divides them), a knee-bend row at every sample or rows at the
force nodes only did not converge on task 3 either (the last lets the
forces run away between the nodes). With
``swing_base_clearance`` 0.5 (stance feet keep 0.7), from the learned
guess at margin 1, 15 of those 18 tasks converge (median 119 iterations,
5.5 s of CPU; 2 iteration limits, 1 time-out at 700 iterations / 150 s),
their plans ask 81–83 N·m at 100 Hz (the unconverged 90–93), and 17 of
18 track (``roughwalk.track``; session 14's free optima 8 of 18). The
other three (9, 11, 17) converge from their free optimum at the same
clearance (``warm_start=``, 50–71 iterations, 2–7 s of CPU, 81–82 N·m) and
track. The tracking bench's 5-iteration solves are the learned guess's
(which asks 240–590 N·m): 24 of 30 tracked with these rows and clearance
as without them.
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
