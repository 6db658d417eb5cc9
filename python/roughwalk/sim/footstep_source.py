"""Where the executor's footstep plans come from: the anytime planner, or a blind crawl.

The executor asks for a plan twice in a run's life: before the clock starts
(from a trunk pose) and after every reflex (from the feet where they stand,
Zucker 2011, §6: "after recovery stabilizes the dog, the footstep planner is
re-started"). :class:`PlannerSource` wraps the footstep planner of
:mod:`roughwalk.planning`; :class:`CrawlSource` is a terrain-blind straight
crawl for flat-ground tests and for machines where the planner is missing.
Both return plans in the format :func:`roughwalk.footstep_trajectories`
reads: footsteps as contact points on the terrain, initial stance first;
certificates (with foot-sphere centres on the terrain) where there are.
A :class:`PlanStart` from the feet holds foot-sphere centres, as measured.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import InvalidArgumentError
from roughwalk.planning.foothold_safety import steep_footholds
from roughwalk.robots.canonical_frame import LEG_NAMES
from roughwalk.sim.config import ExecutorConfig
from roughwalk.sim.foothold_snap import snap_to_footholds
from roughwalk.sim.stride_reach import longer_step_config
from roughwalk.trajectories.body_keyframes import nominal_fit, pose_over_support
from roughwalk.trajectories.whole_body import WholeBody

if TYPE_CHECKING:
    from roughwalk.planning.footstep_config import FootstepConfig
    from roughwalk.robots.robot import Robot
    from roughwalk.terrain.terrain import Terrain

__all__ = [
    "PlanStart",
    "PlanAttempt",
    "FootstepSource",
    "CrawlSource",
    "PlannerSource",
    "default_source",
    "CRAWL_ORDER",
    "FOOTSTEP_PREFIX",
    "planner_config",
    "split_footstep_settings",
    "nominal_feet_xy",
]

CRAWL_ORDER = ("LH", "LF", "RH", "RF")

SNAP_RADIUS_M = 0.025
"""How far [m] a re-plan may move a measured foot that stands off the planner's
footholds onto the nearest one (:func:`~roughwalk.sim.foothold_snap.snap_to_footholds`):
as far as the executor lets a re-plan start from planned footholds instead of the
measured ones. On board AE (seed 0, default timing) a hind foot stood 2.06 cm past
the foothold border after a reflex."""


@dataclass(frozen=True)
class PlanStart:
    """A plan's start: a trunk pose, or the feet where they stand.

    ``pose`` is (x [m], y [m], yaw [rad]); ``feet`` (4, 3) [m], canonical legs,
    with ``next_leg`` (canonical index) the leg to move first and optionally
    ``trunk``, the measured trunk position (3,) [m] and quaternion (4,)
    (w, x, y, z) that the start certificate may be searched from.
    ``refused`` lists footholds no plan may step on again, as (canonical
    leg, x [m], y [m], radius [m]): the leg's end (front or hind) keeps out
    of that disc (a step there the trajectory generator could not make
    collision-free).
    """

    pose: tuple[float, float, float] | None = None
    feet: NDArray[np.float64] | None = None
    next_leg: int | None = None
    trunk: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
    refused: tuple[tuple[int, float, float, float], ...] = ()

    def __post_init__(self) -> None:
        if (self.pose is None) == (self.feet is None):
            raise InvalidArgumentError("a plan start needs exactly one of pose= or feet=")
        if self.trunk is not None and self.feet is None:
            raise InvalidArgumentError("a plan start's trunk= goes with feet=, not pose=")


@dataclass(frozen=True)
class PlanAttempt:
    """What a source returned.

    The ``plan`` (None when it failed), its ``status``, a ``reason`` when it
    failed, and the ``wall_s`` [s] it took. ``start_clearance_m`` is the start
    certificate's body clearance [m] where the source certifies its start
    (the footstep planner; None otherwise): below the planner's
    ``certificate.clearance`` it says the start was certified only with the
    relaxed ``certificate.start_clearance`` from the measured trunk.
    ``relaxed``: the plan is the source's second planner's, with its
    ``fallback`` settings (:class:`PlannerSource`).
    """

    plan: Any
    status: str
    reason: str
    wall_s: float
    start_clearance_m: float | None = None
    relaxed: bool = False

    @property
    def ok(self) -> bool:
        """A plan came back."""
        return self.plan is not None


class FootstepSource(Protocol):
    """Anything that plans footsteps to a goal."""

    name: str

    def plan(self, start: PlanStart, goal: NDArray[np.float64], time_limit: float) -> PlanAttempt:
        """Plan from ``start`` to the goal (x, y) [m] within ``time_limit`` [s]."""
        ...


class CrawlSource:
    """A straight crawl towards the goal, blind to the terrain but for foot heights.

    Each leg in the order LH, LF, RH, RF moves to the nominal footprint
    advanced along the line to the goal: half a ``stride`` on its first
    move, a whole one after, until the footprint's centre is on the goal.

    Parameters
    ----------
    robot, terrain:
        What walks where.
    stride:
        Foot advance per step [m].
    support_margin:
        How far [m] each step's pose keeps the CoM inside the next support triangle.
    """

    name = "crawl"

    def __init__(
        self,
        robot: Robot,
        terrain: Terrain,
        stride: float = 0.08,
        support_margin: float = 0.015,
    ) -> None:
        if not (math.isfinite(stride) and stride > 0):
            raise InvalidArgumentError(f"stride must be a positive length [m], got {stride}")
        self.robot = robot
        self.terrain = terrain
        self.stride = stride
        self.support_margin = support_margin
        self._wb = WholeBody(robot)

    def _on_ground(self, xy: NDArray[np.float64]) -> NDArray[np.float64]:
        """The foot-sphere centre resting on the terrain over ``xy`` (on its highest point)."""
        r = self.robot.foot_radius
        angles = np.linspace(0.0, 2 * np.pi, 8, endpoint=False)
        ring = np.vstack([[0.0, 0.0], 0.7 * r * np.column_stack([np.cos(angles), np.sin(angles)])])
        z = float(np.max(self.terrain.height(xy[None] + ring))) + r
        return np.array([xy[0], xy[1], z])

    def _contact(self, leg: int, centre: NDArray[np.float64]) -> dict[str, Any]:
        """A plan footstep: the contact point, the centre less the radius along the normal."""
        c = centre - self.robot.foot_radius * self.terrain.normal(centre[None, :2])[0]
        return {"leg": LEG_NAMES[leg], "x": float(c[0]), "y": float(c[1]), "z": float(c[2])}

    def plan(self, start: PlanStart, goal: NDArray[np.float64], time_limit: float) -> PlanAttempt:
        """Plan the crawl (instant; ``time_limit`` is not needed)."""
        began = time.perf_counter()
        g = np.asarray(goal, dtype=float)[:2]
        nominal = self.robot.nominal_stance.feet[:, :2]
        nominal = nominal - nominal.mean(axis=0)
        if start.pose is not None:
            x, y, yaw = start.pose
            c, s = math.cos(yaw), math.sin(yaw)
            rot0 = np.array([[c, -s], [s, c]])
            feet = np.array([self._on_ground(np.array([x, y]) + rot0 @ f) for f in nominal])
        else:
            assert start.feet is not None
            feet = np.asarray(start.feet, dtype=float).copy()
        centroid = feet[:, :2].mean(axis=0)
        to_goal = g - centroid
        distance = float(np.linalg.norm(to_goal))
        heading = math.atan2(to_goal[1], to_goal[0]) if distance > 1e-9 else 0.0
        c, s = math.cos(heading), math.sin(heading)
        rot = np.array([[c, -s], [s, c]])
        direction = rot[:, 0]
        order = [LEG_NAMES.index(n) for n in CRAWL_ORDER]
        first = order.index(start.next_leg) if start.next_leg in order else 0
        order = order[first:] + order[:first]
        footsteps = [self._contact(i, feet[i]) for i in range(4)]
        advance = np.full(4, -1.0)
        sequence: list[tuple[int, NDArray[np.float64]]] = []
        k = 0
        limit = 4 * (int(distance / self.stride) + 3)
        while np.any(advance < distance - 1e-9) and k < limit:
            leg = order[k % 4]
            k += 1
            if advance[leg] >= distance - 1e-9:
                continue
            step = 0.5 * self.stride if advance[leg] < 0 else self.stride
            advance[leg] = min(max(advance[leg], 0.0) + step, distance)
            target = self._on_ground(centroid + rot @ nominal[leg] + advance[leg] * direction)
            sequence.append((leg, target))
        # Certificate-like poses, as a certificate search starts them (Zucker 2011,
        # §4.4): the nominal stance fitted to the feet, the CoM nudged into the
        # next step's support triangle.
        certificates = []
        for i, (leg, target) in enumerate(sequence):
            feet = feet.copy()
            feet[leg] = target
            footsteps.append(self._contact(leg, target))
            following = sequence[i + 1][0] if i + 1 < len(sequence) else order[(k + i) % 4]
            support = [j for j in range(4) if j != following]
            fit = nominal_fit(self._wb, feet)
            frame = pose_over_support(self._wb, feet, support, self.support_margin, start=fit)
            certificates.append(
                {
                    "step": i + 1,
                    "base_pos": frame.base_pos.tolist(),
                    "base_quat": frame.base_quat.tolist(),
                    "q": self.robot.from_canonical(frame.q.reshape(12)).tolist(),
                }
            )
        plan = {
            "robot": self.robot.name,
            "terrain": self.terrain.spec,
            "footsteps": footsteps,
            "certificates": certificates,
        }
        return PlanAttempt(plan, "EXACT", "", time.perf_counter() - began)


class PlannerSource:
    """The anytime footstep planner of :mod:`roughwalk.planning` (Zucker 2011, §4).

    Its precomputation (signed distance field, terrain cost maps) happens
    once, here, before any run starts (§4.5: "precomputation is also key");
    re-plans reuse it and the certificates already found.

    Parameters
    ----------
    robot, terrain:
        What walks where (``terrain`` is what the planner sees, which a
        disturbance may have made wrong).
    expansions:
        A budget of expanded states on top of the time limit: the planner's
        deterministic mode (same inputs and budget, same plan), for tests.
    start_snap_m:
        How far [m] a foot of the nominal stance at a start pose that falls
        on no foothold may move onto the nearest one
        (:attr:`~roughwalk.sim.config.ExecutorConfig.start_snap_m`).
    start_max_slope:
        Steepest slope [rad] a start foot may stand on, where the footstep
        settings allow steeper footholds
        (:attr:`~roughwalk.sim.config.ExecutorConfig.start_max_slope`).
    fallback:
        Footstep settings (a :class:`~roughwalk.planning.footstep_config.FootstepConfig`)
        of a second planner, on the same terrain cost and signed distance
        field, that plans where this one finds no plan: from a start or a
        re-plan's feet (built here, with this one). None: no second
        planner (:attr:`~roughwalk.sim.config.ExecutorConfig.relax_edge_margin`).
    fallback_from_pose:
        Whether the second planner also plans from a start pose (the first
        plan), or only from the feet where they stand (re-plans).
    options:
        Passed on to :class:`~roughwalk.planning.footstep_planner.FootstepPlanner`.
    """

    name = "planner"

    def __init__(
        self,
        robot: Robot,
        terrain: Terrain,
        expansions: int | None = None,
        start_snap_m: float = ExecutorConfig.start_snap_m,
        start_max_slope: float = ExecutorConfig.start_max_slope,
        fallback: FootstepConfig | None = None,
        fallback_from_pose: bool = True,
        **options: Any,
    ) -> None:
        from roughwalk.planning.footstep_planner import FootstepPlanner

        self.robot = robot
        self.terrain = terrain
        self.expansions = expansions
        self.start_snap_m = start_snap_m
        self.start_max_slope = start_max_slope
        self._steep_start: NDArray[np.bool_] | None = None
        self.planner = FootstepPlanner(robot, terrain, **options)
        self._refused: list[tuple[int, float, float, float]] = []
        self._refusing_planner: Any = None
        self.fallback = fallback
        self.fallback_from_pose = fallback_from_pose
        # Built here with the rest of the precomputation, not in a re-plan's time.
        self._fallback_planner = (
            None
            if fallback is None
            else PlannerSource(
                robot,
                terrain,
                expansions,
                start_snap_m,
                start_max_slope,
                config=fallback,
                cost=self.planner.cost,
                sdf=self.planner.sdf,
            )
        )

    def plan(self, start: PlanStart, goal: NDArray[np.float64], time_limit: float) -> PlanAttempt:
        """Plan within ``time_limit`` [s]; the best plan found by then is returned.

        Where none comes and there are ``fallback`` settings, their planner
        plans from the same start (from a pose only with
        ``fallback_from_pose``), keeping every foothold refused so far: within
        what is left of ``time_limit``, or under an expansion budget (the
        deterministic mode) within the whole limit and budget again. Its
        attempt's ``wall_s`` counts both.
        """
        attempt = self._plan_once(start, goal, time_limit)
        second = self._fallback_planner
        if attempt.ok or second is None or (start.pose is not None and not self.fallback_from_pose):
            return attempt
        left = time_limit - attempt.wall_s if self.expansions is None else time_limit
        if left <= 0.0:
            return attempt
        fallback_start = (
            replace(start, refused=tuple(self._refused)) if start.feet is not None else start
        )
        again = second._plan_once(fallback_start, goal, left)
        wall = attempt.wall_s + again.wall_s
        if not again.ok:
            # The first planner's reason: the executor reads it (a start with
            # no pose certificate is nudged).
            return replace(attempt, wall_s=wall)
        return replace(again, wall_s=wall, relaxed=True)

    def _plan_once(
        self, start: PlanStart, goal: NDArray[np.float64], time_limit: float
    ) -> PlanAttempt:
        """:meth:`plan` with this planner alone."""
        began = time.perf_counter()
        g = np.asarray(goal, dtype=float)[:2]
        if start.pose is not None:
            result = self._plan_from_gentle_start(start.pose, g, time_limit)
            if result is None:
                result = self.planner.plan(
                    start.pose, g, time_limit=time_limit, expansions=self.expansions
                )
            if self.start_snap_m > 0 and result.start_off_foothold is not None:
                # Put down with a foot on no foothold (a rock's rim): that foot
                # goes onto the nearest foothold, the walk starts from there.
                feet = self._stance_at(start.pose)
                snapped, moved = snap_to_footholds(
                    self.planner, self.terrain, feet, self.start_snap_m
                )
                if moved:
                    result = self.planner.replan(
                        snapped,
                        self.planner.config.walking_order[0],
                        goal=g,
                        time_limit=time_limit,
                        expansions=self.expansions,
                    )
        else:
            assert start.feet is not None
            leg = LEG_NAMES[start.next_leg] if start.next_leg is not None else "LH"
            planner = self._refusing(start.refused)
            feet, _ = snap_to_footholds(planner, self.terrain, start.feet, SNAP_RADIUS_M)
            result = planner.replan(
                feet,
                leg,
                goal=g,
                time_limit=time_limit,
                expansions=self.expansions,
                trunk=start.trunk,
            )
        wall = time.perf_counter() - began
        if not result.solved:
            reason = result.reason or f"the planner found no plan ({result.status})"
            return PlanAttempt(None, result.status, reason, wall)
        start_clearance = None if result.initial_pose is None else result.initial_pose.clearance
        return PlanAttempt(result, result.status, "", wall, start_clearance)

    def certifies(self, start: PlanStart, goal: NDArray[np.float64]) -> bool:
        """Whether a re-plan from the feet of ``start`` would find its start stance certified.

        The stance as :meth:`plan` would start from it (feet off the
        footholds snapped, ``start.refused`` kept out of, ``start.next_leg``
        to lift first, the certificate searched from ``start.trunk`` where
        one is given) and the planner's own pose-certificate routine, with
        no search after it: what a recovery asks before it moves a foot
        (``reflex.replant_certified``). Outcomes are cached by the planner
        as any plan's are.
        """
        if start.feet is None:
            raise InvalidArgumentError("certifies needs a start from the feet (feet=)")
        leg = LEG_NAMES[start.next_leg] if start.next_leg is not None else "LH"
        planner = self._refusing(start.refused)
        feet, _ = snap_to_footholds(planner, self.terrain, start.feet, SNAP_RADIUS_M)
        g = np.asarray(goal, dtype=float)[:2]
        result = planner.replan(feet, leg, goal=g, time_limit=None, expansions=0, trunk=start.trunk)
        # With no search the result carries no certificate; "invalid_input"
        # is what a start stance without one (or a foot on no foothold) gives.
        if result.status != "invalid_input":
            return True
        second = self._fallback_planner
        return second is not None and second.certifies(
            replace(start, refused=tuple(self._refused)), goal
        )

    def _refusing(self, refused: tuple[tuple[int, float, float, float], ...]) -> Any:
        """The planner, or one that keeps every leg out of the discs ``refused`` has ever named.

        Refusals add up over a run: a foothold refused once stays refused
        (the planner is rebuilt with all of them when a new one comes).
        """
        if not refused and not self._refused:
            return self.planner
        new = [r for r in refused if r not in self._refused]
        if new or self._refusing_planner is None:
            self._refused.extend(new)
            planner = self.planner
            front = np.zeros(planner.cost_front.shape, dtype=bool)
            hind = np.zeros(planner.cost_hind.shape, dtype=bool)
            for leg, x, y, radius in self._refused:
                disc_front, disc_hind = planner.refused_masks(leg, x, y, radius)
                front |= disc_front
                hind |= disc_hind
            self._refusing_planner = planner.with_refused((front, hind))
        return self._refusing_planner

    def _plan_from_gentle_start(
        self, pose: tuple[float, float, float], goal: NDArray[np.float64], time_limit: float
    ) -> Any:
        """A plan from the start stance with its feet on slopes beyond ``start_max_slope`` moved.

        Each such foot goes onto the nearest foothold within ``start_snap_m``
        no steeper than that (:func:`snap_to_footholds`), and the plan
        starts from there. None where no foot moved (then the planner plans
        from the pose as usual) or where either setting is off.
        """
        if self.start_snap_m <= 0 or self.start_max_slope >= 0.5 * math.pi:
            return None
        if self._steep_start is None:
            self._steep_start = steep_footholds(
                self.terrain, self.robot.foot_radius, self.start_max_slope
            )
        feet = self._stance_at(pose)
        snapped, moved = snap_to_footholds(
            self.planner, self.terrain, feet, self.start_snap_m, refused=self._steep_start
        )
        if not moved:
            return None
        return self.planner.replan(
            snapped,
            self.planner.config.walking_order[0],
            goal=goal,
            time_limit=time_limit,
            expansions=self.expansions,
        )

    def _stance_at(self, pose: tuple[float, float, float]) -> NDArray[np.float64]:
        """The nominal stance's feet (4, 3) [m] at the trunk pose (x, y, yaw), on the terrain."""
        xy = nominal_feet_xy(self.robot, pose)
        z = np.asarray(self.terrain.height(xy), dtype=float) + self.robot.foot_radius
        return np.column_stack((xy, z))


