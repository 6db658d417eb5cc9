"""``roughwalk.run``: plan, optimise and walk a robot to a goal in MuJoCo; :class:`RunResult`."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from roughwalk.config import override, to_dict
from roughwalk.errors import ConfigError, InvalidArgumentError
from roughwalk.sim.config import SimConfig
from roughwalk.sim.disturbances import Disturbance
from roughwalk.sim.executor import Executor, ProgressCallback
from roughwalk.sim.footstep_source import (
    CrawlSource,
    FootstepSource,
    default_source,
    planner_config,
    split_footstep_settings,
)
from roughwalk.sim.outcome import Outcome
from roughwalk.sim.run_log import RunLog

__all__ = ["run", "RunResult", "sim_config"]


@dataclass
class RunResult:
    """A finished run: its :class:`Outcome`, its :class:`RunLog` and the plans it walked.

    ``to_dict`` gives the JSON fields ``roughwalk run --json`` writes:
    success, reason, distance_m, time_s, speed_cm_s, reflexes, replans and
    the rest of the outcome, with what was run.
    """

    outcome: Outcome
    log: RunLog
    robot: str
    terrain: str
    start: tuple[float, float, float]
    goal: tuple[float, float]
    source: str
    plans: list[Any] = field(default_factory=list)
    config: SimConfig = field(default_factory=SimConfig)
    files: dict[str, str] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """Reached the goal without falling."""
        return self.outcome.success

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        out: dict[str, Any] = dict(self.outcome.to_dict())
        out.update(
            robot=self.robot,
            terrain=self.terrain,
            start=list(self.start),
            goal=list(self.goal),
            planner=self.source,
            disturbances=self.log.meta.get("disturbances", []),
            files=dict(self.files),
        )
        return _finite(out)

    def save(self, out_dir: str | Path, stem: str = "run") -> dict[str, Path]:
        """Write the log (``STEM.npz`` + ``STEM.json``) and ``result.json`` into ``out_dir``."""
        d = Path(out_dir)
        d.mkdir(parents=True, exist_ok=True)
        npz, js = self.log.save(d / stem)
        self.files.update(log=js.name, arrays=npz.name)
        result = d / "result.json"
        result.write_text(json.dumps(self.to_dict(), indent=2) + "\n")
        return {"log": js, "arrays": npz, "result": result}


def _finite(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def sim_config(config: SimConfig | None = None, **overrides: Any) -> SimConfig:
    """A :class:`SimConfig` with dotted-key ``overrides`` applied."""
    base = config if config is not None else SimConfig()
    if not isinstance(base, SimConfig):
        raise ConfigError(f"config must be a SimConfig, got {type(base).__name__}")
    return override(base, overrides) if overrides else base


def _pose(value: Sequence[float], n: int, what: str) -> tuple[float, ...]:
    try:
        a = [float(v) for v in value]
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"{what} must be {n} numbers, got {value!r}") from None
    if len(a) == n - 1 and n == 3:
        a.append(0.0)
    if len(a) != n or not all(math.isfinite(v) for v in a):
        raise InvalidArgumentError(f"{what} must be {n} finite numbers, got {value!r}")
    return tuple(a)


def run(
    robot: Any,
    terrain: Any,
    start: Sequence[float],
    goal: Sequence[float],
    *,
    planner: str | FootstepSource = "auto",
    config: SimConfig | None = None,
    trajectory_config: Any = None,
    disturbances: Sequence[Disturbance] = (),
    progress: ProgressCallback | None = None,
    **overrides: Any,
) -> RunResult:
    """Walk ``robot`` over ``terrain`` from ``start`` to ``goal`` in MuJoCo (Zucker 2011, §6).

    Parameters
    ----------
    robot:
        A :class:`~roughwalk.Robot` or a registered name ("littledog").
    terrain:
        A :class:`~roughwalk.Terrain` or a spec ("large_rocks:seed=3").
    start:
        Trunk pose (x [m], y [m], yaw [rad]) at the start; yaw defaults to 0.
    goal:
        (x, y) [m] for the feet's centroid.
    planner:
        "auto" (the footstep planner if installed, else the blind crawl),
        "planner", "crawl", or a :class:`~roughwalk.sim.footstep_source.FootstepSource`.
    config:
        Simulation settings; ``overrides`` change fields by dotted key
        (``**{"reflex.enabled": False}``), and keys prefixed ``footstep.``
        the footstep planner's (``**{"footstep.edge_drop": 0.03}``).
    trajectory_config:
        Settings of trajectory generation (:class:`~roughwalk.trajectories.TrajectoryConfig`).
    disturbances:
        Pushes, friction drops, map errors (:mod:`roughwalk.sim.disturbances`).
    progress:
        Called with (sim time [s], progress 0–1, mode) every simulated 0.1 s.

    Returns
    -------
    :class:`RunResult`; a fall or a failed plan is a result with
    ``success=False`` and its reason, not an exception.
    """
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain

    overrides, footstep = split_footstep_settings(overrides)
    cfg = sim_config(config, **overrides)
    robot_obj = load_robot(robot) if isinstance(robot, str | Path) else robot
    terrain_obj = load_terrain(terrain) if isinstance(terrain, str | Path) else terrain
    start_pose = _pose(start, 3, "start")
    goal_xy = _pose(goal, 2, "goal")
    seen = terrain_obj
    for d in disturbances:
        seen = d.planner_terrain(seen)
    budget = cfg.executor.plan_expansions or None
    options: dict[str, Any] = {
        "expansions": budget,
        "start_snap_m": cfg.executor.start_snap_m,
        "start_max_slope": cfg.executor.start_max_slope,
    }
    options["config"] = planner_config(robot_obj, cfg.executor.longest_step, footstep)
    relax = cfg.executor.relax_edge_margin
    walk = options["config"]
    if relax != "none" and walk.edge_margin > 0 and walk.edge_drop > 0:
        options["fallback"] = replace(walk, edge_margin=0.0)
        options["fallback_from_pose"] = relax == "all"
    if isinstance(planner, str):
        if planner == "auto":
            source: FootstepSource = default_source(robot_obj, seen, **options)
        elif planner == "crawl":
            source = CrawlSource(robot_obj, seen)
        elif planner == "planner":
            from roughwalk.sim.footstep_source import PlannerSource

            source = PlannerSource(robot_obj, seen, **options)
        else:
            raise InvalidArgumentError(f"unknown planner {planner!r}; known: auto, planner, crawl")
    else:
        source = planner
    executor = Executor(
        robot_obj,
        terrain_obj,
        source,
        config=cfg,
        planner_terrain=seen,
        trajectory_config=trajectory_config,
        disturbances=disturbances,
        progress=progress,
    )
    outcome = executor.run((start_pose[0], start_pose[1], start_pose[2]), goal_xy)
    executor.log.meta["config"] = to_dict(cfg)
    return RunResult(
        outcome=outcome,
        log=executor.log,
        robot=robot_obj.name,
        terrain=terrain_obj.spec,
        start=(start_pose[0], start_pose[1], start_pose[2]),
        goal=(goal_xy[0], goal_xy[1]),
        source=source.name,
        plans=executor.plans,
        config=cfg,
    )
