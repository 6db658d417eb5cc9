"""CHOMP's first coordinate block: the trunk trajectory (Zucker 2011, §5.3).

"First, the body trajectory is optimized with CHOMP, given the current swing
leg joint angles." The variables are the trunk's (x, y, z, roll, pitch, yaw)
at the interior samples; the supporting legs follow by IK, the lifted leg
keeps its joint angles. The objective gathers the smoothness of the change,
the obstacle cost of every body point (supporting feet excepted),
reachability of the supporting feet and the ZMP support margin.

Two backends evaluate the same terms: ``"rust"`` (the core's
``BodyPassEvaluator``: IK, body points, SDF, every term and its gradient in
one call per evaluation) and ``"python"`` (numpy over the batched
kinematics of :class:`WholeBody`; the reference the Rust one is tested
against). ``"auto"`` takes Rust whenever the SDF is the compiled one.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk import _core
from roughwalk.errors import InvalidArgumentError
from roughwalk.trajectories.chomp import Evaluation
from roughwalk.trajectories.config import ChompConfig, ValidityConfig
from roughwalk.trajectories.costs.obstacle import ObstacleCost
from roughwalk.trajectories.costs.reachability import reachability_cost
from roughwalk.trajectories.costs.smoothness import Smoothness
from roughwalk.trajectories.costs.support import ZmpSupportCost
from roughwalk.trajectories.euler import rpy_rate_matrix, rpy_to_matrix
from roughwalk.trajectories.initial_trajectory import FootstepState
from roughwalk.trajectories.whole_body import WholeBody

__all__ = [
    "BACKENDS",
    "DAMPING",
    "BodyPass",
    "clearance_ok",
    "compiled_field",
    "resolve_backend",
    "velocity_ok",
    "velocity_excess",
]

# The ZMP here comes from CHOMP's samples; the check at the control rate
# differentiates a spline through them and lands up to about a millimetre
# elsewhere, so CHOMP stops only with that much to spare [m].
_ZMP_GUARD = 0.001

DAMPING = 1e-3
"""μ of the damped J_fB⁻¹ in the trunk pass's point Jacobians [m/rad]."""

BACKENDS = ("auto", "rust", "python")


def compiled_field(sdf: Any) -> _core.SdfField | None:
    """The Rust core's field behind a :class:`~roughwalk.terrain.SignedDistanceField`, if any."""
    # The terrain wing keeps its compiled field private; reading it here spares
    # a copy of the voxels per pass, and duck-typed test fields simply have none.
    core = getattr(sdf, "_core", None)
    return core if isinstance(core, _core.SdfField) else None


def resolve_backend(backend: str, sdf: Any) -> str:
    """``"rust"`` or ``"python"`` for a requested backend and a field."""
    if backend not in BACKENDS:
        raise InvalidArgumentError(
            f"unknown CHOMP pass backend {backend!r}; known: {', '.join(BACKENDS)}"
        )
    if backend == "python":
        return backend
    if compiled_field(sdf) is None:
        if backend == "rust":
            raise InvalidArgumentError(
                "the rust backend needs a compiled SignedDistanceField, "
                f"got {type(sdf).__name__}; use backend='python'"
            )
        return "python"
    return "rust"


def clearance_ok(
    clearance: NDArray[np.float64],
    active: NDArray[np.bool_],
    points: NDArray[np.float64],
    is_foot: NDArray[np.bool_],
    footholds: NDArray[np.float64],
    validity: ValidityConfig,
    contact_clearance: float = 0.0,
) -> bool:
    """Whether active points (T, U) at ``points`` (T, U, 3) keep the clearance asked for.

    ``footholds`` (K, 3) are the lifted foot's start and target and
    ``contact_clearance`` [m] its clearance on them
    (:meth:`ValidityConfig.required_clearance`).
    """
    need = validity.required_clearance(points, is_foot, footholds, contact_clearance)
    return bool(np.all((clearance >= need) | ~active))