def nominal_feet_xy(robot: Robot, pose: tuple[float, float, float]) -> NDArray[np.float64]:
    """Where the nominal stance puts the feet (4, 2) [m] under the trunk pose (x, y, yaw)."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.asarray(robot.nominal_stance.feet, dtype=float)[:, :2]
    return np.column_stack(
        (x + c * local[:, 0] - s * local[:, 1], y + s * local[:, 0] + c * local[:, 1])
    )


def default_source(robot: Robot, terrain: Terrain, **options: Any) -> FootstepSource:
    """The footstep planner when this installation has it, else :class:`CrawlSource`.

    The planner needs the compiled core's ``FootstepPlanner``; a build that
    predates it falls back to the crawl, which only suits flat ground.
    """
    from roughwalk import _core

    if not hasattr(_core, "FootstepPlanner"):
        return CrawlSource(robot, terrain)
    try:
        return PlannerSource(robot, terrain, **options)
    except ImportError:
        return CrawlSource(robot, terrain)


FOOTSTEP_PREFIX = "footstep."
"""Settings keys with this prefix go, without it, to the footstep planner's config."""


def split_footstep_settings(
    settings: dict[str, Any],
) -> tuple[dict[str, Any], dict[str, Any]]:
    """(simulation, footstep planner) settings: keys prefixed ``footstep.`` go to the planner.

    ``footstep.edge_drop=0.03`` or ``footstep.certificate.start_clearance=0.002``
    become the :class:`~roughwalk.planning.footstep_config.FootstepConfig`
    changes ``edge_drop`` and ``certificate.start_clearance``.
    """
    sim = {k: v for k, v in settings.items() if not k.startswith(FOOTSTEP_PREFIX)}
    footstep = {
        k.removeprefix(FOOTSTEP_PREFIX): v
        for k, v in settings.items()
        if k.startswith(FOOTSTEP_PREFIX)
    }
    return sim, footstep


