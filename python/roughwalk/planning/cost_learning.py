"""Learning a :class:`TerrainCost` from preferences, and measuring how far to trust it.

:func:`learn_cost` scales the features (no centring, so flat ground keeps
u = 0 and unit cost), solves the ranking SVM per leg kind (one model for
both legs unless ``separate_legs``), and reports the agreement with the
judgements it was trained on and, by k-fold cross-validation, with judgements
it was not (Zucker 2011, §4.2, learned from about 200 preferences).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError, PlanningError
from roughwalk.planning.pair_selection import feature_scale
from roughwalk.planning.preference_dataset import PreferenceDataset
from roughwalk.planning.ranking_svm import RankingSvm, RankingSvmConfig
from roughwalk.planning.terrain_cost import LEGS, TerrainCost
from roughwalk.terrain.features import DEFAULT_RADII, FEATURE_NAMES

__all__ = [
    "CostLearningConfig",
    "LearnReport",
    "learn_cost",
    "cross_validate",
    "agreement",
    "INVARIANT_FEATURES",
    "feature_mask",
    "with_seed",
]

# Features that do not change when the ground turns under the robot: the fit's
# eigenvalues, the gradient's magnitude and the residual.
INVARIANT_FEATURES = ("lambda_min", "lambda_max", "grad_norm", "residual")
FeatureSet = Literal["auto", "invariant", "all"]


def feature_mask(n_radii: int, feature_set: str, oriented: bool) -> NDArray[np.bool_]:
    """Which of the 9 · ``n_radii`` features a cost may weight.

    ``"all"``: every one; ``"invariant"``: only :data:`INVARIANT_FEATURES`;
    ``"auto"``: all for an oriented cost, invariant ones otherwise, since in the
    world frame a signed slope k_x or curvature k_xx says nothing about how the
    ground lies under a robot that may walk any way.
    """
    if feature_set not in ("auto", "invariant", "all"):
        raise InvalidArgumentError(
            f"unknown feature_set {feature_set!r}; known: auto, invariant, all"
        )
    if feature_set == "all" or (feature_set == "auto" and oriented):
        return np.ones(len(FEATURE_NAMES) * n_radii, dtype=bool)
    one = np.array([name in INVARIANT_FEATURES for name in FEATURE_NAMES])
    return np.tile(one, n_radii)


@dataclass(frozen=True)
class CostLearningConfig:
    """How a terrain cost is learned.

    Attributes
    ----------
    radii:
        Feature disc radii [m] (Zucker: 1 cm to 6 cm). Each must be ≥ 1.5 grid
        cells of the terrains; more radii see more scales and need more
        preferences.
    oriented:
        Features in the robot's heading frame (uphill and downhill differ);
        the cost then needs a heading at every query.
    separate_legs:
        Learn the front and hind feet apart; each gets only its own judgements.
    feature_set:
        Which features get weights: "auto" (all if oriented, else the
        rotation-invariant ones), "invariant" or "all" (see :func:`feature_mask`).
        Fewer features need fewer preferences.
    scale_quantile:
        Features are divided by this quantile of |f| over the judged footholds
        before learning, so that λ treats them alike.
    svm:
        The ranking SVM's margin, regularization, epochs and seed.
    folds:
        k of the k-fold cross-validation of the report (0 or 1: none).

    """

    radii: tuple[float, ...] = DEFAULT_RADII
    oriented: bool = False
    separate_legs: bool = False
    feature_set: str = "auto"
    scale_quantile: float = 0.99
    svm: RankingSvmConfig = field(default_factory=RankingSvmConfig)
    folds: int = 5

    def __post_init__(self) -> None:
        if not 0 < self.scale_quantile <= 1:
            raise InvalidArgumentError(
                f"scale_quantile must be in (0, 1], got {self.scale_quantile}"
            )
        if self.folds < 0:
            raise InvalidArgumentError(f"folds must be ≥ 0, got {self.folds}")
        feature_mask(1, self.feature_set, self.oriented)


@dataclass(frozen=True)
class LearnReport:
    """What a learning run used and how well its cost agrees with the expert.

    Agreements are fractions of strict judgements ranked the expert's way
    (a tie in u counts one half); ``cv_agreement`` is on held-out folds.
    """

    n_preferences: int
    n_strict: int
    n_equal: int
    n_skipped: int
    by_leg: dict[str, int]
    train_agreement: float
    cv_agreement: float | None
    cv_folds: int
    seconds: float
    skipped: list[tuple[int, str]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {
            "n_preferences": self.n_preferences,
            "n_strict": self.n_strict,
            "n_equal": self.n_equal,
            "n_skipped": self.n_skipped,
            "by_leg": self.by_leg,
            "train_agreement": self.train_agreement,
            "cv_agreement": self.cv_agreement,
            "cv_folds": self.cv_folds,
            "seconds": self.seconds,
            "skipped": [list(s) for s in self.skipped],
        }


def agreement(cost: TerrainCost, data: PreferenceDataset) -> float:
    """Fraction of ``data``'s strict judgements that ``cost`` ranks the expert's way.

    NaN if there are none. A pair the cost cannot tell apart counts one half.
    """
    strict = data.signs != 0
    if not strict.any():
        return float("nan")
    du = np.empty(len(data))
    for leg in LEGS:
        mask = data.hind == (leg == "hind")
        if mask.any():
            du[mask] = cost.utility(data.f_a[mask] - data.f_b[mask], leg)
    agree = np.sign(du[strict]) * data.signs[strict]
    return float(np.mean(np.where(agree > 0, 1.0, np.where(agree == 0, 0.5, 0.0))))


def _fit_weights(
    data: PreferenceDataset, config: CostLearningConfig, scale: NDArray[np.float64]
) -> NDArray[np.float64]:
    mask = feature_mask(len(config.radii), config.feature_set, config.oriented)
    d = ((data.f_a - data.f_b) / scale)[:, mask]
    w_scaled = np.zeros(mask.size)
    w_scaled[mask] = RankingSvm(config.svm).fit(d, data.signs)
    return np.asarray(w_scaled / scale)


def _fit(data: PreferenceDataset, config: CostLearningConfig) -> TerrainCost:
    if len(data) == 0:
        raise PlanningError("no preferences to learn from")
    if data.radii != tuple(config.radii) or data.oriented != config.oriented:
        raise InvalidArgumentError(
            f"the dataset has radii {data.radii} m (oriented={data.oriented}) but the config "
            f"asks for {tuple(config.radii)} m (oriented={config.oriented})"
        )
    scale = feature_scale(np.concatenate([data.f_a, data.f_b]), config.scale_quantile)
    shared = _fit_weights(data, config, scale)
    weights = {leg: shared for leg in LEGS}
    if config.separate_legs:
        for leg in LEGS:
            mask = data.hind == (leg == "hind")
            # A leg without judgements keeps the shared model rather than none.
            if np.count_nonzero(data.signs[mask]) > 0:
                weights[leg] = _fit_weights(data.subset(mask), config, scale)
    return TerrainCost(weights, config.radii, oriented=config.oriented)


def _folds(n: int, k: int, seed: int) -> list[NDArray[np.intp]]:
    order = np.random.default_rng(seed).permutation(n)
    return [np.sort(f) for f in np.array_split(order, k)]


def cross_validate(data: PreferenceDataset, config: CostLearningConfig) -> float | None:
    """Mean held-out agreement over ``config.folds`` folds (None if too few judgements).

    Each fold is learned exactly as :func:`learn_cost` would, scaling included,
    from the other folds; the folds are drawn from ``config.svm.seed``.
    """
    k = config.folds
    if k < 2 or data.n_strict < k:
        return None
    hits = 0.0
    count = 0
    for test in _folds(len(data), k, config.svm.seed):
        train = np.setdiff1d(np.arange(len(data)), test)
        held = data.subset(test)
        n_held = held.n_strict
        if n_held == 0 or len(train) == 0:
            continue
        cost = _fit(data.subset(train), config)
        hits += agreement(cost, held) * n_held
        count += n_held
    return hits / count if count else None


def learn_cost(
    data: PreferenceDataset,
    config: CostLearningConfig | None = None,
    *,
    metadata: dict[str, Any] | None = None,
) -> tuple[TerrainCost, LearnReport]:
    """Learn a terrain cost from ``data`` and report its agreement with the expert.

    Parameters
    ----------
    data:
        Judged pairs with their features (see :class:`PreferenceDataset`).
    config:
        Radii, orientation, legs, SVM settings and cross-validation folds.
    metadata:
        Extra JSON-ready facts stored in the cost (e.g. the store it came from).

    Returns
    -------
    (TerrainCost, LearnReport)
        The cost, learned from every judgement, and the report.

    """
    cfg = config or CostLearningConfig(radii=data.radii, oriented=data.oriented)
    start = time.perf_counter()
    cost = _fit(data, cfg)
    train = agreement(cost, data)
    cv = cross_validate(data, cfg)
    seconds = time.perf_counter() - start
    report = LearnReport(
        n_preferences=len(data),
        n_strict=data.n_strict,
        n_equal=len(data) - data.n_strict,
        n_skipped=len(data.skipped),
        by_leg={
            "front": int(np.count_nonzero(~data.hind)),
            "hind": int(np.count_nonzero(data.hind)),
        },
        train_agreement=train,
        cv_agreement=cv,
        cv_folds=cfg.folds if cv is not None else 0,
        seconds=seconds,
        skipped=list(data.skipped),
    )
    cost.metadata.update(
        {
            "n_preferences": report.n_preferences,
            "train_agreement": report.train_agreement,
            "cv_agreement": report.cv_agreement,
            "cv_folds": report.cv_folds,
            "learner": {
                "margin": cfg.svm.margin,
                "regularization": cfg.svm.regularization,
                "epochs": cfg.svm.epochs,
                "tie_weight": cfg.svm.tie_weight,
                "seed": cfg.svm.seed,
                "scale_quantile": cfg.scale_quantile,
                "feature_set": cfg.feature_set,
                "separate_legs": cfg.separate_legs,
            },
            **(metadata or {}),
        }
    )
    return cost, report


def with_seed(config: CostLearningConfig, seed: int) -> CostLearningConfig:
    """``config`` with the SVM's seed replaced."""
    return replace(config, svm=replace(config.svm, seed=seed))
