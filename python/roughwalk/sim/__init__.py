"""Simulation: MuJoCo world, controllers, executor and evaluation (Zucker 2011, §6).

Start with :func:`run` (a robot, a terrain, a start and a goal in; a
:class:`RunResult` out). The pieces are usable alone: :class:`World` (robot
+ terrain in one MuJoCo model), :class:`Runner` (servo commands at the
control rate), :class:`TrajectoryBuffer`, :class:`JointController`,
:class:`LegIntegrator`, :class:`LiftGate`, :class:`CopStabilizer`, :class:`ReflexMonitor`,
:class:`Executor`, :class:`OutcomeMonitor`, :class:`RunLog` and the disturbances.
"""

from roughwalk.sim.config import (
    ContactConfig,
    ControllerConfig,
    ExecutorConfig,
    IntegratorConfig,
    LiftGateConfig,
    OutcomeConfig,
    ReflexConfig,
    SimConfig,
    StabilizerConfig,
    TouchdownConfig,
    WorldConfig,
)
from roughwalk.sim.cop_stabilizer import CopStabilizer, centre_of_pressure
from roughwalk.sim.disturbances import FrictionDrop, MapError, Push, parse_disturbance
from roughwalk.sim.executor import Executor
from roughwalk.sim.footstep_source import (
    CrawlSource,
    FootstepSource,
    PlanAttempt,
    PlannerSource,
    PlanStart,
    default_source,
)
from roughwalk.sim.joint_controller import JointController
from roughwalk.sim.leg_integrator import LegIntegrator
from roughwalk.sim.lift_gate import LiftGate
from roughwalk.sim.measured_state import MeasuredState, measure
from roughwalk.sim.outcome import Outcome, OutcomeMonitor
from roughwalk.sim.reflexes import ReflexMonitor, ReflexTrigger
from roughwalk.sim.run import RunResult, run, sim_config
from roughwalk.sim.run_log import RunLog
from roughwalk.sim.runner import Runner, ServoCommand
from roughwalk.sim.trajectory_buffer import DesiredState, Segment, TrajectoryBuffer
from roughwalk.sim.world import World

__all__ = [
    "run",
    "RunResult",
    "sim_config",
    "SimConfig",
    "WorldConfig",
    "ContactConfig",
    "ControllerConfig",
    "IntegratorConfig",
    "StabilizerConfig",
    "TouchdownConfig",
    "LiftGateConfig",
    "ReflexConfig",
    "OutcomeConfig",
    "ExecutorConfig",
    "World",
    "Runner",
    "ServoCommand",
    "MeasuredState",
    "measure",
    "TrajectoryBuffer",
    "Segment",
    "DesiredState",
    "JointController",
    "LegIntegrator",
    "LiftGate",
    "CopStabilizer",
    "centre_of_pressure",
    "ReflexMonitor",
    "ReflexTrigger",
    "Executor",
    "Outcome",
    "OutcomeMonitor",
    "RunLog",
    "FootstepSource",
    "CrawlSource",
    "PlannerSource",
    "PlanStart",
    "PlanAttempt",
    "default_source",
    "Push",
    "FrictionDrop",
    "MapError",
    "parse_disturbance",
]
