"""``roughwalk.footstep_trajectories``: a footstep plan in, full-body trajectories out."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roughwalk.config import override, to_dict
from roughwalk.errors import ConfigError, PlanningError
from roughwalk.trajectories.config import TrajectoryConfig
from roughwalk.trajectories.footstep_trajectory import FootstepTrajectory
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator
from roughwalk.trajectories.step_sequence import plan_fields

__all__ = ["footstep_trajectories", "FootstepTrajectories", "trajectory_config"]


@dataclass(frozen=True)
class FootstepTrajectories:
    """The trajectories of every footstep of a plan, in execution order.

    Attributes
    ----------
    robot:
        The robot's name.
    terrain:
        The terrain's spec (rebuilds it with :func:`roughwalk.load_terrain`).
    joint_names:
        The order of the joint columns.
    joint_velocity_limit:
        (12,) the robot's joint speed limits [rad/s], same order.
    steps:
        One :class:`FootstepTrajectory` per footstep.
    config:
        The settings used.
    total_ms:
        Wall time of the whole generation [ms].
    """

    robot: str
    terrain: str | None
    joint_names: tuple[str, ...]
    joint_velocity_limit: NDArray[np.float64]
    steps: list[FootstepTrajectory]
    config: TrajectoryConfig
    total_ms: float

    @property
    def valid_fraction(self) -> float:
        """Share of footsteps whose trajectory is valid (0 … 1)."""
        return float(np.mean([s.valid for s in self.steps])) if self.steps else 0.0

    @property
    def duration_s(self) -> float:
        """Time from the first sample to the last [s]."""
        return float(self.steps[-1].time[-1] - self.steps[0].time[0]) if self.steps else 0.0

    def sampled(self) -> dict[str, NDArray[Any]]:
        """Every footstep's arrays joined in time (shared boundary samples kept once).

        Adds ``step`` (n,), the footstep each sample belongs to.
        """
        if not self.steps:
            return {}
        parts: dict[str, list[NDArray[Any]]] = {}
        for k, s in enumerate(self.steps):
            arrays = s.arrays()
            arrays["step"] = np.full(s.time.shape[0], s.step, dtype=np.int64)
            for name, a in arrays.items():
                parts.setdefault(name, []).append(a if k == 0 else a[1:])
        return {name: np.concatenate(chunks) for name, chunks in parts.items()}

    def save_npz(self, path: str | Path) -> Path:
        """Write :meth:`sampled` and the joint names to ``path`` (.npz); returns the path."""
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        arrays: dict[str, Any] = {"joint_names": np.array(self.joint_names), **self.sampled()}
        with p.open("wb") as f:
            np.savez_compressed(f, **arrays)
        return p

    def summary(self) -> dict[str, Any]:
        """JSON-ready: ``steps`` (the per-step reports), ``valid_fraction`` and context."""
        return {
            "steps": [s.report.to_dict() for s in self.steps],
            "valid_fraction": self.valid_fraction,
            "duration_s": self.duration_s,
            "total_ms": self.total_ms,
            "joint_names": list(self.joint_names),
            "config": to_dict(self.config),
        }


def trajectory_config(config: TrajectoryConfig | None = None, **overrides: Any) -> TrajectoryConfig:
    """A :class:`TrajectoryConfig` with dotted-key ``overrides`` applied."""
    base = config if config is not None else TrajectoryConfig()
    if not isinstance(base, TrajectoryConfig):
        raise ConfigError(f"config must be a TrajectoryConfig, got {type(base).__name__}")
    return override(base, overrides) if overrides else base


def footstep_trajectories(
    plan: Any,
    *,
    robot: Any = None,
    terrain: Any = None,
    sdf: Any = None,
    config: TrajectoryConfig | None = None,
    **overrides: Any,
) -> FootstepTrajectories:
    """Smooth, dynamically stable, collision-free full-body trajectories of a footstep plan.

    Zucker 2011, §5: per footstep, a ZMP preview controller for the trunk,
    splines for the swing foot and the trunk's height and orientation, IK for
    the legs, then CHOMP against the terrain's signed distance field, with
    longer durations on restart; steps that stay infeasible are marked and
    kept.

    Parameters
    ----------
    plan:
        A footstep plan: the planner's ``FootstepPlan``, its JSON (a dict or
        a path to the file ``roughwalk plan`` wrote), with ``footsteps``
        (initial stance first) and, ideally, ``certificates``.
    robot:
        A :class:`~roughwalk.Robot` or a name; default the plan's.
    terrain:
        A :class:`~roughwalk.Terrain` or a spec; default the plan's.
    sdf:
        A prebuilt :class:`~roughwalk.terrain.SignedDistanceField` of the terrain.
    config:
        Settings; ``overrides`` change single fields by dotted key
        (``**{"chomp.max_iterations": 20}``) or by sub-config dict
        (``chomp={"max_iterations": 20}``).

    Returns
    -------
    :class:`FootstepTrajectories`; raises :class:`PlanningError` for a plan
    that cannot be read and :class:`ConfigError` for a bad setting.
    """
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain

    cfg = trajectory_config(config, **overrides)
    fields = plan_fields(plan)
    robot_obj = robot if robot is not None else fields["robot"]
    if robot_obj is None:
        raise PlanningError("the plan names no robot; pass robot=")
    if isinstance(robot_obj, str):
        robot_obj = load_robot(robot_obj)
    terrain_obj = terrain if terrain is not None else fields["terrain"]
    if terrain_obj is None and sdf is None:
        raise PlanningError("the plan names no terrain; pass terrain= (or sdf=)")
    if isinstance(terrain_obj, str | Path):
        terrain_obj = load_terrain(terrain_obj)
    began = time.perf_counter()
    gen = FootstepTrajectoryGenerator(robot_obj, terrain_obj, sdf=sdf, config=cfg)
    # Reading the plan first reports a bad one before the SDF is built.
    steps = list(gen.iter_steps(gen.prepare(plan)))
    spec = getattr(gen.terrain, "spec", None)
    return FootstepTrajectories(
        robot=robot_obj.name,
        terrain=spec if isinstance(spec, str) else None,
        joint_names=tuple(robot_obj.joint_names),
        joint_velocity_limit=np.asarray(robot_obj.joint_velocity_limit, dtype=float),
        steps=steps,
        config=cfg,
        total_ms=(time.perf_counter() - began) * 1000.0,
    )
