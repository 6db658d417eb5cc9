"""The default terrain cost shipped with roughwalk, and how it is rebuilt.

There is no human LittleDog expert at hand, so the shipped preferences come
from :class:`~roughwalk.planning.scripted_expert.ScriptedExpert` (rules on
raw geometry from Zucker 2011, §4.2, with 10 % of its judgements flipped as
label noise) on terrains from roughwalk's own generators, so that anyone can
rebuild them without any data files:

    python scripts/build_default_cost.py            # rewrites planning/data/

It follows the paper's iterate-and-relabel loop: a first round of random
pairs, then rounds of pairs the model learned so far is least sure about.
Everything is seeded, so a rebuild gives the same judgements and the same
weights.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from roughwalk.planning.cost_learning import CostLearningConfig, LearnReport, learn_cost
from roughwalk.planning.pair_selection import PairSelector
from roughwalk.planning.preference_dataset import PreferenceDataset
from roughwalk.planning.preference_store import Preference, PreferenceStore
from roughwalk.planning.scripted_expert import ScriptedExpert, ScriptedExpertConfig
from roughwalk.planning.terrain_cost import TerrainCost
from roughwalk.terrain.features import compute_features
from roughwalk.terrain.spec import load_terrain

__all__ = [
    "DEFAULT_TERRAINS",
    "DefaultCostRecipe",
    "build_default_preferences",
    "build_default_cost",
    "data_dir",
]

# LittleDog-scale courses covering every rule: rocks (domes, crevices),
# slabs (slopes), logs (domes, troughs), stones over a pit and a trench
# (chasms), steps and a barrier (edges).
DEFAULT_TERRAINS = (
    "large_rocks:seed=11",
    "round_rocks:seed=12",
    "sloped_rocks:seed=13",
    "logs:seed=14",
    "stepping_stones:seed=15",
    "gap",
    "barrier",
    "steps",
    "stairs",
)


@dataclass(frozen=True)
class DefaultCostRecipe:
    """Everything that fixes the shipped preferences and cost.

    Attributes
    ----------
    terrains:
        Generator specs to label on.
    n_random:
        Judgements of the first, random round.
    n_rounds, round_size:
        Later rounds of pairs the current model is least sure about.
    noise:
        Probability that the scripted expert's judgement is flipped.
    seed:
        Seed of the pairs, the noise and the learner.

    """

    terrains: tuple[str, ...] = DEFAULT_TERRAINS
    n_random: int = 200
    n_rounds: int = 4
    round_size: int = 50
    noise: float = 0.1
    seed: int = 2011

    @property
    def n_total(self) -> int:
        """Judgements in all."""
        return self.n_random + self.n_rounds * self.round_size


def data_dir() -> Path:
    """The package's data folder (``roughwalk/planning/data``)."""
    return Path(__file__).resolve().parent / "data"


def build_default_preferences(
    store_path: str | Path,
    recipe: DefaultCostRecipe | None = None,
    learning: CostLearningConfig | None = None,
) -> int:
    """Write the scripted expert's judgements into a new store at ``store_path``.

    The file must not exist yet. Returns the number of judgements written.
    """
    recipe = recipe or DefaultCostRecipe()
    learning = learning or CostLearningConfig(folds=0)
    terrains = {spec: load_terrain(spec) for spec in recipe.terrains}
    features = {spec: compute_features(t, radii=learning.radii) for spec, t in terrains.items()}
    selector = PairSelector(
        list(terrains.values()),
        radii=learning.radii,
        seed=recipe.seed,
        features=[features[s] for s in terrains],
    )
    expert = ScriptedExpert(ScriptedExpertConfig(noise=recipe.noise), seed=recipe.seed)
    judged: list[Preference] = []

    def judge(cost: TerrainCost | None, n: int) -> None:
        pairs = [selector.propose(cost) for _ in range(n)]
        labels = expert.judge([(p.a, p.b) for p in pairs], terrains)
        for p, label in zip(pairs, labels, strict=True):
            # Scripted rows carry their order as time, so rebuilds are identical.
            stamp = float(len(judged))
            judged.append(Preference(p.a, p.b, p.leg, label, stamp, "default", "scripted"))

    judge(None, recipe.n_random)
    for _ in range(recipe.n_rounds):
        data = PreferenceDataset.from_preferences(judged, features, oriented=learning.oriented)
        cost, _ = learn_cost(data, learning)
        judge(cost, recipe.round_size)
    with PreferenceStore.open(store_path, create=True) as store:
        if store.count():
            raise FileExistsError(f"'{store_path}' already holds judgements; give a new path")
        for t in terrains.values():
            store.add_terrain(t)
        store.add_many(judged)
        return store.count()


def build_default_cost(
    store_path: str | Path,
    cost_path: str | Path,
    learning: CostLearningConfig | None = None,
) -> tuple[TerrainCost, LearnReport]:
    """Learn the cost from the store at ``store_path`` and save it at ``cost_path``."""
    learning = learning or CostLearningConfig()
    with PreferenceStore.open(store_path, readonly=True) as store:
        data = PreferenceDataset.from_store(store, learning.radii, oriented=learning.oriented)
    meta: dict[str, Any] = {
        "source": "scripted expert (roughwalk.planning.scripted_expert) on generated terrains; "
        "rebuild with `python scripts/build_default_cost.py`",
        "preferences": Path(store_path).name,
        "built": time.strftime("%Y-%m-%d"),
    }
    cost, report = learn_cost(data, learning, metadata=meta)
    cost.save(cost_path)
    return cost, report
