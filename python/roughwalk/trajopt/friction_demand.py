"""The friction a plan's base motion needs: whether any feet at all could push it.

The NLP bounds each foot's force by its friction pyramid at the force nodes
only, and a plan stopped after a few iterations meets that nowhere: on the
double pallet the planned forces of 0 and 5 iterations leave some stance
foot's pyramid on 90–100 % of the samples, pushing the feet against each
other with hundreds of newtons (which is why their implied joint torques,
:mod:`roughwalk.trajopt.implied_torques`, reach 276–618 N·m). Those forces
are a preference a controller may ignore; the base motion it must realise.
On level footholds the feet's net force m(c̈ − g) is inside the friction
cone of some force distribution only if its horizontal part is at most μ
times its vertical one, whatever the feet: this module measures how far a
plan's centre-of-mass acceleration asks beyond that.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roughwalk.errors import PlanningError
from roughwalk.trajopt.result import TrajoptResult

__all__ = ["FrictionDemand", "friction_demand", "required_friction"]

_GRAVITY = 9.81


@dataclass(frozen=True)
class FrictionDemand:
    """How much friction a plan's base motion needs while a foot stands.

    Attributes
    ----------
    friction:
        The friction coefficient μ compared against.
    over_fraction:
        Share of the samples with a foot in stance whose needed ratio
        exceeds ``friction``.
    max_ratio:
        The largest ratio needed |Σf_xy| / Σf_z (+inf where the plan asks
        the feet to pull the body down).
    time_s:
        When [s].
    """

    friction: float
    over_fraction: float
    max_ratio: float
    time_s: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields (an infinite ratio as None)."""
        return {
            "friction": self.friction,
            "over_fraction": self.over_fraction,
            "max_ratio": self.max_ratio if np.isfinite(self.max_ratio) else None,
            "time_s": self.time_s,
        }

    def describe(self) -> str:
        """One line for people."""
        return (
            f"the plan's base motion needs friction beyond μ = {self.friction:.2g} on "
            f"{100 * self.over_fraction:.0f} % of its stance samples (up to "
            f"{self.max_ratio:.2g} at {self.time_s:.2f} s)"
        )


def required_friction(com_acc: ArrayLike) -> NDArray[np.float64]:
    """(n,) the ratio |Σf_xy| / Σf_z [-] the feet's net force needs for accelerations (n, 3).

    The feet's net force is m(c̈ − g): its ratio does not depend on the mass.
    +inf where c̈_z ≤ −g (the feet would have to pull).
    """
    a = np.atleast_2d(np.asarray(com_acc, dtype=float))
    support = a[:, 2] + _GRAVITY
    horizontal = np.linalg.norm(a[:, :2], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = horizontal / support
    return np.asarray(np.where(support > 0.0, ratio, np.inf))


def friction_demand(
    result: TrajoptResult, friction: float | None = None, rate_hz: float = 100.0
) -> FrictionDemand:
    """How much friction ``result``'s centre-of-mass motion needs (level footholds).

    ``friction`` is μ to compare against (default: the plan's own, its body's).
    Samples the plan every 1/``rate_hz`` [s]; samples without a foot in
    stance (flight) need none and are left out.
    """
    if friction is None:
        if result.body is None:
            raise PlanningError("the plan names no body friction; pass friction=...")
        friction = result.body.friction
    mu = float(friction)
    plan = result.sample(rate_hz)  # raises when there is no trajectory
    assert result.splines is not None
    _, _, acc = result.splines.base_linear.evaluate(plan["t"])
    ratio = required_friction(acc)
    standing = np.asarray(plan["contact"]).any(axis=1)
    if not standing.any():
        return FrictionDemand(mu, 0.0, 0.0, 0.0)
    ratio = np.where(standing, ratio, -np.inf)
    k = int(np.argmax(ratio))
    return FrictionDemand(
        friction=mu,
        over_fraction=float((ratio > mu).sum() / standing.sum()),
        max_ratio=float(ratio[k]),
        time_s=float(plan["t"][k]),
    )