def velocity_excess(q: NDArray[np.float64], dt: float, limit: NDArray[np.float64]) -> float:
    """Σ max(0, |Δq| − v·dt) [rad] of joint angles (T, ...) sampled every ``dt`` [s].

    ``limit`` (...) holds the velocity limits [rad/s].
    """
    return float(np.sum(np.maximum(np.abs(np.diff(q, axis=0)) - limit[None] * dt, 0.0)))


def velocity_ok(q: NDArray[np.float64], dt: float, limit: NDArray[np.float64]) -> bool:
    """Whether joint angles (T, 4, 3) sampled every ``dt`` [s] keep to ``limit`` (4, 3) [rad/s]."""
    return velocity_excess(q, dt, limit) == 0.0


class BodyPass:
    """The trunk block of one footstep's CHOMP: :meth:`evaluate` for :class:`Chomp`.

    Parameters
    ----------
    wb:
        Batched kinematics (with the body points).
    state:
        The footstep's current trajectory; read, and written by :meth:`apply`.
    obstacle:
        The obstacle term over ``wb.points``.
    config, validity:
        Weights and the feasibility thresholds.
    gravity:
        g [m/s²] of the ZMP.
    reference:
        The interior trunk path (n, 6) whose changes the smoothness term
        penalises (default: the state's current one).
    backend:
        ``"auto"``, ``"rust"`` or ``"python"`` (module docstring).
    damping:
        μ [m/rad] of the damped J_fB⁻¹ that carries the supporting legs'
        points with the trunk (a straight leg must not blow it up); the
        gradient is exact as μ → 0.
    """

    def __init__(
        self,
        wb: WholeBody,
        state: FootstepState,
        obstacle: ObstacleCost,
        config: ChompConfig,
        validity: ValidityConfig,
        gravity: float = 9.81,
        reference: NDArray[np.float64] | None = None,
        backend: str = "auto",
        damping: float = DAMPING,
    ) -> None:
        self.wb = wb
        self.damping = float(damping)
        self.state = state
        self.obstacle = obstacle
        self.config = config
        self.validity = validity
        t = state.n_samples
        self.h = 1.0 / (t - 1)
        r2 = config.rotation_scale**2
        # The trunk is held where the swing leg changes hands between IK and
        # its own joint angles (lift-off, touchdown), so the leg stays continuous.
        fixed = np.zeros(t - 2, dtype=bool)
        for k in (state.lift_off, state.touchdown):
            if 0 < k < t - 1:
                fixed[k - 1] = True
        self.smoothness = Smoothness(
            state.body[1:-1] if reference is None else reference,
            config.smoothness_order,
            config.smoothness_weight,
            [1, 1, 1, r2, r2, r2],
            fixed=fixed,
        )
        self.support_cost = ZmpSupportCost(
            state.polygons,
            state.polygon_index,
            state.com_offset[:, :2],
            state.com_offset_acceleration[:, :2],
            state.com_height,
            state.dt,
            config.zmp_margin,
            config.support_weight * self.h,
            gravity,
        )
        pts = wb.points
        leg = np.maximum(pts.leg, 0)
        foot_down = pts.is_foot[None, :] & state.support[:, leg]
        self.active = ~foot_down
        self.held_q = state.q.copy()
        self.footholds = np.array([state.step.start, state.step.target])
        self.hips = wb.hips
        self.backend = resolve_backend(backend, obstacle.sdf)
        self._rust: _core.BodyPassEvaluator | None = None
        field = compiled_field(obstacle.sdf)
        if field is not None and self.backend == "rust":
            self._rust = _core.BodyPassEvaluator(
                wb.core,
                field,
                pts.leg,
                pts.link,
                pts.local,
                pts.radius,
                pts.is_foot,
                state.body,
                state.feet,
                state.support,
                self.held_q,
                self.active,
                self.hips,
                wb.max_reach,
                wb.velocity_limit,
                [np.asarray(p, dtype=float)[:, :2] for p in state.polygons],
                state.polygon_index,
                state.com_offset[:, :2],
                state.com_offset_acceleration[:, :2],
                dt=state.dt,
                reach_margin=config.reach_margin,
                reach_weight=config.reachability_weight * self.h,
                damping=self.damping,
                zmp_k=state.com_height / gravity,
                zmp_margin=config.zmp_margin,
                support_weight=config.support_weight * self.h,
                obstacle_epsilon=obstacle.epsilon,
                obstacle_weight=obstacle.weight,
                gradient=obstacle.mode,
            )

    def configure(
        self, xi: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
        """Full trunk path (T, 6), rotations (T, 3, 3), joint angles (T, 4, 3), reached (T, 4)."""
        s = self.state
        body = s.body.copy()
        body[1:-1] = xi
        rot = rpy_to_matrix(body[:, 3:])
        feet_b = np.einsum("tji,tlj->tli", rot, s.feet - body[:, None, :3])
        # A lifted leg keeps its angles: spare IK its (maybe unreachable) target.
        feet_b = np.where(s.support[..., None], feet_b, self.wb.nominal_feet[None])
        q_ik, reached = self.wb.inverse_kinematics(feet_b)
        q = np.where(s.support[..., None], q_ik, self.held_q)
        reached = reached | ~s.support
        return body, rot, q, reached

    def reach_errors(
        self, body: NDArray[np.float64], rot: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Reach errors e = f′ − FK(IK(f′)) (T, 4, 3) [m, world].

        f′ is the foot target pushed ``reach_margin`` away from its hip.

        Asking for a slightly longer leg makes the term act before a foot is
        lost (a plain ½‖e‖² penalty settles slightly outside the
        workspace); its gradient is the §3.2 virtual force.
        """
        s = self.state
        feet_b = np.einsum("tji,tlj->tli", rot, s.feet - body[:, None, :3])
        towards = feet_b - self.hips[None]
        dist = np.linalg.norm(towards, axis=-1, keepdims=True)
        pushed = feet_b + self.config.reach_margin * towards / np.maximum(dist, 1e-9)
        error_b = np.zeros_like(pushed)
        # Pushing outward only matters near full stretch: solve only those samples.
        near = np.flatnonzero(np.any(dist[..., 0] > 0.93 * self.wb.max_reach[None, :], axis=1))
        if near.size:
            q, reached = self.wb.inverse_kinematics(pushed[near])
            # A reached target has no error; forward kinematics only where one is missed.
            missed = ~reached.all(axis=1)
            if np.any(missed):
                rows = near[missed]
                error_b[rows] = pushed[rows] - self.wb.foot_positions(q[missed])
                error_b[rows] *= ~reached[missed][..., None]
        return np.einsum("tij,tlj->tli", rot, error_b)

    def evaluate(self, xi: NDArray[np.float64]) -> Evaluation:
        """Obstacle + reachability + support terms and their gradient (n, 6) at ξ."""
        if self._rust is not None:
            return self._evaluate_rust(xi)
        return self.evaluate_python(xi)

    def _feasible(
        self,
        lost: float,
        excess: float,
        clearance: NDArray[np.float64],
        points: NDArray[np.float64],
        margins: NDArray[np.float64],
    ) -> bool:
        return (
            lost == 0
            and excess == 0.0
            and clearance_ok(
                clearance,
                self.active,
                points,
                self.wb.points.is_foot,
                self.footholds,
                self.validity,
                self.state.contact_clearance,
            )
            and bool(np.all(margins >= _ZMP_GUARD - self.validity.zmp_tolerance))
        )

    def _evaluate_rust(self, xi: NDArray[np.float64]) -> Evaluation:
        assert self._rust is not None
        r = self._rust.evaluate(np.ascontiguousarray(xi, dtype=float))
        lost = float(np.sum(~r["reached"]))
        excess = float(r["velocity_excess"])
        parts = {k: float(r[k]) for k in ("obstacle", "reachability", "support")}
        return Evaluation(
            value=parts["obstacle"] + parts["reachability"] + parts["support"],
            gradient=r["gradient"],
            parts=parts,
            feasible=self._feasible(lost, excess, r["clearance"], r["points"], r["margins"]),
            violation=lost + excess,
        )

    def evaluate_python(self, xi: NDArray[np.float64]) -> Evaluation:
        """:meth:`evaluate` in numpy: the reference of the Rust evaluation."""
        s = self.state
        wb = self.wb
        body, rot, q, reached = self.configure(xi)
        frames = wb.link_frames(q)
        p_b, feet_b = wb.points_base(q, frames)
        points = body[:, None, :3] + np.einsum("tij,tuj->tui", rot, p_b)
        obs = self.obstacle.evaluate(points, self.active)
        ti, ui = ObstacleCost.gradient_pairs(obs.workspace_gradient)
        jac = wb.body_pass_jacobians_at(
            q, frames, p_b, feet_b, rot, body[:, 3:], s.support, ti + 1, ui, self.damping
        )
        n = body.shape[0] - 2
        grad = ObstacleCost.to_coordinates(obs.workspace_gradient, jac, ti, ui, n)

        errors = self.reach_errors(body, rot)
        inner = slice(1, -1)
        reach_value, reach_grad = reachability_cost(
            errors[inner],
            s.feet[inner],
            body[inner, :3],
            rpy_rate_matrix(body[inner, 3:]),
            s.support[inner],
            self.config.reachability_weight * self.h,
        )
        grad += reach_grad
        sup_value, sup_grad, margins = self.support_cost.evaluate(body[:, :2])
        grad[:, :2] += sup_grad
        excess = velocity_excess(q, s.dt, self.wb.velocity_limit)
        lost = float(np.sum(~reached))
        feasible = self._feasible(lost, excess, obs.clearance, points, margins)
        return Evaluation(
            value=obs.value + reach_value + sup_value,
            gradient=grad,
            parts={"obstacle": obs.value, "reachability": reach_value, "support": sup_value},
            feasible=feasible,
            violation=lost + excess,
        )

    def apply(self, xi: NDArray[np.float64]) -> None:
        """Write the optimised trunk path into the state (legs re-solved, swing foot carried)."""
        s = self.state
        body, rot, q, reached = self.configure(xi)
        s.body = body
        s.q = q
        s.reached = reached
        s.update_com_offset(self.wb)
        airborne = ~s.support
        if np.any(airborne):
            feet_w = body[:, None, :3] + np.einsum("tij,tlj->tli", rot, self.wb.foot_positions(q))
            s.feet = np.where(airborne[..., None], feet_w, s.feet)

    def feasible_without_leg(self, leg: int) -> bool:
        """Whether all but leg ``leg``'s points and joints is feasible at the current state."""
        s = self.state
        body, rot, q, reached = self.configure(s.body[1:-1])
        p_b, _ = self.wb.points_base(q)
        points = body[:, None, :3] + np.einsum("tij,tuj->tui", rot, p_b)
        d, _ = self.obstacle.clearance(points)
        others = self.wb.points.leg != leg
        active = self.active & others[None, :]
        margins = self.support_cost.margins(self.support_cost.zmp(body[:, :2]))[0]
        keep = np.arange(4) != leg
        return (
            bool(np.all(reached))
            and clearance_ok(
                d,
                active,
                points,
                self.wb.points.is_foot,
                self.footholds,
                self.validity,
                s.contact_clearance,
            )
            and bool(np.all(margins >= _ZMP_GUARD - self.validity.zmp_tolerance))
            and velocity_ok(q[:, keep], s.dt, self.wb.velocity_limit[keep])
        )
