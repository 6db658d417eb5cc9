"""Full-body footstep trajectories: ZMP preview, swing splines and CHOMP (Zucker 2011, §5).

Start with :func:`footstep_trajectories` (a footstep plan in,
:class:`FootstepTrajectories` out), or drive the per-step pipeline yourself
with :class:`FootstepTrajectoryGenerator`. The pieces are usable alone:
:class:`ZmpPreviewController` (cart-table preview control), :class:`ZmpReference`,
:class:`SwingSpline`, :class:`BodySpline`, :func:`step_timing`, and
:class:`Chomp` with the terms in :mod:`roughwalk.trajectories.costs`.
"""

from roughwalk.trajectories.api import (
    FootstepTrajectories,
    footstep_trajectories,
    trajectory_config,
)
from roughwalk.trajectories.body_spline import BodySpline
from roughwalk.trajectories.chomp import Chomp, ChompResult, ChompStatus, Evaluation
from roughwalk.trajectories.config import (
    ChompConfig,
    SwingConfig,
    TimingConfig,
    TrajectoryConfig,
    ValidityConfig,
    ZmpConfig,
)
from roughwalk.trajectories.crawl_plan import straight_crawl_plan
from roughwalk.trajectories.footstep_trajectory import FootstepTrajectory
from roughwalk.trajectories.generator import FootstepTrajectoryGenerator
from roughwalk.trajectories.step_report import StepReport
from roughwalk.trajectories.swing_spline import SwingSpline
from roughwalk.trajectories.timing import StepTiming, step_timing
from roughwalk.trajectories.whole_body import WholeBody
from roughwalk.trajectories.zmp_preview import ZmpPreviewController
from roughwalk.trajectories.zmp_reference import ZmpReference, shortcut_anchor

__all__ = [
    "footstep_trajectories",
    "FootstepTrajectories",
    "FootstepTrajectory",
    "FootstepTrajectoryGenerator",
    "StepReport",
    "trajectory_config",
    "TrajectoryConfig",
    "TimingConfig",
    "ZmpConfig",
    "SwingConfig",
    "ChompConfig",
    "ValidityConfig",
    "ZmpPreviewController",
    "ZmpReference",
    "shortcut_anchor",
    "SwingSpline",
    "BodySpline",
    "StepTiming",
    "step_timing",
    "Chomp",
    "ChompResult",
    "ChompStatus",
    "Evaluation",
    "WholeBody",
    "straight_crawl_plan",
]
