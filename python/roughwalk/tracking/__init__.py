"""Whole-body tracking of optimised motions in MuJoCo (Melon et al. 2020, §V).

Start with :func:`track`: it executes a :class:`~roughwalk.trajopt.TrajoptResult`
(or the JSON ``roughwalk optimize --json`` writes) on the robot in physics
with a 400 Hz whole-body QP controller and says whether the motion was
trackable (:class:`TrackingOutcome`).
"""

from roughwalk.tracking.config import (
    ContactStateConfig,
    TaskWeights,
    TrackingConfig,
    TrackingGains,
)
from roughwalk.tracking.contact_state import ContactEstimate, ContactStateMachine, LegContact
from roughwalk.tracking.outcome import TrackingLog, TrackingOutcome
from roughwalk.tracking.reach import LegReach, reach_aware_reference
from roughwalk.tracking.reference import Reference, ReferenceSample, load_trajectory
from roughwalk.tracking.swing import SwingPlanner, SwingTrajectory
from roughwalk.tracking.tasks import LeastSquaresTask, QPLayout
from roughwalk.tracking.track import TrunkPush, execute_reference, track
from roughwalk.tracking.whole_body_qp import QPSolution, WholeBodyQP, friction_pyramid

__all__ = [
    "track",
    "execute_reference",
    "TrunkPush",
    "TrackingOutcome",
    "TrackingLog",
    "TrackingConfig",
    "TrackingGains",
    "TaskWeights",
    "ContactStateConfig",
    "ContactStateMachine",
    "ContactEstimate",
    "LegContact",
    "Reference",
    "ReferenceSample",
    "load_trajectory",
    "LegReach",
    "reach_aware_reference",
    "SwingPlanner",
    "SwingTrajectory",
    "LeastSquaresTask",
    "QPLayout",
    "WholeBodyQP",
    "QPSolution",
    "friction_pyramid",
]
