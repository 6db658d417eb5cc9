"""roughwalk: footstep, full-body and dynamic trajectories for quadrupeds on rough terrain.

The public API is re-exported here; each wing (:mod:`roughwalk.terrain`, ...)
has its own ``__init__`` with a fuller API.
"""

from roughwalk import learning  # noqa: F401  (registers the ``learned`` initialiser)
from roughwalk._core import __version__
from roughwalk.errors import (
    ConfigError,
    InvalidArgumentError,
    PlanningError,
    RobotModelError,
    RoughwalkError,
    TerrainError,
)
from roughwalk.planning.footstep_planner import plan_footsteps
from roughwalk.robots import Robot, load_robot
from roughwalk.sim.run import run
from roughwalk.terrain import Terrain, load_terrain
from roughwalk.tracking.track import track
from roughwalk.trajectories.api import footstep_trajectories
from roughwalk.trajopt import optimize_motion

__all__ = [
    "__version__",
    "RoughwalkError",
    "InvalidArgumentError",
    "TerrainError",
    "RobotModelError",
    "PlanningError",
    "ConfigError",
    "Terrain",
    "load_terrain",
    "Robot",
    "load_robot",
    "run",
    "plan_footsteps",
    "optimize_motion",
    "footstep_trajectories",
    "track",
]
