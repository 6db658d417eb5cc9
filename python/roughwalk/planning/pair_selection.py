"""Which pair of footholds to show the expert next.

A :class:`PairSelector` draws a pool of candidate footholds on the labelling
terrains (a share of them on uneven ground, where judgements teach the most,
since two flat footholds are always equal), then proposes pairs from it. With
no model yet, pairs are random. With a model, it mostly proposes the pair it is
least sure about: among a batch of random pairs, the one whose difference
Δf lies closest to the model's decision boundary, |w·Δf| / ‖Δf‖ with features
scaled to comparable ranges (margin sampling for SVMs, Tong & Koller 2001);
a fixed share of pairs stays random so that the model's blind spots are
still visited.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.planning.preference_store import Foothold
from roughwalk.planning.terrain_cost import LEGS, TerrainCost
from roughwalk.terrain.features import DEFAULT_RADII, TerrainFeatures, compute_features
from roughwalk.terrain.terrain import Terrain

__all__ = ["PairSelectionConfig", "CandidatePair", "PairSelector", "feature_scale"]


def feature_scale(values: NDArray[np.floating], quantile: float = 0.9) -> NDArray[np.float64]:
    """Per-feature scale: the ``quantile`` of |f| over the rows of ``values`` (N, F).

    Features are scaled, never centred, so that flat ground keeps the zero
    vector. A quantile rather than the RMS, since curvatures at edges are
    heavy-tailed. Features that are zero almost everywhere take the largest |f|,
    and all-zero features scale 1.
    """
    a = np.abs(np.asarray(values, dtype=np.float64))
    if a.ndim != 2:
        raise InvalidArgumentError(f"expected feature rows (N, F), got shape {a.shape}")
    if a.shape[0] == 0:
        return np.ones(a.shape[1])
    scale = np.quantile(a, quantile, axis=0)
    top = a.max(axis=0)
    scale = np.where(scale > 0, scale, top)
    return np.where(scale > 0, scale, 1.0)


@dataclass(frozen=True)
class PairSelectionConfig:
    """How candidate footholds and pairs are drawn.

    Attributes
    ----------
    candidates_per_terrain:
        Footholds drawn per terrain. More cover the terrain better and cost
        memory (F floats each).
    rough_fraction:
        Share of the candidates drawn where the ground is not flat.
    heading_spread:
        Candidate headings are uniform in ±this [rad] around +x (the course
        direction); 0 keeps every heading at 0.
    batch:
        Random pairs scored per proposal; more find less certain pairs.
    explore:
        Share of proposals that are plain random pairs, even with a model.
    hind_fraction:
        Share of pairs judged for a hind foot.

    """

    candidates_per_terrain: int = 3000
    rough_fraction: float = 0.7
    heading_spread: float = 0.0
    batch: int = 256
    explore: float = 0.25
    hind_fraction: float = 0.5


@dataclass(frozen=True)
class CandidatePair:
    """A proposed pair: two footholds and the leg they are judged for."""

    a: Foothold
    b: Foothold
    leg: str
    informative: bool


class PairSelector:
    """Proposes pairs of footholds on ``terrains`` for the expert to judge.

    Parameters
    ----------
    terrains:
        The labelling terrains (their ``spec`` names the footholds' terrain).
    radii:
        Feature radii [m] of the candidates' features (the model's).
    config:
        Pool and selection settings.
    seed:
        Seed of every random draw: the same seed proposes the same pairs
        given the same models.
    features:
        Precomputed world-frame features of ``terrains`` with ``radii``.

    """

    def __init__(
        self,
        terrains: Sequence[Terrain],
        radii: Sequence[float] = DEFAULT_RADII,
        config: PairSelectionConfig | None = None,
        seed: int = 0,
        features: Sequence[TerrainFeatures] | None = None,
    ) -> None:
        if not terrains:
            raise InvalidArgumentError("pair selection needs at least one terrain")
        self.config = cfg = config or PairSelectionConfig()
        self.terrains = list(terrains)
        self._rng = np.random.default_rng(seed)
        if features is None:
            features = [compute_features(t, radii=radii) for t in self.terrains]
        footholds: list[Foothold] = []
        rows: list[NDArray[np.floating]] = []
        for terrain, feats in zip(self.terrains, features, strict=True):
            xy = self._draw(terrain, feats)
            headings = self._rng.uniform(-cfg.heading_spread, cfg.heading_spread, len(xy))
            footholds += [
                Foothold(terrain.spec, float(x), float(y), float(h))
                for (x, y), h in zip(xy, headings, strict=True)
            ]
            rows.append(feats.at(xy))
        self.footholds = footholds
        self.values = np.concatenate(rows)
        self.scale = feature_scale(self.values)
        self._headings = np.array([f.heading for f in footholds])

    def _draw(self, terrain: Terrain, feats: TerrainFeatures) -> NDArray[np.float64]:
        """Candidate (x, y) [m] inside the valid region, a share of them on uneven ground."""
        from scipy.ndimage import binary_erosion

        cfg = self.config
        # Cells whose 8 neighbours are valid too: any point within half a cell of
        # their centre interpolates from valid cells only.
        inner = binary_erosion(feats.valid, structure=np.ones((3, 3), dtype=bool))
        valid = np.flatnonzero(inner.ravel())
        if valid.size == 0:
            raise InvalidArgumentError(
                f"terrain '{terrain.spec}' has no cell whose feature discs (radii up to "
                f"{max(feats.radii)} m) stay on known ground; use a larger terrain"
            )
        uneven = valid[np.any(feats.values.reshape(-1, feats.n_features)[valid] != 0, axis=1)]
        n = cfg.candidates_per_terrain
        n_rough = int(round(n * cfg.rough_fraction)) if uneven.size else 0
        cells = np.concatenate(
            [
                self._rng.choice(uneven, n_rough) if n_rough else np.empty(0, dtype=int),
                self._rng.choice(valid, n - n_rough),
            ]
        )
        i, j = np.unravel_index(cells, feats.shape)
        x = terrain.x0 + (i + self._rng.uniform(-0.5, 0.5, cells.size)) * terrain.dx
        y = terrain.y0 + (j + self._rng.uniform(-0.5, 0.5, cells.size)) * terrain.dy
        return np.column_stack([x, y])

    def _model_values(self, cost: TerrainCost, idx: NDArray[np.intp]) -> NDArray[np.float64]:
        from roughwalk.terrain.features import orient_features

        v = self.values[idx]
        if cost.oriented:
            v = orient_features(v, self._headings[idx])
        return np.asarray(v, dtype=np.float64)

    def propose(self, cost: TerrainCost | None = None) -> CandidatePair:
        """The next pair to judge: random without ``cost``, mostly the least certain with it."""
        cfg = self.config
        n = len(self.footholds)
        leg = LEGS[1] if self._rng.random() < cfg.hind_fraction else LEGS[0]
        explore = cost is None or self._rng.random() < cfg.explore
        size = 8 if explore else cfg.batch
        ia = self._rng.integers(0, n, size)
        ib = self._rng.integers(0, n, size)
        diff = (self.values[ia] - self.values[ib]) / self.scale
        if cost is not None and not explore:
            # Only differences the model can see count towards its uncertainty.
            diff = diff[:, cost.weights[leg] != 0]
        norm = np.sqrt(np.einsum("ij,ij->i", diff, diff))
        # Two flat footholds (Δf = 0) are equal to any model and teach nothing.
        usable = (norm > 1e-6) & (ia != ib)
        if not usable.any():
            usable = ia != ib
            if not usable.any():
                usable[:] = True
        if explore:
            k = int(np.flatnonzero(usable)[0])
        else:
            assert cost is not None
            w = cost.weights[leg]
            u = self._model_values(cost, ia) @ w - self._model_values(cost, ib) @ w
            score = np.where(usable, np.abs(u) / np.maximum(norm, 1e-12), np.inf)
            k = int(np.argmin(score))
        return CandidatePair(self.footholds[ia[k]], self.footholds[ib[k]], leg, not explore)
