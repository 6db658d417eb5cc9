"""Planning: footstep costs learned from an expert's preferences (Zucker 2011, §4.2).

Start with :class:`TerrainCost`: ``TerrainCost.load()`` gives the cost shipped
with roughwalk; ``cost.cost_map(terrain)`` the cost of every cell. To learn
your own, collect preferences with the labelling app
(:mod:`roughwalk.planning.labeling`, or ``roughwalk cost label``) into a
:class:`PreferenceStore`, then :func:`learn_cost` (``roughwalk cost learn``).
"""

from roughwalk.planning.cost_learning import (
    CostLearningConfig,
    LearnReport,
    agreement,
    cross_validate,
    learn_cost,
)
from roughwalk.planning.footstep_config import CertificateConfig, FootstepConfig
from roughwalk.planning.footstep_cost import default_terrain_cost, hand_set_terrain_cost
from roughwalk.planning.footstep_plan import Footstep, FootstepPlan
from roughwalk.planning.footstep_planner import FootstepPlanner, plan_footsteps
from roughwalk.planning.pair_selection import (
    CandidatePair,
    PairSelectionConfig,
    PairSelector,
    feature_scale,
)
from roughwalk.planning.preference_dataset import PreferenceDataset, TerrainResolver
from roughwalk.planning.preference_store import (
    Foothold,
    Preference,
    PreferenceStore,
    PreferenceStoreError,
    TerrainRecord,
)
from roughwalk.planning.ranking_svm import RankingSvm, RankingSvmConfig, ranking_objective
from roughwalk.planning.scripted_expert import ScriptedExpert, ScriptedExpertConfig
from roughwalk.planning.terrain_cost import (
    COST_VERSION,
    LEGS,
    CostModelError,
    TerrainCost,
    default_cost_path,
)

__all__ = [
    "FootstepPlanner",
    "FootstepPlan",
    "FootstepConfig",
    "CertificateConfig",
    "Footstep",
    "plan_footsteps",
    "default_terrain_cost",
    "hand_set_terrain_cost",
    "TerrainCost",
    "CostModelError",
    "COST_VERSION",
    "LEGS",
    "default_cost_path",
    "Foothold",
    "Preference",
    "PreferenceStore",
    "PreferenceStoreError",
    "TerrainRecord",
    "PreferenceDataset",
    "TerrainResolver",
    "RankingSvm",
    "RankingSvmConfig",
    "ranking_objective",
    "CostLearningConfig",
    "LearnReport",
    "learn_cost",
    "cross_validate",
    "agreement",
    "ScriptedExpert",
    "ScriptedExpertConfig",
    "PairSelector",
    "PairSelectionConfig",
    "CandidatePair",
    "feature_scale",
]
