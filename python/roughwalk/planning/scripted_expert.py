"""A scripted expert that judges footholds by rules on the raw height field.

There is no human LittleDog expert at hand, so the default cost shipped with
roughwalk, and the tests of the learner, use this stand-in. It follows the
statements of Zucker 2011, §4.2 about what makes a foothold good or bad, as
rules on heights sampled around the foothold (never on the quadratic-fit
features the learner uses, and not linear in them):

* steep slopes are bad: the slope of the plane fitted within 2 cm;
* domes are bad, feet slip off: the centre standing above the ring 2 cm out;
* small indentations are good, they register the foot: the centre below that
  ring, rewarded up to a depth of ``dimple_depth`` and only as far as the
  ring encloses it;
* large indentations and crevices are bad, shins get stuck: walls higher than
  ``shin_depth`` on two opposite sides within 2.5–6 cm (holes up to 12 cm
  across, LittleDog's shin length);
* chasms are worst: ground falling away more than ``chasm_drop`` within 3 cm,
  the foot's radius plus the 2 cm it may slip.

Each rule gives a penalty growing with the square of how far past its start
the geometry is; their sum, minus the dimple reward, is the expert's
*badness*, and of two footholds he prefers the less bad one (or says "equal"
within ``tie_tolerance``). Label noise flips a judgement with probability
``noise``. Its judgement is the same for front and hind feet.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.planning.preference_store import Foothold
from roughwalk.terrain.terrain import Terrain

__all__ = ["ScriptedExpertConfig", "ScriptedExpert"]

# Sample rings [m] and directions around a foothold.
_RADII = np.array([0.005, 0.01, 0.015, 0.02, 0.025, 0.03, 0.04, 0.05, 0.06])
_N_DIRECTIONS = 16


@dataclass(frozen=True)
class ScriptedExpertConfig:
    """The scripted expert's rules (lengths [m], angles [rad]).

    Attributes
    ----------
    slope_reference:
        Slope whose penalty is 1 (20°); the penalty is (θ / this)².
    dome_reference:
        Height [m] of the centre above its 2 cm ring whose penalty is 1.
    dimple_depth:
        Depth [m] below the 2 cm ring at which the dimple reward is full.
    dimple_reward:
        The full reward of a dimple that encloses the foot all round.
    shin_depth:
        Height [m] of walls on both sides beyond which the shin may be trapped.
    shin_reference:
        Wall height [m] past ``shin_depth`` whose penalty is 1.
    chasm_drop:
        Drop [m] within 3 cm beyond which the foot is at a chasm's edge.
    chasm_reference:
        Drop [m] past ``chasm_drop`` whose penalty is ``chasm_weight``.
    chasm_weight:
        Penalty of a drop of ``chasm_drop + chasm_reference``; chasms are worst.
    tie_tolerance:
        Difference of badness below which the expert says "equal".
    noise:
        Probability that a strict judgement is flipped.

    """

    slope_reference: float = 0.35
    dome_reference: float = 0.01
    dimple_depth: float = 0.008
    dimple_reward: float = 0.5
    shin_depth: float = 0.025
    shin_reference: float = 0.02
    chasm_drop: float = 0.03
    chasm_reference: float = 0.03
    chasm_weight: float = 3.0
    tie_tolerance: float = 0.02
    noise: float = 0.0

    def __post_init__(self) -> None:
        if not 0.0 <= self.noise <= 1.0:
            raise InvalidArgumentError(f"noise must be a probability in [0, 1], got {self.noise}")
        for name in ("slope_reference", "dome_reference", "dimple_depth", "shin_reference"):
            if not getattr(self, name) > 0:
                raise InvalidArgumentError(f"{name} must be positive, got {getattr(self, name)}")


class ScriptedExpert:
    """Judges pairs of footholds by the rules of the module docstring.

    Parameters
    ----------
    config:
        The rules' thresholds and the label noise.
    seed:
        Seed of the label noise: the same seed flips the same judgements.

    """

    def __init__(self, config: ScriptedExpertConfig | None = None, seed: int = 0) -> None:
        self.config = config or ScriptedExpertConfig()
        self._rng = np.random.default_rng(seed)

    def badness(self, terrain: Terrain, xy: ArrayLike) -> NDArray[np.float64]:
        """Badness (N,) of footholds ``xy`` (N, 2) [m]: 0 on flat ground, higher is worse."""
        cfg = self.config
        p = np.atleast_2d(np.asarray(xy, dtype=np.float64))
        if p.ndim != 2 or p.shape[1] != 2:
            raise InvalidArgumentError(f"expected xy of shape (N, 2), got {p.shape}")
        n = p.shape[0]
        angles = 2 * np.pi * np.arange(_N_DIRECTIONS) / _N_DIRECTIONS
        dirs = np.stack([np.cos(angles), np.sin(angles)], axis=-1)  # (K, 2)
        offsets = _RADII[:, None, None] * dirs[None]  # (R, K, 2)
        points = p[:, None, None, :] + offsets[None]
        heights = terrain.height(points.reshape(-1, 2)).reshape(n, len(_RADII), _N_DIRECTIONS)
        z0 = terrain.height(p)
        rise = heights - z0[:, None, None]  # (N, R, K)

        # Plane through the samples within 2 cm: with rings symmetric about the
        # centre, the least-squares gradient decouples into two sums.
        near = _RADII <= 0.02 + 1e-9
        u = offsets[near, :, 0]
        v = offsets[near, :, 1]
        gx = np.einsum("nrk,rk->n", rise[:, near], u) / np.sum(u * u)
        gy = np.einsum("nrk,rk->n", rise[:, near], v) / np.sum(v * v)
        slope = np.arctan(np.hypot(gx, gy))
        slope_penalty = (slope / cfg.slope_reference) ** 2

        ring = rise[:, int(np.argmin(np.abs(_RADII - 0.02)))]  # (N, K)
        bump = -ring.mean(axis=1)
        dome_penalty = (np.maximum(bump, 0.0) / cfg.dome_reference) ** 2
        enclosed = np.mean(ring > 0.002, axis=1)
        dimple = np.minimum(np.maximum(-bump, 0.0) / cfg.dimple_depth, 1.0)
        dimple_reward = cfg.dimple_reward * dimple * enclosed

        walls = rise[:, _RADII >= 0.025 - 1e-9].max(axis=1)  # (N, K)
        half = _N_DIRECTIONS // 2
        trap = np.minimum(walls[:, :half], walls[:, half:]).max(axis=1)
        trap_penalty = (np.maximum(trap - cfg.shin_depth, 0.0) / cfg.shin_reference) ** 2

        drop = -np.minimum(rise[:, _RADII <= 0.03 + 1e-9].min(axis=(1, 2)), 0.0)
        chasm_penalty = (
            cfg.chasm_weight * (np.maximum(drop - cfg.chasm_drop, 0.0) / cfg.chasm_reference) ** 2
        )
        return np.asarray(
            slope_penalty + dome_penalty + trap_penalty + chasm_penalty - dimple_reward
        )

    def judge(
        self,
        pairs: Sequence[tuple[Foothold, Foothold]],
        terrains: Mapping[str, Terrain],
        *,
        noisy: bool = True,
    ) -> list[str]:
        """Labels ("a", "b" or "equal") for ``pairs`` of footholds on ``terrains`` (by spec).

        With ``noisy`` (and ``config.noise`` > 0), each strict label is flipped
        with that probability, drawing from the expert's own seeded generator.
        """
        bad_a = self._badness_of([a for a, _ in pairs], terrains)
        bad_b = self._badness_of([b for _, b in pairs], terrains)
        diff = bad_b - bad_a  # > 0: a is better
        labels = np.where(
            np.abs(diff) < self.config.tie_tolerance, "equal", np.where(diff > 0, "a", "b")
        )
        if noisy and self.config.noise > 0:
            flip = self._rng.random(len(pairs)) < self.config.noise
            labels = np.where(
                flip & (labels == "a"), "b", np.where(flip & (labels == "b"), "a", labels)
            )
        return [str(label) for label in labels]

    def _badness_of(
        self, footholds: Sequence[Foothold], terrains: Mapping[str, Terrain]
    ) -> NDArray[np.float64]:
        out = np.empty(len(footholds))
        by_terrain: dict[str, list[int]] = {}
        for i, f in enumerate(footholds):
            by_terrain.setdefault(f.terrain, []).append(i)
        for spec, idx in by_terrain.items():
            if spec not in terrains:
                raise InvalidArgumentError(
                    f"the scripted expert was not given terrain '{spec}'; it has {sorted(terrains)}"
                )
            xy = np.array([footholds[i].xy for i in idx])
            out[idx] = self.badness(terrains[spec], xy)
        return out
