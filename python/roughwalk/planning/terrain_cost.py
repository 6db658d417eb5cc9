"""The learned terrain cost c(f) = exp(−w·f) of a foothold (Zucker 2011, §4.2).

A :class:`TerrainCost` holds one weight vector per leg kind ("front",
"hind"; both the same unless it was learned with separate legs) over the
quadratic-fit features of :func:`roughwalk.terrain.compute_features`. Flat
ground has the zero feature vector, so it costs exactly 1; a foothold the
expert prefers costs less, one he avoids costs more. Footholds whose feature
discs leave the grid or touch unknown cells cost +inf.

The file format is JSON (``schema`` ``"roughwalk_terrain_cost"``, ``version``
:data:`COST_VERSION`); :meth:`TerrainCost.load` with no path gives the cost
shipped with the package, learned from the scripted expert's preferences in
``roughwalk/planning/data`` (see that folder's README).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError, PlanningError
from roughwalk.terrain.features import (
    FEATURE_NAMES,
    TerrainFeatures,
    compute_features,
    orient_features,
)
from roughwalk.terrain.terrain import Terrain

__all__ = [
    "COST_SCHEMA",
    "COST_VERSION",
    "LEGS",
    "Leg",
    "CostModelError",
    "TerrainCost",
    "default_cost_path",
]

COST_SCHEMA = "roughwalk_terrain_cost"
COST_VERSION = 1
LEGS = ("front", "hind")
Leg = Literal["front", "hind"]

# u is clipped to ±this before exp(−u), so that a wild foothold gives a large
# finite cost (e^50 ≈ 5e21) rather than an overflow.
_MAX_ABS_UTILITY = 50.0


class CostModelError(PlanningError):
    """A terrain-cost file is missing, malformed or of a version this roughwalk cannot read."""


def default_cost_path() -> Path:
    """Path of the default cost shipped in the package (``planning/data/default_cost.json``)."""
    return Path(str(resources.files("roughwalk.planning").joinpath("data", "default_cost.json")))


def check_leg(leg: str) -> Leg:
    """Return ``leg`` if it is "front" or "hind"; raise :class:`InvalidArgumentError` otherwise."""
    if leg not in LEGS:
        raise InvalidArgumentError(f"unknown leg {leg!r}; known: {', '.join(LEGS)}")
    return leg  # type: ignore[return-value]


class TerrainCost:
    """A foothold cost c(f) = exp(−w_leg · f) over quadratic-fit terrain features.

    Parameters
    ----------
    weights:
        ``{"front": w, "hind": w}``, each of length 9 · len(radii) in the
        layout of :attr:`TerrainFeatures.values` [units: inverse of each feature's].
    radii:
        Feature disc radii [m] the weights were learned with.
    oriented:
        True if the features are expressed in the robot's heading frame
        (then every query needs a heading [rad]).
    metadata:
        What it was learned from (free-form, JSON-ready), e.g. the number of
        preferences and the cross-validated agreement.

    """

    def __init__(
        self,
        weights: Mapping[str, ArrayLike],
        radii: Sequence[float],
        *,
        oriented: bool = False,
        metadata: Mapping[str, Any] | None = None,
    ) -> None:
        self.radii = tuple(float(r) for r in radii)
        if not self.radii or any(not np.isfinite(r) or r <= 0 for r in self.radii):
            raise CostModelError(f"feature radii must be positive numbers [m], got {radii!r}")
        n = len(FEATURE_NAMES) * len(self.radii)
        missing = [leg for leg in LEGS if leg not in weights]
        if missing:
            raise CostModelError(f"weights for leg(s) {missing} missing; need {list(LEGS)}")
        self.weights: dict[str, NDArray[np.float64]] = {}
        for leg in LEGS:
            w = np.array(weights[leg], dtype=np.float64)
            if w.shape != (n,) or not np.all(np.isfinite(w)):
                raise CostModelError(
                    f"weights of the {leg} leg must be {n} finite numbers (9 features × "
                    f"{len(self.radii)} radii), got shape {w.shape}"
                )
            w.flags.writeable = False
            self.weights[leg] = w
        self.oriented = bool(oriented)
        self.metadata: dict[str, Any] = dict(metadata or {})

    # --------------------------------------------------------------- naming
    @property
    def feature_names(self) -> tuple[str, ...]:
        """Names of the weighted features (``r0.02/k_xx``, ...), as in :class:`TerrainFeatures`."""
        return tuple(f"r{r:g}/{n}" for r in self.radii for n in FEATURE_NAMES)

    @property
    def separate_legs(self) -> bool:
        """True if the front and hind legs have different weights."""
        return not np.array_equal(self.weights["front"], self.weights["hind"])

    # ----------------------------------------------------------- evaluation
    def utility(self, features: ArrayLike, leg: str = "front") -> NDArray[np.float64]:
        """Return u = w_leg · f for feature vectors of shape (..., F) (higher is better)."""
        f = np.asarray(features, dtype=np.float64)
        w = self.weights[check_leg(leg)]
        if f.shape[-1:] != w.shape:
            raise InvalidArgumentError(
                f"feature vectors must have {w.shape[0]} entries (radii {self.radii} m), "
                f"got shape {f.shape}"
            )
        return np.asarray(f @ w)

    def cost(self, features: ArrayLike, leg: str = "front") -> NDArray[np.float64]:
        """Return c = exp(−u) for feature vectors (..., F); 1 for flat ground."""
        u = np.clip(self.utility(features, leg), -_MAX_ABS_UTILITY, _MAX_ABS_UTILITY)
        return np.asarray(np.exp(-u))

    def features_for(self, terrain: Terrain, heading: float | None = None) -> TerrainFeatures:
        """Compute the features this cost needs on ``terrain`` (world frame unless ``heading``)."""
        return compute_features(terrain, radii=self.radii, oriented_heading=heading)

    def _check_features(self, features: TerrainFeatures) -> None:
        if features.radii != self.radii:
            raise InvalidArgumentError(
                f"features were computed with radii {features.radii} m but this cost needs "
                f"{self.radii} m; use TerrainCost.features_for(terrain)"
            )

    def _check_heading(self, heading: ArrayLike | None) -> None:
        if self.oriented and heading is None:
            raise InvalidArgumentError(
                "this cost was learned with oriented features; give the robot's heading [rad]"
            )

    def cost_map(
        self,
        terrain: Terrain,
        heading: float | None = None,
        leg: str = "front",
        *,
        features: TerrainFeatures | None = None,
    ) -> NDArray[np.float64]:
        """Cost of every grid cell of ``terrain``: (nx, ny), aligned with ``terrain.x``/``.y``.

        Parameters
        ----------
        terrain:
            The height field.
        heading:
            The robot's heading [rad]; needed (and used) only by an oriented cost.
        leg:
            "front" or "hind".
        features:
            Precomputed features of ``terrain`` with this cost's radii (world
            frame, or in the frame of ``heading``), to save recomputing them.

        Returns
        -------
        numpy.ndarray
            float64 costs, +inf where the feature discs leave the grid or touch
            unknown cells.

        """
        self._check_heading(heading)
        check_leg(leg)
        use_heading = heading if self.oriented else None
        if features is None:
            features = self.features_for(terrain, use_heading)
        self._check_features(features)
        if features.shape != terrain.shape:
            raise InvalidArgumentError(
                f"features of shape {features.shape} do not match the terrain {terrain.shape}"
            )
        values = features.values
        # The weights expect the heading frame (oriented) or the world frame.
        target = use_heading if use_heading is not None else 0.0
        current = features.heading or 0.0
        if target != current:
            values = orient_features(values, target - current)
        out = self.cost(values, leg)
        out[~features.valid] = np.inf
        return out

    def cost_at(
        self,
        terrain_features: TerrainFeatures,
        xy: ArrayLike,
        heading: ArrayLike | None = None,
        leg: str = "front",
    ) -> NDArray[np.float64]:
        """Cost of footholds ``xy`` (N, 2) [m], features interpolated bilinearly.

        ``heading`` [rad] (scalar or (N,)) is needed by an oriented cost and
        ignored otherwise. Footholds off the grid or near unknown cells cost +inf:
        a point is usable only if all four cells around it are valid, so at the
        edge of the valid region this is one cell more cautious than :meth:`cost_map`.
        """
        self._check_heading(heading)
        self._check_features(terrain_features)
        points = np.asarray(xy, dtype=np.float64)
        if points.ndim == 1 and points.shape == (2,):
            points = points[None, :]
        if self.oriented:
            f = terrain_features.at(points, heading=heading)
        else:
            # Features computed in some heading frame go back to the world frame.
            f = terrain_features.at(points, heading=0.0 if terrain_features.heading else None)
        out = self.cost(f, leg)
        out[~terrain_features.valid_at(points)] = np.inf
        return out

    # ------------------------------------------------------------------- io
    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description (what :meth:`save` writes)."""
        from roughwalk import __version__

        return {
            "schema": COST_SCHEMA,
            "version": COST_VERSION,
            "roughwalk_version": __version__,
            "feature_radii": list(self.radii),
            "feature_names": list(self.feature_names),
            "oriented": self.oriented,
            "separate_legs": self.separate_legs,
            "weights": {leg: self.weights[leg].tolist() for leg in LEGS},
            "metadata": self.metadata,
        }

    def save(self, path: str | Path) -> None:
        """Write the cost as JSON to ``path`` (atomically: a crash never leaves half a file)."""
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        tmp = p.with_name(p.name + ".tmp")
        tmp.write_text(json.dumps(self.to_dict(), indent=1, allow_nan=False) + "\n")
        tmp.replace(p)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> TerrainCost:
        """Rebuild a cost from :meth:`to_dict` output; ``source`` names it in errors."""
        if not isinstance(data, Mapping) or data.get("schema") != COST_SCHEMA:
            found = data.get("schema") if isinstance(data, Mapping) else type(data).__name__
            raise CostModelError(
                f"{source} is not a roughwalk terrain cost (schema {found!r}, "
                f"expected {COST_SCHEMA!r})"
            )
        version = data.get("version")
        if version != COST_VERSION:
            raise CostModelError(
                f"{source} is a terrain cost of version {version!r}; this roughwalk reads "
                f"version {COST_VERSION} only (re-learn it with `roughwalk cost learn`)"
            )
        try:
            radii = data["feature_radii"]
            weights = data["weights"]
            names = data.get("feature_names")
        except KeyError as e:
            raise CostModelError(f"{source} lacks the field {e.args[0]!r}") from None
        if not isinstance(weights, Mapping):
            raise CostModelError(f"{source}: 'weights' must map leg names to lists")
        cost = cls(
            weights,
            radii,
            oriented=bool(data.get("oriented", False)),
            metadata=data.get("metadata") or {},
        )
        if names is not None and tuple(names) != cost.feature_names:
            raise CostModelError(
                f"{source} was written for features {names[:3]}... but this roughwalk computes "
                f"{list(cost.feature_names[:3])}...; re-learn it with `roughwalk cost learn`"
            )
        return cost

    @classmethod
    def load(cls, path: str | Path | None = None) -> TerrainCost:
        """Read a cost file; ``None`` gives the default cost shipped with roughwalk."""
        p = default_cost_path() if path is None else Path(path)
        if not p.is_file():
            raise CostModelError(f"terrain cost file '{p}' does not exist")
        try:
            data = json.loads(p.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError) as e:
            raise CostModelError(f"terrain cost file '{p}' is not valid JSON: {e}") from None
        return cls.from_dict(data, source=f"terrain cost file '{p}'")

    def __repr__(self) -> str:
        legs = "separate front/hind" if self.separate_legs else "one model for all legs"
        frame = "oriented" if self.oriented else "world-frame"
        n = self.metadata.get("n_preferences")
        learned = f", learned from {n} preferences" if n is not None else ""
        return f"TerrainCost(radii {self.radii} m, {frame} features, {legs}{learned})"
