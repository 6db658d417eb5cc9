"""Disturbances for robustness trials: a lateral push, a friction drop, a wrong terrain map.

Each is a small object the executor calls every control tick
(:meth:`apply`, with the time since the first motion) and asks, once, for
the terrain the planner should see (:meth:`planner_terrain`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np
from scipy import ndimage

from roughwalk.errors import InvalidArgumentError
from roughwalk.terrain.terrain import Terrain

if TYPE_CHECKING:
    from roughwalk.sim.run_log import RunLog
    from roughwalk.sim.world import World

__all__ = ["Disturbance", "Push", "FrictionDrop", "MapError", "parse_disturbance"]


class Disturbance(Protocol):
    """What the executor needs of a disturbance."""

    def describe(self) -> str:
        """One line for logs and reports."""
        ...

    def planner_terrain(self, terrain: Terrain) -> Terrain:
        """The terrain the planner sees, given the true one."""
        ...

    def apply(self, world: World, now: float, first_motion: float | None, log: RunLog) -> None:
        """Act on the world at simulated time ``now`` [s] (clock started at ``first_motion``)."""
        ...


@dataclass
class Push:
    """A horizontal push on the trunk.

    ``impulse_ns`` [N·s] spread over ``duration_s`` [s], ``at_s`` [s] after the
    first motion, towards ``direction_deg`` [deg] from +x (90: to the robot's
    left when it walks along +x).
    """

    impulse_ns: float = 0.5
    at_s: float = 2.0
    duration_s: float = 0.1
    direction_deg: float = 90.0

    def __post_init__(self) -> None:
        if not (self.duration_s > 0 and math.isfinite(self.impulse_ns) and self.at_s >= 0):
            raise InvalidArgumentError(
                f"a push needs a finite impulse, at_s ≥ 0 and duration_s > 0, got {self}"
            )
        self._active = False

    def describe(self) -> str:
        """One line."""
        return (
            f"push {self.impulse_ns:g} N·s towards {self.direction_deg:g}° over "
            f"{self.duration_s:g} s at {self.at_s:g} s"
        )

    def planner_terrain(self, terrain: Terrain) -> Terrain:
        """Unchanged."""
        return terrain

    def apply(self, world: World, now: float, first_motion: float | None, log: RunLog) -> None:
        """Apply the force while the push lasts."""
        body = world.base_body
        if first_motion is None:
            return
        t = now - first_motion
        on = self.at_s <= t < self.at_s + self.duration_s
        if on:
            force = self.impulse_ns / self.duration_s
            a = math.radians(self.direction_deg)
            world.data.xfrc_applied[body, :3] = [force * math.cos(a), force * math.sin(a), 0.0]
            if not self._active:
                log.event(now, "push", impulse_ns=self.impulse_ns, direction_deg=self.direction_deg)
        elif self._active:
            world.data.xfrc_applied[body, :] = 0.0
        self._active = on


@dataclass
class FrictionDrop:
    """Foot–terrain friction falls to ``mu`` at ``at_s`` [s] after the first motion."""

    mu: float = 0.4
    at_s: float = 0.0

    def __post_init__(self) -> None:
        if not (self.mu >= 0 and self.at_s >= 0):
            raise InvalidArgumentError(f"a friction drop needs mu ≥ 0 and at_s ≥ 0, got {self}")
        self._done = False

    def describe(self) -> str:
        """One line."""
        return f"friction drops to {self.mu:g} at {self.at_s:g} s"

    def planner_terrain(self, terrain: Terrain) -> Terrain:
        """Unchanged."""
        return terrain

    def apply(self, world: World, now: float, first_motion: float | None, log: RunLog) -> None:
        """Lower the friction once."""
        if self._done or first_motion is None or now - first_motion < self.at_s:
            return
        world.set_friction(self.mu)
        self._done = True
        log.event(now, "friction", mu=self.mu)


@dataclass
class MapError:
    """The planner's terrain map is wrong by a smooth error of at most ±``amplitude_m`` [m].

    The error varies over about ``correlation_m`` [m] and is drawn from
    ``numpy.random.default_rng(seed)``.
    """

    amplitude_m: float = 0.01
    correlation_m: float = 0.05
    seed: int = 0

    def __post_init__(self) -> None:
        if not (self.amplitude_m >= 0 and self.correlation_m > 0 and self.seed >= 0):
            raise InvalidArgumentError(
                f"a map error needs amplitude_m ≥ 0, correlation_m > 0 and seed ≥ 0, got {self}"
            )

    def describe(self) -> str:
        """One line."""
        return f"terrain map error ±{100 * self.amplitude_m:g} cm (seed {self.seed})"

    def planner_terrain(self, terrain: Terrain) -> Terrain:
        """The true heights plus the error field."""
        rng = np.random.default_rng(self.seed)
        noise = rng.standard_normal(terrain.shape)
        sigma = (self.correlation_m / terrain.dx, self.correlation_m / terrain.dy)
        smooth = ndimage.gaussian_filter(noise, sigma, mode="wrap")
        peak = float(np.max(np.abs(smooth)))
        error = smooth * (self.amplitude_m / peak) if peak > 0 else smooth
        return Terrain(
            terrain.raw_heights + error,
            terrain.x0,
            terrain.y0,
            terrain.dx,
            terrain.dy,
            name=f"{terrain.name} (map error)",
            spec=f"{terrain.spec} with {self.describe()}",
        )

    def apply(self, world: World, now: float, first_motion: float | None, log: RunLog) -> None:
        """Nothing happens in the world itself."""


def parse_disturbance(text: str) -> Disturbance:
    """Read a disturbance from the command line.

    Examples: ``push:impulse_ns=0.6,at_s=2``, ``friction:mu=0.4``,
    ``map_error:amplitude_m=0.01,seed=3``.
    """
    kinds: dict[str, type] = {"push": Push, "friction": FrictionDrop, "map_error": MapError}
    name, _, args = text.partition(":")
    if name not in kinds:
        raise InvalidArgumentError(
            f"unknown disturbance {name!r}; known: {', '.join(kinds)} (e.g. push:impulse_ns=0.6)"
        )
    cls = kinds[name]
    params: dict[str, float | int] = {}
    for item in filter(None, (a.strip() for a in args.split(","))):
        key, sep, value = item.partition("=")
        fields = [f.name for f in dataclasses.fields(cls)]
        if not sep or key not in fields:
            raise InvalidArgumentError(
                f"disturbance {name}: expected key=value with key in {', '.join(fields)}, "
                f"got {item!r}"
            )
        try:
            params[key] = int(value) if key == "seed" else float(value)
        except ValueError:
            raise InvalidArgumentError(
                f"disturbance {name}: {key} must be a number, got {value!r}"
            ) from None
    disturbance: Disturbance = cls(**params)
    return disturbance
