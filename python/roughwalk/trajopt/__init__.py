"""Dynamic trajectory optimisation: TOWR's phase-based NLP with Melon et al.'s costs.

Start with :func:`optimize_motion`. The NLP is gathered from small parts —
``variables/``, ``constraints/``, ``costs/``, one per file — by
:class:`Formulation`, solved by IPOPT through CasADi (:class:`TrajoptSolver`)
and returned as a :class:`TrajoptResult` whose splines can be sampled at any
rate. :class:`TrajoptProblem` builds an NLP once and solves many tasks.
"""

from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.friction_demand import FrictionDemand, friction_demand, required_friction
from roughwalk.trajopt.gaits import GAIT_NAMES, ContactSchedule, make_gait, valid_step_counts
from roughwalk.trajopt.implied_torques import ImpliedTorques, implied_torques, plan_joint_torques
from roughwalk.trajopt.initializers import (
    FootstepsInitializer,
    HeuristicInitializer,
    Initializer,
    initializer_names,
    make_initializer,
    register_initializer,
)
from roughwalk.trajopt.optimize import TrajoptProblem, clear_cache, optimize_motion
from roughwalk.trajopt.parameters import (
    CostWeights,
    GuessProjection,
    IntegralCost,
    SolverOptions,
    TerrainModelConfig,
    TrajoptConfig,
    melon_config,
    towr_config,
)
from roughwalk.trajopt.result import TrajoptResult
from roughwalk.trajopt.robot_model import (
    TOWR_ANYMAL,
    SingleRigidBody,
    rigid_body_from_robot,
    rigid_body_model,
)
from roughwalk.trajopt.solver import IterationInfo, TrajoptSolver, TrajoptStatus
from roughwalk.trajopt.task import Task, parse_pose
from roughwalk.trajopt.terrain_model import TerrainModel

__all__ = [
    "optimize_motion",
    "TrajoptProblem",
    "TrajoptResult",
    "TrajoptStatus",
    "IterationInfo",
    "Task",
    "parse_pose",
    "TrajoptConfig",
    "CostWeights",
    "GuessProjection",
    "IntegralCost",
    "SolverOptions",
    "TerrainModelConfig",
    "melon_config",
    "towr_config",
    "SingleRigidBody",
    "TOWR_ANYMAL",
    "rigid_body_from_robot",
    "rigid_body_model",
    "ContactSchedule",
    "GAIT_NAMES",
    "make_gait",
    "valid_step_counts",
    "TerrainModel",
    "Formulation",
    "TrajoptSolver",
    "Initializer",
    "HeuristicInitializer",
    "FootstepsInitializer",
    "make_initializer",
    "register_initializer",
    "initializer_names",
    "clear_cache",
    "ImpliedTorques",
    "implied_torques",
    "FrictionDemand",
    "friction_demand",
    "required_friction",
    "plan_joint_torques",
]
