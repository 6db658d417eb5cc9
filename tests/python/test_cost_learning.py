"""The cost learner against a synthetic expert it never sees; the ranking SVM against SLSQP.

The expert (:class:`ScriptedExpert`) judges raw heights by rules (slopes,
domes, dimples, shin traps, chasms) that are not linear in the learner's
quadratic-fit features; the learner only sees its noisy labels.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.stats import spearmanr

from roughwalk.planning import (
    CandidatePair,
    CostLearningConfig,
    Foothold,
    PairSelector,
    Preference,
    PreferenceDataset,
    RankingSvm,
    RankingSvmConfig,
    ScriptedExpert,
    ScriptedExpertConfig,
    TerrainCost,
    agreement,
    learn_cost,
    ranking_objective,
)
from roughwalk.planning.cost_learning import feature_mask, with_seed
from roughwalk.terrain import Terrain, TerrainFeatures, compute_features, load_terrain

SPECS = (
    "large_rocks:seed=1",
    "round_rocks:seed=2",
    "sloped_rocks:seed=3",
    "logs:seed=4",
    "stepping_stones:seed=5",
    "gap",
    "steps",
)


class World:
    """Terrains, their features and a pool of candidate footholds, shared by the tests."""

    def __init__(self) -> None:
        self.terrains: dict[str, Terrain] = {s: load_terrain(s) for s in SPECS}
        self.features: dict[str, TerrainFeatures] = {
            s: compute_features(t) for s, t in self.terrains.items()
        }
        self.selector = PairSelector(
            list(self.terrains.values()),
            features=[self.features[s] for s in SPECS],
            seed=7,
        )
        self.clean = ScriptedExpert()

    def pairs(self, n: int) -> list[CandidatePair]:
        return [self.selector.propose(None) for _ in range(n)]

    def dataset(self, pairs: Sequence[CandidatePair], labels: Sequence[str]) -> PreferenceDataset:
        prefs = [Preference(p.a, p.b, p.leg, lab) for p, lab in zip(pairs, labels, strict=True)]
        return PreferenceDataset.from_preferences(prefs, self.features)

    def noisy_labels(self, pairs: Sequence[CandidatePair], seed: int) -> list[str]:
        expert = ScriptedExpert(ScriptedExpertConfig(noise=0.1), seed=seed)
        return expert.judge([(p.a, p.b) for p in pairs], self.terrains)

    def clean_labels(self, pairs: Sequence[CandidatePair]) -> list[str]:
        return self.clean.judge([(p.a, p.b) for p in pairs], self.terrains, noisy=False)


@pytest.fixture(scope="module")
def world() -> World:
    return World()


@pytest.fixture(scope="module")
def held_out(world: World) -> PreferenceDataset:
    pairs = world.pairs(1500)
    data = world.dataset(pairs, world.clean_labels(pairs))
    assert data.n_strict > 1200, "held-out pairs should be mostly strict judgements"
    return data


@pytest.fixture(scope="module")
def training(world: World) -> tuple[list[CandidatePair], list[str]]:
    pairs = world.pairs(400)
    return pairs, world.noisy_labels(pairs, seed=11)


def _pit_terrain(depth: float) -> Terrain:
    x = np.arange(-0.15, 0.1501, 0.005)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    r2 = gx**2 + gy**2
    return Terrain(-depth * np.exp(-r2 / (2 * 0.015**2)), -0.15, -0.15, 0.005, 0.005)


def test_no_linear_utility_of_the_features_can_reproduce_the_expert() -> None:
    # Scaling a pit's depth scales every quadratic-fit feature by the same factor,
    # so u = w·f of a pit has the same sign at every depth for any w (flat ground,
    # depth 0, has u = 0). The expert prefers a shallow dimple to flat ground and
    # flat ground to a deep pit: no w can agree with both.
    depths = np.array([0.006, 0.02, 0.05, 0.08])
    feats = np.stack([compute_features(_pit_terrain(d)).at([[0.0, 0.0]])[0] for d in depths])
    np.testing.assert_allclose(feats, depths[:, None] / depths[0] * feats[0], rtol=1e-6, atol=1e-9)
    expert = ScriptedExpert()
    bad = np.array([expert.badness(_pit_terrain(d), [[0.0, 0.0]])[0] for d in depths])
    flat = expert.badness(_pit_terrain(0.0), [[0.0, 0.0]])[0]
    assert flat == 0.0
    assert bad[0] < flat and bad[1] < flat, bad
    assert bad[-1] > flat + 1.0, bad


def test_expert_follows_the_papers_statements() -> None:
    expert = ScriptedExpert()
    x = np.arange(-0.15, 0.1501, 0.005)
    gx, gy = np.meshgrid(x, x, indexing="ij")
    r = np.hypot(gx, gy)

    def bad(heights: np.ndarray) -> float:
        t = Terrain(heights, -0.15, -0.15, 0.005, 0.005)
        return float(expert.badness(t, [[0.0, 0.0]])[0])

    flat = bad(np.zeros_like(gx))
    slope = bad(np.tan(np.radians(25)) * gx)
    dome = bad(0.02 * np.exp(-(r**2) / (2 * 0.015**2)))
    dimple = bad(-0.006 * np.exp(-(r**2) / (2 * 0.012**2)))
    trap = bad(np.where(r < 0.03, -0.06, 0.0))
    chasm = bad(np.where(gx > 0.015, -0.15, 0.0))
    assert flat == 0.0
    assert dimple < flat < dome
    assert flat < slope
    assert max(slope, dome) < trap < chasm


def test_learned_cost_agrees_with_the_expert_on_held_out_pairs(
    world: World, held_out: PreferenceDataset, training: tuple[list[CandidatePair], list[str]]
) -> None:
    pairs, labels = training
    data = world.dataset(pairs[:200], labels[:200])
    assert len(data) == 200
    flipped = sum(
        lab != ref
        for lab, ref in zip(labels[:200], world.clean_labels(pairs[:200]), strict=True)
        if ref != "equal"
    )
    assert 10 <= flipped <= 32, "about 10 % of the strict labels are noisy"
    cost, report = learn_cost(data)
    assert agreement(cost, held_out) >= 0.90
    # The noisy training labels cap what cross-validation can show: ≈ 0.9 × accuracy.
    assert report.cv_agreement is not None and report.cv_agreement >= 0.75

    # Its ranking of random footholds agrees with the expert's.
    idx = np.random.default_rng(3).choice(len(world.selector.footholds), 1500, replace=False)
    footholds = [world.selector.footholds[i] for i in idx]
    bad = np.empty(len(idx))
    u = np.empty(len(idx))
    for spec in SPECS:
        mine = [k for k, f in enumerate(footholds) if f.terrain == spec]
        xy = np.array([footholds[k].xy for k in mine])
        bad[mine] = world.clean.badness(world.terrains[spec], xy)
        u[mine] = cost.utility(world.features[spec].at(xy))
    assert spearmanr(u, -bad).statistic >= 0.8


def test_learning_is_deterministic_for_a_seed(
    world: World, training: tuple[list[CandidatePair], list[str]]
) -> None:
    pairs, labels = training
    data = world.dataset(pairs[:120], labels[:120])
    config = CostLearningConfig(folds=3)
    a, ra = learn_cost(data, config)
    b, rb = learn_cost(data, config)
    np.testing.assert_array_equal(a.weights["front"], b.weights["front"])
    assert ra.cv_agreement == rb.cv_agreement
    c, _ = learn_cost(data, with_seed(config, 1))
    assert not np.array_equal(a.weights["front"], c.weights["front"])


def test_adding_preferences_keeps_or_improves_held_out_agreement(
    world: World, held_out: PreferenceDataset, training: tuple[list[CandidatePair], list[str]]
) -> None:
    pairs, labels = training
    scores = []
    for n in (10, 50, 200, 400):
        cost, _ = learn_cost(world.dataset(pairs[:n], labels[:n]), CostLearningConfig(folds=0))
        scores.append(agreement(cost, held_out))
    # Near the linear model's ceiling (≈ 0.92 here) noise moves agreement by a
    # fraction of a point; "keeps" allows one point.
    for before, after in zip(scores, scores[1:], strict=False):
        assert after >= before - 0.01, scores
    assert scores[2] > scores[0], scores


def test_flat_ground_costs_one_and_world_frame_costs_ignore_signed_features(
    world: World, training: tuple[list[CandidatePair], list[str]]
) -> None:
    pairs, labels = training
    cost, _ = learn_cost(world.dataset(pairs[:100], labels[:100]), CostLearningConfig(folds=0))
    flat = load_terrain("flat")
    grid = cost.cost_map(flat)
    assert np.all(grid[np.isfinite(grid)] == 1.0)
    mask = feature_mask(len(cost.radii), "auto", oriented=False)
    assert np.all(cost.weights["front"][~mask] == 0.0)
    assert np.count_nonzero(cost.weights["front"][mask]) > 0


def test_separate_legs_learn_each_legs_own_judgements(
    world: World, training: tuple[list[CandidatePair], list[str]]
) -> None:
    pairs, labels = training
    data = world.dataset(pairs[:200], labels[:200])
    assert 0 < int(data.hind.sum()) < len(data)
    shared, _ = learn_cost(data, CostLearningConfig(folds=0))
    separate, _ = learn_cost(data, CostLearningConfig(folds=0, separate_legs=True))
    assert not shared.separate_legs and separate.separate_legs
    front_only, _ = learn_cost(data.subset(~data.hind), CostLearningConfig(folds=0))
    # The front model of a separate-legs cost is learned from the front judgements
    # alone (with the feature scale of all of them).
    np.testing.assert_allclose(
        separate.utility(data.f_a[:5], "front") > 0, front_only.utility(data.f_a[:5]) > 0
    )


def _qp_optimum(d: np.ndarray, s: np.ndarray, cfg: RankingSvmConfig) -> float:
    """The SVM primal with slacks, min λ/2‖w‖² + mean ξ, by SLSQP."""
    n, f = d.shape

    def objective(z: np.ndarray) -> float:
        return cfg.regularization / 2 * z[:f] @ z[:f] + z[f:].mean()

    cons = [
        {"type": "ineq", "fun": lambda z: z[f:] - (cfg.margin - s * (d @ z[:f]))},
        {"type": "ineq", "fun": lambda z: z[f:]},
    ]
    res = minimize(
        objective,
        np.zeros(f + n),
        constraints=cons,
        method="SLSQP",
        options={"maxiter": 500, "ftol": 1e-12},
    )
    assert res.success, res.message
    return float(res.fun)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ranking_svm_reaches_the_qp_optimum(seed: int) -> None:
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(60, 5))
    w_true = rng.normal(size=5)
    s = np.sign(d @ w_true + rng.normal(scale=0.5, size=60)).astype(int)
    cfg = RankingSvmConfig(regularization=0.1, epochs=400, seed=seed)
    w = RankingSvm(cfg).fit(d, s)
    best = _qp_optimum(d, s, cfg)
    assert ranking_objective(w, d, s, cfg) <= best * 1.01 + 1e-4


def test_ranking_svm_ties_pull_utilities_together() -> None:
    rng = np.random.default_rng(5)
    d = rng.normal(size=(80, 3))
    s = np.sign(d[:, 0]).astype(int)
    # Pairs differing only along the third axis are "equally good".
    ties = np.column_stack([np.zeros(40), np.zeros(40), rng.normal(scale=3, size=40)])
    d3 = np.concatenate([d, ties])
    s3 = np.concatenate([s, np.zeros(40, dtype=int)])
    cfg = RankingSvmConfig(regularization=0.01, epochs=100, tie_weight=1.0)
    w = RankingSvm(cfg).fit(d3, s3)
    assert abs(w[2]) < 0.2 * abs(w[0])
    assert ranking_objective(w, d3, s3, cfg) < ranking_objective(np.zeros(3), d3, s3, cfg)


def test_cost_of_a_learned_model_round_trips_through_json(
    world: World, training: tuple[list[CandidatePair], list[str]], tmp_path
) -> None:
    pairs, labels = training
    cost, report = learn_cost(world.dataset(pairs[:60], labels[:60]), CostLearningConfig(folds=2))
    path = tmp_path / "cost.json"
    cost.save(path)
    again = TerrainCost.load(path)
    np.testing.assert_array_equal(again.weights["hind"], cost.weights["hind"])
    assert again.metadata["n_preferences"] == 60
    assert again.metadata["cv_agreement"] == report.cv_agreement


def test_oriented_features_learn_what_depends_on_the_heading() -> None:
    # An expert who prefers footholds that rise along the robot's heading (raw
    # heights 2 cm ahead and behind): invisible to world-frame, rotation-invariant
    # features, plain to oriented ones.
    from roughwalk.planning import PairSelectionConfig

    x = np.arange(0.0, 1.0, 0.005)
    y = np.arange(-0.3, 0.3, 0.005)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    rolling = 0.03 * np.sin(7 * gx) * np.cos(5 * gy) + 0.015 * np.sin(13 * gy + 4 * gx + 1)
    ground = Terrain(rolling, 0.0, -0.3, 0.005, 0.005, name="rolling", spec="rolling")
    feats = {ground.spec: compute_features(ground)}
    selector = PairSelector(
        [ground],
        features=[feats[ground.spec]],
        config=PairSelectionConfig(heading_spread=np.pi, rough_fraction=1.0),
        seed=2,
    )

    def rise(f: Foothold) -> float:
        ahead = np.array([np.cos(f.heading), np.sin(f.heading)]) * 0.02
        xy = np.array([f.xy])
        return float(ground.height(xy + ahead)[0] - ground.height(xy - ahead)[0])

    def labelled(n: int) -> list[Preference]:
        pairs = [selector.propose(None) for _ in range(n)]
        return [Preference(p.a, p.b, p.leg, "a" if rise(p.a) > rise(p.b) else "b") for p in pairs]

    train, test = labelled(200), labelled(500)
    scores = {}
    for oriented in (True, False):
        cost, _ = learn_cost(
            PreferenceDataset.from_preferences(train, feats, oriented=oriented),
            CostLearningConfig(oriented=oriented, folds=0),
        )
        held = PreferenceDataset.from_preferences(test, feats, oriented=oriented)
        scores[oriented] = agreement(cost, held)
    assert scores[True] > 0.9, scores  # measured 0.972 and 0.5
    assert scores[False] < 0.65, scores
