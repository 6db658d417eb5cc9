"""The state of a labelling session, apart from HTTP: pairs, judgements, undo, the live model.

The web server (:mod:`roughwalk.planning.labeling.labeling_server`) only
turns requests into calls of :class:`LabelingSession` and its answers into
JSON. Every judgement is committed to the store before the answer leaves, so
a page that shows a count has it on disk. After each judgement the cost is
re-learned from every judgement in the store (in a background thread, so
the next pair is shown at once) and the next pair is chosen where that model
is least sure (:class:`~roughwalk.planning.pair_selection.PairSelector`).
"""

from __future__ import annotations

import secrets
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from roughwalk.errors import InvalidArgumentError, RoughwalkError
from roughwalk.planning.cost_learning import CostLearningConfig, learn_cost
from roughwalk.planning.pair_selection import CandidatePair, PairSelectionConfig, PairSelector
from roughwalk.planning.preference_dataset import PreferenceDataset, TerrainResolver
from roughwalk.planning.preference_store import Foothold, Preference, PreferenceStore
from roughwalk.planning.terrain_cost import TerrainCost
from roughwalk.terrain.features import TerrainFeatures, compute_features
from roughwalk.terrain.terrain import Terrain

__all__ = ["LabelingConfig", "LabelingSession", "CHOICES"]

# What the page may send: the left (first) foothold is better, the right one,
# both are equally good, or skip this pair without a judgement.
CHOICES = ("left", "right", "equal", "skip")
_LABEL_OF_CHOICE = {"left": "a", "right": "b", "equal": "equal"}


@dataclass(frozen=True)
class LabelingConfig:
    """What the page shows and how often the model is checked.

    Attributes
    ----------
    foot_radius:
        Radius [m] of the foot drawn on each patch (LittleDog's is about 1 cm).
    patch_half_size:
        Half the side [m] of the square patch shown around each foothold.
    patch_cells:
        Samples per side of the patch (odd, so that the foothold is a sample).
    min_for_cross_validation:
        Judgements needed before the page shows a cross-validated agreement.

    """

    foot_radius: float = 0.01
    patch_half_size: float = 0.08
    patch_cells: int = 49
    min_for_cross_validation: int = 20

    def __post_init__(self) -> None:
        if self.patch_cells < 3 or self.patch_cells % 2 == 0:
            raise InvalidArgumentError(f"patch_cells must be odd and ≥ 3, got {self.patch_cells}")
        if not (self.foot_radius > 0 and self.patch_half_size > self.foot_radius):
            raise InvalidArgumentError(
                "need 0 < foot_radius < patch_half_size [m], got "
                f"{self.foot_radius} and {self.patch_half_size}"
            )


@dataclass
class _Shown:
    token: str
    pair: CandidatePair