EXECUTION_FOOTHOLD_SAFETY: dict[str, Any] = {
    "edge_drop": 0.03,
    "edge_margin": 0.01,
    "max_foothold_slope": math.radians(45.0),
}
"""Footstep settings a walk in physics plans with unless told otherwise.

A plan that only has to exist (``roughwalk plan``) may put a foot anywhere
the learned cost allows; a robot that walks it slides off a rock's rim and
off flanks steeper than its friction cone (atan μ, 45° at μ = 1):
:mod:`roughwalk.planning.foothold_safety`. Execution refuses them, and a
start foot on one is moved onto the nearest foothold
(``executor.start_snap_m``). Board bench, 4 seeds of every class with the
session-15 swing defaults: 26 of 28 runs with both, 24 with the rim check
alone (logs 1/4 → 3/4); figures in
:class:`~roughwalk.planning.footstep_config.FootstepConfig`'s
``max_foothold_slope``. ``--set footstep.edge_drop=0`` or
``footstep.max_foothold_slope=1.5708`` turns one off.

Since session 23 a walk also keeps feet 1 cm beyond their radius from such
rims (``edge_margin``; why, in
:class:`~roughwalk.planning.footstep_config.FootstepConfig`), and where that
leaves no plan it plans without the margin
(``executor.relax_edge_margin``). ``bench_littledog.py --expansions 40000``,
one process per seed: large rocks seeds 0–31 **31/32 at 6.86 cm/s**, 14
reflexes (25/32 at 6.80, 24 reflexes, without the margin; 30/32 at 7.00
with it and no relaxing, the other two re-plans finding no step: relaxed,
seed 22 walks at 4.28 and 24 falls after four reflexes); seeds 0–7 of the
other classes 47/48 (46/48): round rocks 8/8 at 8.10 cm/s (8.18), sloped
rocks 7/8 at 9.78 (8.68; seed 7 falls as before; 6 and 7 had no start with
the margin and started relaxed), logs **8/8** at 8.86 (7/8 at 9.27), gap
8/8 at 7.59 (the same runs), barrier 8/8 at 8.39 (the same), steps 8/8
at 7.92 (8.34). Of the 80 runs three re-planned with the margin relaxed
(large rocks seeds 20, 22 and 24).
"""


def planner_config(robot: Any, longest: float, footstep: dict[str, Any]) -> Any:
    """The footstep planner's settings for a walk of ``robot``.

    ``longest`` > 0 adds :func:`longer_step_config`'s actions; then
    :data:`EXECUTION_FOOTHOLD_SAFETY`, then ``footstep``'s dotted-key
    changes of the planner's config (applied last, so they win), checked by
    :func:`roughwalk.config.override`, which names an unknown field.
    """
    from roughwalk.config import override
    from roughwalk.planning.footstep_config import FootstepConfig

    base = longer_step_config(robot, longest) if longest > 0 else FootstepConfig.for_robot(robot)
    return override(base, {**EXECUTION_FOOTHOLD_SAFETY, **footstep})
