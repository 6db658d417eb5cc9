"""Preferences turned into feature vectors, ready for the ranking SVM.

:class:`TerrainResolver` finds the terrains a store names: generator specs
rebuild anywhere; file specs are tried as given, then beside the store, then
in extra search folders, and every terrain is checked against the fingerprint
the store took when it was labelled. :class:`PreferenceDataset` holds, per
judgement, the features of both footholds (in the heading frame for an
oriented cost), the sign of the preference and the leg.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError, RoughwalkError, TerrainError
from roughwalk.planning.preference_store import Preference, PreferenceStore, TerrainRecord
from roughwalk.terrain.features import TerrainFeatures, compute_features
from roughwalk.terrain.spec import load_terrain
from roughwalk.terrain.terrain import Terrain

__all__ = ["TerrainResolver", "PreferenceDataset"]


def _is_file_part(source: str) -> bool:
    # Generator specs carry their parameters after ':' (and '.' in numbers).
    return ":" not in source and Path(source).suffix != ""


class TerrainResolver:
    """Loads terrains by spec, looking for relative files in a few folders, with a cache.

    Parameters
    ----------
    search_dirs:
        Folders to look for relative terrain files in, after the current
        directory (the store's own folder is usually the first).

    """

    def __init__(self, search_dirs: Sequence[str | Path] = ()) -> None:
        self.search_dirs = [Path(d) for d in search_dirs]
        self._cache: dict[str, Terrain] = {}

    def _resolve_spec(self, spec: str) -> tuple[str, list[str]]:
        """The spec with relative file parts made findable, and every path tried."""
        parts = []
        tried: list[str] = []
        for raw in spec.split("+"):
            m = re.fullmatch(r"(.*?)(@-?\d+)?", raw.strip())
            assert m is not None
            source, rotation = m.group(1), m.group(2) or ""
            path = Path(source)
            if _is_file_part(source) and not path.is_absolute() and not path.exists():
                tried.append(str(path))
                for d in self.search_dirs:
                    for candidate in (d / path, d / path.name):
                        tried.append(str(candidate))
                        if candidate.exists():
                            source = str(candidate)
                            break
                    else:
                        continue
                    break
            parts.append(source + rotation)
        return "+".join(parts), tried

    def load(self, spec: str, record: TerrainRecord | None = None) -> Terrain:
        """The terrain of ``spec``; with ``record``, checked against its fingerprint.

        Raises :class:`TerrainError` naming the spec, the places looked in, and
        the cause, or what differs from the labelled terrain.
        """
        if spec not in self._cache:
            resolved, tried = self._resolve_spec(spec)
            try:
                terrain = load_terrain(resolved)
            except RoughwalkError as e:
                where = f" (looked for {', '.join(tried)})" if tried else ""
                raise TerrainError(
                    f"cannot load terrain '{spec}' named by the preferences{where}: {e}. "
                    "Run from the folder it was labelled in or pass --terrain-dir"
                ) from None
            self._cache[spec] = terrain
        terrain = self._cache[spec]
        if record is not None:
            diff = record.matches(terrain)
            if diff is not None:
                raise TerrainError(
                    f"terrain '{spec}' differs from the one that was labelled: it now has {diff}"
                )
        return terrain


@dataclass
class PreferenceDataset:
    """Feature vectors of judged pairs.

    Attributes
    ----------
    f_a, f_b:
        (n, F) features of the first and second foothold of each pair.
    signs:
        (n,) +1 if the first is preferred, −1 if the second, 0 if equal.
    hind:
        (n,) True where the judgement is for a hind foot.
    row_ids:
        (n,) the store's row ids (−1 for pairs that never were in a store).
    radii:
        Feature radii [m].
    oriented:
        True if the features are in each foothold's heading frame.
    skipped:
        (row id, reason) of judgements left out, e.g. footholds whose feature
        discs leave the terrain or touch unknown cells.

    """

    f_a: NDArray[np.float64]
    f_b: NDArray[np.float64]
    signs: NDArray[np.int8]
    hind: NDArray[np.bool_]
    row_ids: NDArray[np.int64]
    radii: tuple[float, ...]
    oriented: bool = False
    skipped: list[tuple[int, str]] = field(default_factory=list)

    def __len__(self) -> int:
        return int(self.signs.shape[0])

    @property
    def n_strict(self) -> int:
        """Number of strict (not "equal") judgements."""
        return int(np.count_nonzero(self.signs))

    def subset(self, index: NDArray[np.intp] | NDArray[np.bool_]) -> PreferenceDataset:
        """The judgements at ``index`` (an index array or a boolean mask)."""
        return PreferenceDataset(
            self.f_a[index],
            self.f_b[index],
            self.signs[index],
            self.hind[index],
            self.row_ids[index],
            self.radii,
            self.oriented,
            [],
        )

    @classmethod
    def from_preferences(
        cls,
        preferences: Sequence[Preference],
        features: dict[str, TerrainFeatures],
        *,
        oriented: bool = False,
    ) -> PreferenceDataset:
        """Build from judgements and the world-frame features of their terrains (by spec)."""
        radii_set = {f.radii for f in features.values()}
        if len(radii_set) > 1:
            raise InvalidArgumentError(f"features of several radii sets given: {radii_set}")
        radii = radii_set.pop() if radii_set else ()
        n = len(preferences)
        n_features = 9 * len(radii)
        f_ab = np.zeros((2, n, n_features))
        ok = np.ones(n, dtype=bool)
        skipped: list[tuple[int, str]] = []
        for side in (0, 1):
            by_terrain: dict[str, list[int]] = {}
            for i, p in enumerate(preferences):
                by_terrain.setdefault((p.a if side == 0 else p.b).terrain, []).append(i)
            for spec, idx in by_terrain.items():
                if spec not in features:
                    raise InvalidArgumentError(f"no features given for terrain '{spec}'")
                feats = features[spec]
                ends = [preferences[i].a if side == 0 else preferences[i].b for i in idx]
                xy = np.array([f.xy for f in ends], dtype=np.float64)
                heading = np.array([f.heading for f in ends]) if oriented else None
                f_ab[side, idx] = feats.at(xy, heading=heading)
                valid = feats.valid_at(xy)
                for i, v in zip(idx, valid, strict=True):
                    if not v and ok[i]:
                        ok[i] = False
                        row = preferences[i].id
                        skipped.append(
                            (
                                -1 if row is None else row,
                                f"foothold {'ab'[side]} on '{spec}' is within "
                                f"{max(radii)} m of the terrain's edge or of unknown cells",
                            )
                        )
        keep = np.flatnonzero(ok)
        kept = [preferences[int(i)] for i in keep]
        return cls(
            f_a=f_ab[0, keep],
            f_b=f_ab[1, keep],
            signs=np.array([p.sign for p in kept], dtype=np.int8),
            hind=np.array([p.leg == "hind" for p in kept], dtype=np.bool_),
            row_ids=np.array([-1 if p.id is None else p.id for p in kept], dtype=np.int64),
            radii=tuple(radii),
            oriented=oriented,
            skipped=sorted(skipped),
        )

    @classmethod
    def from_store(
        cls,
        store: PreferenceStore,
        radii: Sequence[float],
        *,
        oriented: bool = False,
        resolver: TerrainResolver | None = None,
    ) -> PreferenceDataset:
        """Load every judgement of ``store`` with features of ``radii`` [m].

        Terrains are found by ``resolver`` (by default: as named, then in the
        store's folder) and checked against the store's fingerprints.
        """
        resolver = resolver or TerrainResolver([store.path.parent])
        preferences = store.preferences()
        used = {p.a.terrain for p in preferences} | {p.b.terrain for p in preferences}
        features = {}
        for record in store.terrains():
            if record.spec in used:
                terrain = resolver.load(record.spec, record)
                features[record.spec] = compute_features(terrain, radii=radii)
        return cls.from_preferences(preferences, features, oriented=oriented)
