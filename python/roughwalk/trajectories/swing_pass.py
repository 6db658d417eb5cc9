"""CHOMP's second coordinate block: the swing leg's joint angles (Zucker 2011, §5.3).

"Second, the swing leg joint angles are optimized with CHOMP given the
current body poses." The variables are the swing leg's three joint angles at
the airborne samples (lift-off and touchdown fixed); its points move with
∂p/∂q = R·J_pB. Updates are clamped to the joint limits, and a joint-speed
term keeps the leg from dashing at its velocity limits. The backends are
those of :mod:`~roughwalk.trajectories.body_pass` (the core's
``SwingPassEvaluator``, or numpy as the reference).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roughwalk import _core
from roughwalk.trajectories.body_pass import (
    clearance_ok,
    compiled_field,
    resolve_backend,
    velocity_excess,
)
from roughwalk.trajectories.chomp import Evaluation
from roughwalk.trajectories.config import ChompConfig, ValidityConfig
from roughwalk.trajectories.costs.joint_speed import joint_speed_cost
from roughwalk.trajectories.costs.obstacle import ObstacleCost
from roughwalk.trajectories.costs.smoothness import Smoothness
from roughwalk.trajectories.initial_trajectory import FootstepState
from roughwalk.trajectories.whole_body import WholeBody

__all__ = ["SwingPass"]


class SwingPass:
    """The swing-leg block of one footstep's CHOMP: :meth:`evaluate` for :class:`Chomp`.

    Parameters
    ----------
    wb:
        Batched kinematics.
    state:
        The footstep's current trajectory; read, and written by :meth:`apply`.
    sdf:
        The terrain's signed distance field.
    config, validity:
        Weights and feasibility thresholds.
    rest_feasible:
        Whether everything except this leg is already feasible (it does not
        change here), so that the pass may stop as soon as the leg is.
    reference:
        The airborne joint angles (n, 3) whose changes the smoothness term
        penalises (default: the current ones).
    backend:
        ``"auto"``, ``"rust"`` or ``"python"``.
    """

    def __init__(
        self,
        wb: WholeBody,
        state: FootstepState,
        sdf: object,
        config: ChompConfig,
        validity: ValidityConfig,
        rest_feasible: bool,
        reference: NDArray[np.float64] | None = None,
        backend: str = "auto",
    ) -> None:
        self.wb = wb
        self.state = state
        self.leg = state.step.leg
        self.window = slice(state.lift_off, state.touchdown + 1)
        self.sel = wb.points.leg == self.leg
        self.index = np.flatnonzero(self.sel)
        self.is_foot = wb.points.is_foot[self.sel]
        self.obstacle = ObstacleCost(
            sdf,
            wb.points.radius[self.sel],
            config.obstacle_epsilon,
            config.obstacle_weight,
            config.gradient,
        )
        self.validity = validity
        self.config = config
        self.rest_feasible = rest_feasible
        self.body = state.body[self.window]
        self.rotation = state.rotation[self.window]
        self._current = state.q[state.lift_off + 1 : state.touchdown, self.leg].copy()
        self.smoothness = Smoothness(
            self._current if reference is None else reference,
            config.smoothness_order,
            config.smoothness_weight,
            [config.joint_scale**2] * 3,
        )
        self.lower = wb.lower[self.leg]
        self.upper = wb.upper[self.leg]
        t = self.body.shape[0]
        self.h = 1.0 / (t - 1)
        self.active = np.ones((t, int(self.sel.sum())), dtype=bool)
        # The foot touches down at both ends of the window.
        self.active[[0, -1]] &= ~self.is_foot[None, :]
        self.footholds = np.array([state.step.start, state.step.target])
        self.backend = resolve_backend(backend, sdf)
        self._rust: _core.SwingPassEvaluator | None = None
        field = compiled_field(sdf)
        if field is not None and self.backend == "rust":
            pts = wb.points
            q = state.q
            self._rust = _core.SwingPassEvaluator(
                wb.core,
                field,
                pts.leg,
                pts.link,
                pts.local,
                pts.radius,
                pts.is_foot,
                self.leg,
                self.body[:, :3],
                self.rotation,
                np.array([q[state.lift_off, self.leg], q[state.touchdown, self.leg]]),
                self.active,
                wb.velocity_limit[self.leg],
                dt=state.dt,
                speed_fraction=config.speed_fraction,
                speed_weight=config.speed_weight * self.h,
                obstacle_epsilon=config.obstacle_epsilon,
                obstacle_weight=config.obstacle_weight,
                gradient=config.gradient,
            )

    @property
    def initial(self) -> NDArray[np.float64]:
        """ξ₀ (n, 3): the swing leg's current airborne joint angles [rad]."""
        return self._current.copy()

    def project(self, xi: NDArray[np.float64]) -> NDArray[np.float64]:
        """Clamp joint angles to the leg's limits."""
        return np.clip(xi, self.lower, self.upper)

    def _window_q(self, xi: NDArray[np.float64]) -> NDArray[np.float64]:
        q = self.state.q[self.window].copy()
        q[1:-1, self.leg] = xi
        return q

    def evaluate(self, xi: NDArray[np.float64]) -> Evaluation:
        """Obstacle and joint-speed terms of the swing leg and their gradient (n, 3) at ξ."""
        if self._rust is None:
            return self.evaluate_python(xi)
        r = self._rust.evaluate(np.ascontiguousarray(xi, dtype=float))
        excess = float(r["velocity_excess"])
        parts = {"obstacle": float(r["obstacle"]), "joint_speed": float(r["joint_speed"])}
        return Evaluation(
            parts["obstacle"] + parts["joint_speed"],
            r["gradient"],
            parts,
            self._feasible(excess, r["clearance"], r["points"]),
            excess,
        )

    def _feasible(
        self, excess: float, clearance: NDArray[np.float64], points: NDArray[np.float64]
    ) -> bool:
        return (
            self.rest_feasible
            and excess == 0.0
            and clearance_ok(
                clearance,
                self.active,
                points,
                self.is_foot,
                self.footholds,
                self.validity,
                self.state.contact_clearance,
            )
        )

    def evaluate_python(self, xi: NDArray[np.float64]) -> Evaluation:
        """:meth:`evaluate` in numpy: the reference of the Rust evaluation."""
        q = self._window_q(xi)
        frames = self.wb.link_frames(q)
        p_b, _ = self.wb.points_base(q, frames)
        p_b = p_b[:, self.sel]
        points = self.body[:, None, :3] + np.einsum("tij,tuj->tui", self.rotation, p_b)
        obs = self.obstacle.evaluate(points, self.active)
        ti, ui = ObstacleCost.gradient_pairs(obs.workspace_gradient)
        jac = self.wb.swing_pass_jacobians_at(
            frames, p_b[ti + 1, ui], self.rotation, ti + 1, self.index[ui]
        )
        grad = ObstacleCost.to_coordinates(obs.workspace_gradient, jac, ti, ui, q.shape[0] - 2)
        speed_value, speed_grad = joint_speed_cost(
            q[:, self.leg],
            self.state.dt,
            self.wb.velocity_limit[self.leg],
            self.config.speed_fraction,
            self.config.speed_weight * self.h,
        )
        grad += speed_grad
        excess = velocity_excess(q[:, self.leg], self.state.dt, self.wb.velocity_limit[self.leg])
        return Evaluation(
            obs.value + speed_value,
            grad,
            {"obstacle": obs.value, "joint_speed": speed_value},
            self._feasible(excess, obs.clearance, points),
            excess,
        )

    def apply(self, xi: NDArray[np.float64]) -> None:
        """Write the optimised swing angles into the state (and the swing foot's path)."""
        s = self.state
        q = self._window_q(xi)
        s.q[self.window] = q
        s.update_com_offset(self.wb)
        foot_b = self.wb.foot_positions(q)[:, self.leg]
        inner = slice(s.lift_off + 1, s.touchdown)
        s.feet[inner, self.leg] = self.body[1:-1, :3] + np.einsum(
            "tij,tj->ti", self.rotation[1:-1], foot_b[1:-1]
        )