class LabelingSession:
    """One expert's labelling session on ``terrains``, writing to ``store``.

    Parameters
    ----------
    store:
        An open, writable preference store (earlier judgements are kept and learned from).
    terrains:
        Terrains to propose footholds on; registered in the store (a terrain
        whose spec the store knows with other heights is refused).
    learning:
        How the live model is learned (radii, legs, SVM).
    selection:
        How candidate pairs are drawn.
    config:
        What the page shows.
    seed:
        Seed of the pair proposals.
    background:
        Re-learn in a background thread (the server); False learns before
        answering (tests, scripts).
    resolver:
        Finds the terrains of earlier judgements that are not in ``terrains``.

    """

    def __init__(
        self,
        store: PreferenceStore,
        terrains: Sequence[Terrain],
        *,
        learning: CostLearningConfig | None = None,
        selection: PairSelectionConfig | None = None,
        config: LabelingConfig | None = None,
        seed: int = 0,
        background: bool = True,
        resolver: TerrainResolver | None = None,
    ) -> None:
        if not terrains:
            raise InvalidArgumentError("a labelling session needs at least one terrain")
        self.store = store
        self.learning = learning or CostLearningConfig()
        self.config = config or LabelingConfig()
        self.session_id = secrets.token_hex(6)
        self.terrains = {t.spec: t for t in terrains}
        for t in terrains:
            store.add_terrain(t)
        self._features: dict[str, TerrainFeatures] = {
            spec: compute_features(t, radii=self.learning.radii)
            for spec, t in self.terrains.items()
        }
        self.unusable: list[str] = []
        self._load_other_terrains(resolver or TerrainResolver([store.path.parent]))
        self.selector = PairSelector(
            list(self.terrains.values()),
            radii=self.learning.radii,
            config=selection,
            seed=seed,
            features=[self._features[s] for s in self.terrains],
        )
        self._lock = threading.RLock()
        self._undo: list[tuple[int, CandidatePair]] = []
        self._session_count = 0
        self._model: TerrainCost | None = None
        self._model_stats: dict[str, Any] = {}
        self._model_version = 0
        self._wanted_version = 0
        self._wake = threading.Condition(self._lock)
        self._closed = False
        self._thread: threading.Thread | None = None
        if background:
            self._thread = threading.Thread(target=self._learn_loop, daemon=True)
            self._thread.start()
        self._request_learning(background)
        self._shown = _Shown(secrets.token_hex(8), self.selector.propose(self._model))

    def _load_other_terrains(self, resolver: TerrainResolver) -> None:
        """Features of the store's other terrains, so that the live model uses every judgement."""
        used = {p.a.terrain for p in self.store.preferences()} | {
            p.b.terrain for p in self.store.preferences()
        }
        for record in self.store.terrains():
            if record.spec in self._features or record.spec not in used:
                continue
            try:
                terrain = resolver.load(record.spec, record)
            except RoughwalkError as e:
                # Those judgements stay in the store; only the live model goes without.
                self.unusable.append(f"{record.spec}: {e}")
                continue
            self._features[record.spec] = compute_features(terrain, radii=self.learning.radii)

    # ------------------------------------------------------------ learning
    def _request_learning(self, background: bool) -> None:
        with self._lock:
            self._wanted_version += 1
            if background:
                self._wake.notify_all()
                return
        self._learn_once()

    def _learn_loop(self) -> None:
        while True:
            with self._lock:
                while not self._closed and self._model_version >= self._wanted_version:
                    self._wake.wait()
                if self._closed:
                    return
            self._learn_once()

    def _learn_once(self) -> None:
        with self._lock:
            target = self._wanted_version
        preferences = [
            p
            for p in self.store.preferences()
            if p.a.terrain in self._features and p.b.terrain in self._features
        ]
        model: TerrainCost | None = None
        stats: dict[str, Any] = {"n_used": 0}
        data = PreferenceDataset.from_preferences(
            preferences, self._features, oriented=self.learning.oriented
        )
        if data.n_strict > 0:
            folds = self.learning.folds
            if data.n_strict < self.config.min_for_cross_validation:
                folds = 0
            cfg = CostLearningConfig(
                radii=self.learning.radii,
                oriented=self.learning.oriented,
                separate_legs=self.learning.separate_legs,
                scale_quantile=self.learning.scale_quantile,
                svm=self.learning.svm,
                folds=folds,
            )
            model, report = learn_cost(data, cfg)
            stats = {
                "n_used": report.n_strict,
                "train_agreement": report.train_agreement,
                "cv_agreement": report.cv_agreement,
                "cv_folds": report.cv_folds,
                "seconds": report.seconds,
            }
        with self._lock:
            self._model = model
            self._model_stats = stats
            self._model_version = max(self._model_version, target)
            self._wake.notify_all()

    def wait_for_model(self, timeout: float = 30.0) -> bool:
        """Block until the live model includes every judgement so far (True) or ``timeout`` [s]."""
        deadline = time.monotonic() + timeout
        with self._lock:
            while self._model_version < self._wanted_version:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._wake.wait(left)
        return True

    @property
    def model(self) -> TerrainCost | None:
        """The latest live model (None before the first strict judgement)."""
        with self._lock:
            return self._model

    # -------------------------------------------------------------- actions
    def state(self) -> dict[str, Any]:
        """What the page shows: counts, the model's agreement, the pair to judge."""
        with self._lock:
            shown = self._shown
            stats = dict(self._model_stats)
            learning = self._model_version < self._wanted_version
            return {
                "count": self.store.count(),
                "session_count": self._session_count,
                "can_undo": bool(self._undo),
                "model": {**stats, "learning": learning},
                "store": str(self.store.path),
                "terrains": list(self.terrains),
                "unusable_terrains": self.unusable,
                "foot_radius": self.config.foot_radius,
                "pair": {
                    "token": shown.token,
                    "leg": shown.pair.leg,
                    "left": self._patch(shown.pair.a),
                    "right": self._patch(shown.pair.b),
                },
            }

    def label(self, token: str, choice: str) -> dict[str, Any]:
        """Record ``choice`` for the pair shown as ``token``; the next pair is shown.

        Raises :class:`InvalidArgumentError` for an unknown choice, and
        :class:`StalePairError` if ``token`` is not the pair on show (a
        double key press, or a second tab): nothing is recorded then.
        """
        if choice not in CHOICES:
            raise InvalidArgumentError(f"unknown choice {choice!r}; known: {', '.join(CHOICES)}")
        with self._lock:
            if token != self._shown.token:
                raise StalePairError(
                    "that pair is no longer on show (judged already, or judged in another tab)"
                )
            pair = self._shown.pair
            if choice != "skip":
                row = self.store.add(
                    Preference(
                        pair.a,
                        pair.b,
                        pair.leg,
                        _LABEL_OF_CHOICE[choice],
                        session=self.session_id,
                        source="human",
                    )
                )
                self._undo.append((row, pair))
                self._session_count += 1
            model = self._model
            self._shown = _Shown(secrets.token_hex(8), self.selector.propose(model))
        if choice != "skip":
            self._request_learning(self._thread is not None)
        return self.state()

    def undo(self) -> dict[str, Any]:
        """Delete this session's latest judgement and show its pair again.

        Only judgements made in this session can be undone: earlier sessions'
        judgements are never touched from the page.
        """
        with self._lock:
            if not self._undo:
                raise InvalidArgumentError("nothing to undo in this session")
            row, pair = self._undo.pop()
            self.store.delete(row)
            self._session_count -= 1
            self._shown = _Shown(secrets.token_hex(8), pair)
        self._request_learning(self._thread is not None)
        return self.state()

    def close(self) -> None:
        """Stop the learning thread (the store stays open; its owner closes it)."""
        with self._lock:
            self._closed = True
            self._wake.notify_all()
        if self._thread is not None:
            self._thread.join(timeout=10)

    # ---------------------------------------------------------------- views
    def _patch(self, foothold: Foothold) -> dict[str, Any]:
        """Heights around ``foothold`` in its heading frame, rows from back to front.

        ``heights[i][j]`` is at forward offset u_i and leftward offset v_j, both
        from −half to +half [m], relative to the foothold's own height [m].
        """
        cfg = self.config
        terrain = self.terrains.get(foothold.terrain)
        if terrain is None:
            raise InvalidArgumentError(f"terrain '{foothold.terrain}' is not in this session")
        s = np.linspace(-cfg.patch_half_size, cfg.patch_half_size, cfg.patch_cells)
        u, v = np.meshgrid(s, s, indexing="ij")
        c, sn = np.cos(foothold.heading), np.sin(foothold.heading)
        xy = np.column_stack(
            [
                foothold.x + c * u.ravel() - sn * v.ravel(),
                foothold.y + sn * u.ravel() + c * v.ravel(),
            ]
        )
        z0 = float(terrain.height([foothold.xy])[0])
        heights = terrain.height(xy).reshape(u.shape) - z0
        known = terrain.is_known(xy).reshape(u.shape)
        return {
            "terrain": terrain.name,
            "spec": terrain.spec,
            "x": foothold.x,
            "y": foothold.y,
            "heading": foothold.heading,
            "z": z0,
            "half_size": cfg.patch_half_size,
            "heights": np.round(heights, 5).tolist(),
            "known": known.astype(int).tolist(),
        }


class StalePairError(RoughwalkError):
    """A judgement named a pair that is no longer on show."""
