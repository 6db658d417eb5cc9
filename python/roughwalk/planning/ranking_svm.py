"""Support-vector ranking by online subgradient descent.

Zucker 2011, §4.2: find a utility u(f) = w·f such that every preference
f⁺ ≻ f⁻ holds by a margin, u(f⁺) > u(f⁻) + m, softened by slack variables
(Herbrich et al. 1999), solved online as in Kivinen, Smola & Williamson 2004.
With d = f⁺ − f⁻ the problem is

    min_w  λ/2 ‖w‖² + (1/n) Σ_i ℓ_i(w),
    ℓ_i = max(0, m − w·d_i)                      for a strict preference,
    ℓ_i = τ · max(0, |w·d_i| − m)                for "equally good" (a tie),

a strongly convex objective. Each step takes one preference in a seeded random
order: w ← (1 − η_t λ) w + η_t g_i with g_i the negative subgradient of ℓ_i,
step η_t = 1/(λ (t + t₀)), then w is projected on the ball ‖w‖ ≤ √(2m/λ)
that holds the optimum (ℓ(0) = m). The answer is the average of the iterates
of the second half of the run, which converges where the last iterate jitters.
Same data, same seed: the same weights, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import InvalidArgumentError

__all__ = ["RankingSvmConfig", "RankingSvm", "ranking_objective"]


@dataclass(frozen=True)
class RankingSvmConfig:
    """Settings of the ranking SVM.

    Attributes
    ----------
    margin:
        m in u(f⁺) > u(f⁻) + m. With c = exp(−u) it is a multiplicative
        margin: a preferred foothold should cost e^−m times the other. Larger
        makes the learned costs spread wider.
    regularization:
        λ: the weight of ‖w‖²/2 against the mean slack. Larger gives smoother,
        more conservative costs that fit the preferences less closely.
    epochs:
        Passes over the preferences. More converge further and take longer.
    tie_weight:
        τ: how much an "equally good" judgement counts against a strict one.
    seed:
        Seed of the order the preferences are visited in.

    """

    margin: float = 1.0
    regularization: float = 0.3
    epochs: int = 60
    tie_weight: float = 0.5
    seed: int = 0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.margin) and self.margin > 0):
            raise InvalidArgumentError(f"margin must be positive, got {self.margin}")
        if not (np.isfinite(self.regularization) and self.regularization > 0):
            raise InvalidArgumentError(
                f"regularization must be positive, got {self.regularization}"
            )
        if self.epochs < 1:
            raise InvalidArgumentError(f"epochs must be at least 1, got {self.epochs}")
        if not (np.isfinite(self.tie_weight) and self.tie_weight >= 0):
            raise InvalidArgumentError(f"tie_weight must be ≥ 0, got {self.tie_weight}")


def _check(d: ArrayLike, signs: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.int8]]:
    diff = np.asarray(d, dtype=np.float64)
    s = np.asarray(signs)
    if diff.ndim != 2 or s.shape != (diff.shape[0],):
        raise InvalidArgumentError(
            f"expected differences (n, F) and signs (n,), got {diff.shape} and {s.shape}"
        )
    if not np.all(np.isfinite(diff)):
        raise InvalidArgumentError("feature differences must be finite")
    if not np.all(np.isin(s, (-1, 0, 1))):
        raise InvalidArgumentError("signs must be +1 (first preferred), −1 or 0 (equal)")
    return diff, s.astype(np.int8)


def ranking_objective(
    w: ArrayLike, d: ArrayLike, signs: ArrayLike, config: RankingSvmConfig
) -> float:
    """The objective λ/2 ‖w‖² + mean slack, for checking a solution."""
    diff, s = _check(d, signs)
    wv = np.asarray(w, dtype=np.float64)
    u = diff @ wv
    m = config.margin
    strict = np.maximum(0.0, m - s * u)
    tie = config.tie_weight * np.maximum(0.0, np.abs(u) - m)
    loss = np.where(s != 0, strict, tie)
    return float(config.regularization / 2 * wv @ wv + loss.mean())


class RankingSvm:
    """The soft-margin ranking SVM u = w·f, trained online (see the module docstring)."""

    def __init__(self, config: RankingSvmConfig | None = None) -> None:
        self.config = config or RankingSvmConfig()

    def fit(self, d: ArrayLike, signs: ArrayLike) -> NDArray[np.float64]:
        """Weights w (F,) from differences d = f_a − f_b (n, F) and signs (n,).

        ``signs[i]`` is +1 if the first foothold of pair i is preferred, −1 if
        the second is, and 0 if the expert judged them equal.
        """
        diff, s = _check(d, signs)
        n, n_features = diff.shape
        if n == 0:
            return np.zeros(n_features)
        cfg = self.config
        lam, m, tau = cfg.regularization, cfg.margin, cfg.tie_weight
        rng = np.random.default_rng(cfg.seed)
        radius = np.sqrt(2 * m / lam)
        # Starting at t₀ caps the first step at 1/(λ t₀), so that one preference
        # cannot throw w to the edge of the ball before the others have spoken.
        longest = float(np.sqrt(np.max(np.einsum("ij,ij->i", diff, diff))))
        t0 = max(1.0, longest / (lam * radius))
        w = np.zeros(n_features)
        total = np.zeros(n_features)
        n_steps = cfg.epochs * n
        first_averaged = n_steps // 2
        rows = [diff[i] for i in range(n)]
        labels = s.tolist()
        t = 0
        for _ in range(cfg.epochs):
            for i in rng.permutation(n).tolist():
                eta = 1.0 / (lam * (t + t0))
                u = float(rows[i] @ w)
                w *= 1.0 - eta * lam
                label = labels[i]
                if label != 0:
                    if label * u < m:
                        w += (eta * label) * rows[i]
                elif abs(u) > m:
                    w -= (eta * tau * np.sign(u)) * rows[i]
                norm = float(np.sqrt(w @ w))
                if norm > radius:
                    w *= radius / norm
                if t >= first_averaged:
                    total += w
                t += 1
        return total / (n_steps - first_averaged)
